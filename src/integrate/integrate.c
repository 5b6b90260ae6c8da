/* Integrators as generic drivers over backend vector operations (in the
 * style of SUNDIALS' N_Vector): every update is one px_buffer_lincomb on the
 * state's backend; the right-hand side is the caller's. */
#include <math.h>
#include <string.h>

#include "compute/backend_impl.h"
#include "partix/integrate.h"
#include "partix/memory.h"

#define PX_INTEGRATOR_WORK 4
#define PX_INTEGRATOR_HISTORY 4

struct px_integrator {
  struct px_backend *be; /* borrowed */
  enum px_integrator_method method;
  enum px_dtype type;
  size_t n;
  uint64_t steps;
  double dt; /* step of the history (0 when there is none) */
  int hlen;  /* valid history vectors, newest at ring slot `head` */
  int head;
  int nhist;                                     /* history slots allocated by the method */
  int nwork;                                     /* work buffers allocated by the method */
  struct px_buffer *hist[PX_INTEGRATOR_HISTORY]; /* owned */
  struct px_buffer *work[PX_INTEGRATOR_WORK];    /* owned */
};

const char *px_integrator_method_name(enum px_integrator_method method) {
  switch (method) {
    case PX_INTEGRATOR_EULER: return "euler";
    case PX_INTEGRATOR_RK2: return "rk2";
    case PX_INTEGRATOR_RK4: return "rk4";
    case PX_INTEGRATOR_ABM4: return "abm4";
    case PX_INTEGRATOR_VERLET: return "verlet";
  }
  return "?";
}

enum px_status px_integrator_method_parse(const char *name, enum px_integrator_method *out) {
  int m;
  if (!name || !out) return PX_STATUS_INVALID;
  for (m = PX_INTEGRATOR_EULER; m <= PX_INTEGRATOR_VERLET; ++m)
    if (strcmp(name, px_integrator_method_name((enum px_integrator_method)m)) == 0) {
      *out = (enum px_integrator_method)m;
      return PX_STATUS_OK;
    }
  return PX_STATUS_INVALID;
}

int px_integrator_method_order(enum px_integrator_method method) {
  switch (method) {
    case PX_INTEGRATOR_EULER: return 1;
    case PX_INTEGRATOR_RK2:
    case PX_INTEGRATOR_VERLET: return 2;
    case PX_INTEGRATOR_RK4:
    case PX_INTEGRATOR_ABM4: return 4;
  }
  return 0;
}

/* Buffers per method: history slots and work vectors. */
static void px_integrator_layout(enum px_integrator_method m, int *nhist, int *nwork) {
  switch (m) {
    case PX_INTEGRATOR_EULER:
      *nhist = 0;
      *nwork = 1;
      return; /* k */
    case PX_INTEGRATOR_RK2:
      *nhist = 0;
      *nwork = 2;
      return; /* k, ytmp */
    case PX_INTEGRATOR_RK4:
      *nhist = 0;
      *nwork = 4;
      return; /* k1, k2, k3|k4, ytmp */
    case PX_INTEGRATOR_ABM4:
      *nhist = 4;
      *nwork = 3;
      return; /* f ring; k2, k3|k4, ytmp */
    case PX_INTEGRATOR_VERLET:
      *nhist = 1;
      *nwork = 1;
      return; /* a_n; a_{n+1} */
  }
  *nhist = *nwork = 0;
}

static enum px_status px_integrator_alloc(struct px_integrator *it) {
  const size_t bytes = it->n * px_dtype_size(it->type);
  int i;
  for (i = 0; i < it->nhist; ++i) {
    if (!it->hist[i])
      PX_TRY(px_buffer_create(it->be, "integrator history", bytes, &it->hist[i]));
    else
      PX_TRY(px_buffer_resize(it->hist[i], bytes));
  }
  for (i = 0; i < it->nwork; ++i) {
    if (!it->work[i])
      PX_TRY(px_buffer_create(it->be, "integrator work", bytes, &it->work[i]));
    else
      PX_TRY(px_buffer_resize(it->work[i], bytes));
  }
  return PX_STATUS_OK;
}

enum px_status px_integrator_create(struct px_backend *be, enum px_integrator_method method,
                                    enum px_dtype type, size_t n, struct px_integrator **out) {
  static const char *const what = "px_integrator_create";
  struct px_integrator *it;
  enum px_status st;
  if (!be || !out)
    return be ? px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: out is NULL", what)
              : PX_STATUS_INVALID;
  *out = NULL;
  if (px_integrator_method_order(method) == 0)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: unknown method %d", what, (int)method);
  if (type != PX_DTYPE_F32 && type != PX_DTYPE_F64)
    return px_context_fail(be->ctx, PX_STATUS_INVALID, "%s: element type %s, expected f32 or f64",
                           what, px_dtype_name(type));
  if (type == PX_DTYPE_F64) PX_TRY(px_backend_require(be, PX_PRECISION_DOUBLE));
  it = px_mem_calloc(be->ctx, "integrator", 1, sizeof *it);
  if (!it) return PX_STATUS_NOMEM;
  it->be = be;
  it->method = method;
  it->type = type;
  it->n = n;
  px_integrator_layout(method, &it->nhist, &it->nwork);
  st = px_integrator_alloc(it);
  if (st != PX_STATUS_OK) {
    px_integrator_free(it);
    return st;
  }
  *out = it;
  return PX_STATUS_OK;
}

void px_integrator_free(struct px_integrator *it) {
  int i;
  if (!it) return;
  for (i = 0; i < PX_INTEGRATOR_HISTORY; ++i) px_buffer_free(it->hist[i]);
  for (i = 0; i < PX_INTEGRATOR_WORK; ++i) px_buffer_free(it->work[i]);
  px_mem_free(it->be->ctx, it);
}

enum px_integrator_method px_integrator_method(const struct px_integrator *it) {
  return it ? it->method : PX_INTEGRATOR_EULER;
}
size_t px_integrator_size(const struct px_integrator *it) { return it ? it->n : 0; }
uint64_t px_integrator_steps(const struct px_integrator *it) { return it ? it->steps : 0; }
double px_integrator_dt(const struct px_integrator *it) { return it ? it->dt : 0.0; }
int px_integrator_history_length(const struct px_integrator *it) { return it ? it->hlen : 0; }

void px_integrator_reset(struct px_integrator *it) {
  if (!it) return;
  it->hlen = 0;
  it->head = 0;
  it->dt = 0.0;
}

enum px_status px_integrator_resize(struct px_integrator *it, size_t n) {
  if (!it) return PX_STATUS_INVALID;
  it->n = n;
  px_integrator_reset(it);
  return px_integrator_alloc(it);
}

/* ------------------------------------------------------------------------ */

/* out = Σ c[k] in[k] over the state's n elements. */
static enum px_status px_lc(struct px_integrator *it, struct px_buffer *out, int nterms,
                            const double *c, struct px_buffer *const *in) {
  return px_buffer_lincomb(out, it->type, it->n, nterms, c, in);
}

static enum px_status px_rhs(struct px_integrator *it, px_rhs_fn f, void *user, double t,
                             struct px_buffer *y, struct px_buffer *dydt) {
  enum px_status st = f(user, t, y, dydt);
  if (st != PX_STATUS_OK)
    px_context_prefix(it->be->ctx, "%s step %llu: right-hand side at t = %.17g",
                      px_integrator_method_name(it->method), (unsigned long long)it->steps, t);
  return st;
}

/* History ring: logical index k (0 = newest) to buffer. */
static struct px_buffer *px_hist(struct px_integrator *it, int k) {
  return it->hist[(it->head - k + PX_INTEGRATOR_HISTORY) % PX_INTEGRATOR_HISTORY];
}

/* Classic RK4 step of y from t, with k1 = f(t, y) given (left unchanged);
 * k2, k3, ytmp are work vectors:
 *   y_{n+1} = y + dt/6 (k1 + 2 k2 + 2 k3 + k4),
 * evaluated as y + dt/6 s + dt/6 k4 with s = k1 + 2 k2 + 2 k3 folded into
 * k2's storage and k4 written over k3 (four vectors of storage in all). */
static enum px_status px_rk4_update(struct px_integrator *it, px_rhs_fn f, void *user, double t,
                                    double dt, struct px_buffer *y, struct px_buffer *k1,
                                    struct px_buffer *k2, struct px_buffer *k3,
                                    struct px_buffer *ytmp) {
  double c[3];
  struct px_buffer *in[3];
  c[0] = 1.0;
  c[1] = 0.5 * dt;
  in[0] = y;
  in[1] = k1;
  PX_TRY(px_lc(it, ytmp, 2, c, in));
  PX_TRY(px_rhs(it, f, user, t + 0.5 * dt, ytmp, k2));
  in[1] = k2;
  PX_TRY(px_lc(it, ytmp, 2, c, in));
  PX_TRY(px_rhs(it, f, user, t + 0.5 * dt, ytmp, k3));
  c[1] = dt;
  in[1] = k3;
  PX_TRY(px_lc(it, ytmp, 2, c, in));
  c[0] = 1.0;
  c[1] = 2.0;
  c[2] = 2.0;
  in[0] = k1;
  in[1] = k2;
  in[2] = k3;
  PX_TRY(px_lc(it, k2, 3, c, in));
  PX_TRY(px_rhs(it, f, user, t + dt, ytmp, k3));
  c[0] = 1.0;
  c[1] = dt / 6.0;
  c[2] = dt / 6.0;
  in[0] = y;
  in[1] = k2;
  in[2] = k3;
  return px_lc(it, y, 3, c, in);
}

static enum px_status px_check_step(struct px_integrator *it, const char *what, double t, double dt,
                                    struct px_buffer *y) {
  if (!isfinite(t) || !isfinite(dt) || dt == 0.0)
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID,
                           "%s: t = %g, dt = %g; expected finite values and dt != 0", what, t, dt);
  return px_buffer_check(it->be, what, "state", y, it->n, it->type);
}

/* One step of a first-order method (arguments checked). */
static enum px_status px_integrator_advance(struct px_integrator *it, px_rhs_fn f, void *user,
                                            double t, double dt, struct px_buffer *y) {
  double c[5];
  struct px_buffer *in[5];
  switch (it->method) {
    case PX_INTEGRATOR_EULER:
      PX_TRY(px_rhs(it, f, user, t, y, it->work[0]));
      c[0] = 1.0;
      c[1] = dt;
      in[0] = y;
      in[1] = it->work[0];
      PX_TRY(px_lc(it, y, 2, c, in));
      break;
    case PX_INTEGRATOR_RK2: { /* explicit midpoint */
      struct px_buffer *k = it->work[0], *ytmp = it->work[1];
      PX_TRY(px_rhs(it, f, user, t, y, k));
      c[0] = 1.0;
      c[1] = 0.5 * dt;
      in[0] = y;
      in[1] = k;
      PX_TRY(px_lc(it, ytmp, 2, c, in));
      PX_TRY(px_rhs(it, f, user, t + 0.5 * dt, ytmp, k));
      c[1] = dt;
      PX_TRY(px_lc(it, y, 2, c, in));
      break;
    }
    case PX_INTEGRATOR_RK4:
      PX_TRY(px_rhs(it, f, user, t, y, it->work[0]));
      PX_TRY(
          px_rk4_update(it, f, user, t, dt, y, it->work[0], it->work[1], it->work[2], it->work[3]));
      break;
    case PX_INTEGRATOR_ABM4: {
      struct px_buffer *k2 = it->work[0], *k3 = it->work[1], *ytmp = it->work[2];
      if (it->hlen > 0 && dt != it->dt) it->hlen = 1; /* unequal spacing: restart */
      if (it->hlen == 0) {
        it->head = 0;
        PX_TRY(px_rhs(it, f, user, t, y, px_hist(it, 0)));
        it->hlen = 1;
      }
      if (it->hlen < 4) {
        /* start-up: classic RK4 with k1 = f_n from the history */
        PX_TRY(px_rk4_update(it, f, user, t, dt, y, px_hist(it, 0), k2, k3, ytmp));
      } else {
        /* P: AB4  y* = y + dt/24 (55 f_n − 59 f_{n−1} + 37 f_{n−2} − 9 f_{n−3}) */
        c[0] = 1.0;
        c[1] = 55.0 * dt / 24.0;
        c[2] = -59.0 * dt / 24.0;
        c[3] = 37.0 * dt / 24.0;
        c[4] = -9.0 * dt / 24.0;
        in[0] = y;
        in[1] = px_hist(it, 0);
        in[2] = px_hist(it, 1);
        in[3] = px_hist(it, 2);
        in[4] = px_hist(it, 3);
        PX_TRY(px_lc(it, ytmp, 5, c, in));
        /* E: f* = f(t + dt, y*) */
        PX_TRY(px_rhs(it, f, user, t + dt, ytmp, k2));
        /* C: AM4  y = y + dt/24 (9 f* + 19 f_n − 5 f_{n−1} + f_{n−2}) */
        c[1] = 9.0 * dt / 24.0;
        c[2] = 19.0 * dt / 24.0;
        c[3] = -5.0 * dt / 24.0;
        c[4] = 1.0 * dt / 24.0;
        in[1] = k2;
        in[2] = px_hist(it, 0);
        in[3] = px_hist(it, 1);
        in[4] = px_hist(it, 2);
        PX_TRY(px_lc(it, y, 5, c, in));
      }
      /* E: f_{n+1} = f(t + dt, y_{n+1}) becomes the newest history entry
       * (its slot held f_{n−3}, no longer needed). */
      it->head = (it->head + 1) % PX_INTEGRATOR_HISTORY;
      PX_TRY(px_rhs(it, f, user, t + dt, y, px_hist(it, 0)));
      if (it->hlen < 4) ++it->hlen;
      it->dt = dt;
      break;
    }
    case PX_INTEGRATOR_VERLET: break;
  }
  return PX_STATUS_OK;
}

enum px_status px_integrator_step(struct px_integrator *it, px_rhs_fn f, void *user, double t,
                                  double dt, struct px_buffer *y) {
  static const char *const what = "px_integrator_step";
  enum px_status st;
  if (!it) return PX_STATUS_INVALID;
  if (!f) return px_context_fail(it->be->ctx, PX_STATUS_INVALID, "%s: f is NULL", what);
  if (it->method == PX_INTEGRATOR_VERLET)
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID,
                           "%s: verlet integrates x'' = a(t, x); call px_integrator_step_verlet",
                           what);
  PX_TRY(px_check_step(it, what, t, dt, y));
  st = it->n ? px_integrator_advance(it, f, user, t, dt, y) : PX_STATUS_OK;
  if (st != PX_STATUS_OK) {
    /* y may be partly advanced and the history half updated */
    px_integrator_reset(it);
    return st;
  }
  ++it->steps;
  return PX_STATUS_OK;
}

enum px_status px_integrator_step_verlet(struct px_integrator *it, px_accel_fn a, void *user,
                                         double t, double dt, struct px_buffer *x,
                                         struct px_buffer *v) {
  static const char *const what = "px_integrator_step_verlet";
  double c[3];
  struct px_buffer *in[3], *swap;
  enum px_status st;
  if (!it) return PX_STATUS_INVALID;
  if (!a) return px_context_fail(it->be->ctx, PX_STATUS_INVALID, "%s: a is NULL", what);
  if (it->method != PX_INTEGRATOR_VERLET)
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID,
                           "%s: the integrator is %s; velocity Verlet needs method verlet", what,
                           px_integrator_method_name(it->method));
  PX_TRY(px_check_step(it, what, t, dt, x));
  PX_TRY(px_buffer_check(it->be, what, "v", v, it->n, it->type));
  if (x == v)
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID, "%s: x and v are the same buffer", what);
  if (it->n == 0) {
    ++it->steps;
    return PX_STATUS_OK;
  }
  if (it->hlen == 0) {
    st = a(user, t, x, it->hist[0]);
    if (st != PX_STATUS_OK)
      return px_context_prefix(it->be->ctx, "verlet: acceleration at t = %.17g", t);
    it->hlen = 1;
  }
  /* from here on a failure leaves x advanced and v not: reset the history */
  /* x += dt v + dt²/2 a_n */
  c[0] = 1.0;
  c[1] = dt;
  c[2] = 0.5 * dt * dt;
  in[0] = x;
  in[1] = v;
  in[2] = it->hist[0];
  st = px_lc(it, x, 3, c, in);
  if (st == PX_STATUS_OK) {
    st = a(user, t + dt, x, it->work[0]);
    if (st != PX_STATUS_OK)
      px_context_prefix(it->be->ctx, "verlet: acceleration at t = %.17g", t + dt);
  }
  if (st != PX_STATUS_OK) {
    px_integrator_reset(it);
    return st;
  }
  /* v += dt/2 (a_n + a_{n+1}) */
  c[1] = 0.5 * dt;
  c[2] = 0.5 * dt;
  in[0] = v;
  in[1] = it->hist[0];
  in[2] = it->work[0];
  st = px_lc(it, v, 3, c, in);
  if (st != PX_STATUS_OK) {
    px_integrator_reset(it);
    return st;
  }
  swap = it->hist[0];
  it->hist[0] = it->work[0];
  it->work[0] = swap;
  it->dt = dt;
  ++it->steps;
  return PX_STATUS_OK;
}

static enum px_status px_history_index(struct px_integrator *it, const char *what, int k,
                                       const void *host) {
  if (k < 0 || k >= it->hlen)
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID,
                           "%s: history vector %d requested, %d valid", what, k, it->hlen);
  if (!host && it->n)
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID, "%s: host pointer is NULL", what);
  return PX_STATUS_OK;
}

/* Verlet keeps a_n in hist[0] without a ring. */
static struct px_buffer *px_history_buffer(struct px_integrator *it, int k) {
  return it->method == PX_INTEGRATOR_VERLET ? it->hist[0] : px_hist(it, k);
}

enum px_status px_integrator_history_read(struct px_integrator *it, int k, void *host) {
  if (!it) return PX_STATUS_INVALID;
  PX_TRY(px_history_index(it, "px_integrator_history_read", k, host));
  return px_buffer_read(px_history_buffer(it, k), 0, it->n * px_dtype_size(it->type), host);
}

enum px_status px_integrator_history_write(struct px_integrator *it, int k, const void *host) {
  if (!it) return PX_STATUS_INVALID;
  PX_TRY(px_history_index(it, "px_integrator_history_write", k, host));
  return px_buffer_write(px_history_buffer(it, k), 0, it->n * px_dtype_size(it->type), host);
}

enum px_status px_integrator_set_state(struct px_integrator *it, uint64_t steps, double dt,
                                       int history_length) {
  if (!it) return PX_STATUS_INVALID;
  if (history_length < 0 || history_length > it->nhist)
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID,
                           "px_integrator_set_state: history length %d; %s keeps at most %d",
                           history_length, px_integrator_method_name(it->method), it->nhist);
  if (!isfinite(dt))
    return px_context_fail(it->be->ctx, PX_STATUS_INVALID,
                           "px_integrator_set_state: dt is not finite");
  it->steps = steps;
  it->dt = dt;
  it->hlen = history_length;
  it->head = 0;
  return PX_STATUS_OK;
}
