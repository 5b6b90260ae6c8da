/* Integrators on the backend named by argv[1]: observed order of
 * convergence on ODEs with known solutions (dt halved three times, every
 * observed order within ±0.2 of the method's order), checkpoint export and
 * import of the history continuing bit for bit, dt changes, and misuse.
 * The right-hand sides do their arithmetic on the host through
 * px_buffer_read/write; the integrators' vector updates run on the backend. */
#include <math.h>

#include "compute/backend_impl.h"
#include "compute_test.h"

enum { NCOMP = 37 };

struct rhs_data {
  enum px_precision p;
  struct px_context *ctx;
  long calls;
};

/* y' = y cos t, y(0) = y0  =>  y(t) = y0 exp(sin t) */
static enum px_status rhs_exp_sin(void *user, double t, struct px_buffer *y,
                                  struct px_buffer *dydt) {
  struct rhs_data *d = user;
  double v[NCOMP];
  size_t i;
  px_test_download(d->ctx, y, d->p, NCOMP, v);
  for (i = 0; i < NCOMP; ++i) v[i] *= cos(t);
  if (d->p == PX_PRECISION_SINGLE) {
    float f[NCOMP];
    for (i = 0; i < NCOMP; ++i) f[i] = (float)v[i];
    PX_TRY(px_buffer_write(dydt, 0, sizeof f, f));
  } else {
    PX_TRY(px_buffer_write(dydt, 0, sizeof v, v));
  }
  ++d->calls;
  return PX_STATUS_OK;
}

/* x'' = -ω² x with ω = 1 + i/NCOMP per component. */
static enum px_status accel_oscillator(void *user, double t, struct px_buffer *x,
                                       struct px_buffer *a) {
  struct rhs_data *d = user;
  double v[NCOMP];
  size_t i;
  (void)t;
  px_test_download(d->ctx, x, d->p, NCOMP, v);
  for (i = 0; i < NCOMP; ++i) {
    const double w = 1.0 + (double)i / NCOMP;
    v[i] *= -w * w;
  }
  ++d->calls;
  return px_buffer_write(a, 0, sizeof v, v);
}

static enum px_status rhs_fails(void *user, double t, struct px_buffer *y, struct px_buffer *dydt) {
  struct rhs_data *d = user;
  (void)y;
  (void)dydt;
  return px_context_fail(d->ctx, PX_STATUS_NUMERIC, "test right-hand side refuses t = %g", t);
}

static double y0_of(size_t i) { return 1.0 + 0.1 * (double)i; }

/* Max error at T of method m with `steps` steps of the exp(sin t) problem. */
static double solve_first_order(struct px_context *ctx, struct px_backend *be,
                                enum px_integrator_method m, enum px_precision p, int steps,
                                double T, long *calls) {
  struct rhs_data d;
  struct px_integrator *it = NULL;
  struct px_buffer *y;
  double v[NCOMP], err = 0.0;
  const double dt = T / steps;
  size_t i;
  int s;
  d.p = p;
  d.ctx = ctx;
  d.calls = 0;
  for (i = 0; i < NCOMP; ++i) v[i] = y0_of(i);
  y = px_test_upload(ctx, be, "y", p, NCOMP, v);
  PX_CHECK_OK(ctx, px_integrator_create(
                       be, m, p == PX_PRECISION_SINGLE ? PX_DTYPE_F32 : PX_DTYPE_F64, NCOMP, &it));
  for (s = 0; s < steps && it; ++s)
    PX_CHECK_OK(ctx, px_integrator_step(it, rhs_exp_sin, &d, s * dt, dt, y));
  px_test_download(ctx, y, p, NCOMP, v);
  for (i = 0; i < NCOMP; ++i) {
    const double e = fabs(v[i] - y0_of(i) * exp(sin(T)));
    if (e > err) err = e;
  }
  if (it) PX_CHECK(px_integrator_steps(it) == (uint64_t)steps);
  px_integrator_free(it);
  px_buffer_free(y);
  if (calls) *calls = d.calls;
  return err;
}

static double solve_verlet(struct px_context *ctx, struct px_backend *be, int steps, double T) {
  struct rhs_data d;
  struct px_integrator *it = NULL;
  struct px_buffer *x, *v;
  double xs[NCOMP], vs[NCOMP], err = 0.0;
  const double dt = T / steps;
  size_t i;
  int s;
  d.p = PX_PRECISION_DOUBLE;
  d.ctx = ctx;
  d.calls = 0;
  for (i = 0; i < NCOMP; ++i) {
    xs[i] = y0_of(i);
    vs[i] = 0.0;
  }
  x = px_test_upload(ctx, be, "x", d.p, NCOMP, xs);
  v = px_test_upload(ctx, be, "v", d.p, NCOMP, vs);
  PX_CHECK_OK(ctx, px_integrator_create(be, PX_INTEGRATOR_VERLET, PX_DTYPE_F64, NCOMP, &it));
  for (s = 0; s < steps && it; ++s)
    PX_CHECK_OK(ctx, px_integrator_step_verlet(it, accel_oscillator, &d, s * dt, dt, x, v));
  /* one acceleration per step, plus the first */
  PX_CHECK(d.calls == steps + 1);
  px_test_download(ctx, x, d.p, NCOMP, xs);
  px_test_download(ctx, v, d.p, NCOMP, vs);
  for (i = 0; i < NCOMP; ++i) {
    const double w = 1.0 + (double)i / NCOMP;
    const double ex = fabs(xs[i] - y0_of(i) * cos(w * T));
    const double ev = fabs(vs[i] + y0_of(i) * w * sin(w * T));
    if (ex > err) err = ex;
    if (ev > err) err = ev;
  }
  px_integrator_free(it);
  px_buffer_free(x);
  px_buffer_free(v);
  return err;
}

static void check_order(const char *name, const char *backend, int order, const double *err,
                        const int *steps, int levels) {
  int k;
  printf("%-7s [%s]:", name, backend);
  for (k = 0; k < levels; ++k) printf(" N=%d err=%.3e", steps[k], err[k]);
  printf("\n   observed orders:");
  for (k = 0; k + 1 < levels; ++k) {
    const double q = log2(err[k] / err[k + 1]);
    printf(" %.3f", q);
    PX_CHECK_MSG(fabs(q - order) <= 0.2,
                 "%s on %s: observed order %.3f between N = %d and %d, "
                 "expected %d ± 0.2",
                 name, backend, q, steps[k], steps[k + 1], order);
  }
  printf("\n");
}

static void test_orders(struct px_context *ctx, struct px_backend *be) {
  /* start N per method: in the asymptotic range, and the finest error well
   * above rounding (double) */
  static const struct {
    enum px_integrator_method m;
    int n0;
  } cases[4] = {{PX_INTEGRATOR_EULER, 200},
                {PX_INTEGRATOR_RK2, 40},
                {PX_INTEGRATOR_RK4, 10},
                {PX_INTEGRATOR_ABM4, 40}};
  const double T = 2.0;
  double err[4];
  int steps[4], c, k;
  for (c = 0; c < 4; ++c) {
    for (k = 0; k < 4; ++k) {
      steps[k] = cases[c].n0 << k;
      err[k] = solve_first_order(ctx, be, cases[c].m, PX_PRECISION_DOUBLE, steps[k], T, NULL);
    }
    check_order(px_integrator_method_name(cases[c].m), px_backend_name(be),
                px_integrator_method_order(cases[c].m), err, steps, 4);
  }
  for (k = 0; k < 4; ++k) {
    steps[k] = 40 << k;
    err[k] = solve_verlet(ctx, be, steps[k], T);
  }
  check_order("verlet", px_backend_name(be), 2, err, steps, 4);
  /* single precision: Euler's first order is visible far above float rounding */
  for (k = 0; k < 3; ++k) {
    steps[k] = 50 << k;
    err[k] =
        solve_first_order(ctx, be, PX_INTEGRATOR_EULER, PX_PRECISION_SINGLE, steps[k], T, NULL);
  }
  check_order("euler32", px_backend_name(be), 1, err, steps, 3);
  /* cost: ABM4 evaluates f 4 times per start-up step and then twice, plus
   * the first derivative: 1 + 3*4 + (N-3)*2 */
  {
    long calls = 0;
    solve_first_order(ctx, be, PX_INTEGRATOR_ABM4, PX_PRECISION_DOUBLE, 20, T, &calls);
    PX_CHECK_MSG(calls == 1 + 3 * 4 + 17 * 2, "abm4: %ld right-hand sides for 20 steps", calls);
    solve_first_order(ctx, be, PX_INTEGRATOR_RK4, PX_PRECISION_DOUBLE, 20, T, &calls);
    PX_CHECK(calls == 80);
  }
}

/* Run 12 ABM4 steps straight, and 6 + export + import into a fresh
 * integrator + 6: the states must be identical bit for bit. */
static void test_checkpoint(struct px_context *ctx, struct px_backend *be) {
  struct rhs_data d;
  struct px_integrator *a = NULL, *b = NULL;
  struct px_buffer *ya, *yb;
  double v[NCOMP], va[NCOMP], vb[NCOMP], hist[4][NCOMP], dt = 0.05, saved_dt;
  uint64_t saved_steps;
  int s, k, hlen;
  size_t i;
  d.p = PX_PRECISION_DOUBLE;
  d.ctx = ctx;
  d.calls = 0;
  for (i = 0; i < NCOMP; ++i) v[i] = y0_of(i);
  ya = px_test_upload(ctx, be, "ya", d.p, NCOMP, v);
  PX_CHECK_OK(ctx, px_integrator_create(be, PX_INTEGRATOR_ABM4, PX_DTYPE_F64, NCOMP, &a));
  if (!a) return;
  for (s = 0; s < 6; ++s) PX_CHECK_OK(ctx, px_integrator_step(a, rhs_exp_sin, &d, s * dt, dt, ya));
  /* export */
  saved_steps = px_integrator_steps(a);
  saved_dt = px_integrator_dt(a);
  hlen = px_integrator_history_length(a);
  PX_CHECK(saved_steps == 6 && saved_dt == dt && hlen == 4);
  for (k = 0; k < hlen; ++k) PX_CHECK_OK(ctx, px_integrator_history_read(a, k, hist[k]));
  px_test_download(ctx, ya, d.p, NCOMP, v);
  /* the newest history vector is f(t_6, y_6) */
  for (i = 0, k = 0; i < NCOMP; ++i) k += hist[0][i] != v[i] * cos(5 * dt + dt);
  PX_CHECK_MSG(k == 0, "history[0] is not f at the current state");
  /* import into a fresh integrator and a fresh state buffer */
  yb = px_test_upload(ctx, be, "yb", d.p, NCOMP, v);
  PX_CHECK_OK(ctx, px_integrator_create(be, PX_INTEGRATOR_ABM4, PX_DTYPE_F64, NCOMP, &b));
  if (!b) return;
  PX_CHECK_OK(ctx, px_integrator_set_state(b, saved_steps, saved_dt, hlen));
  for (k = 0; k < hlen; ++k) PX_CHECK_OK(ctx, px_integrator_history_write(b, k, hist[k]));
  for (s = 6; s < 12; ++s) {
    PX_CHECK_OK(ctx, px_integrator_step(a, rhs_exp_sin, &d, s * dt, dt, ya));
    PX_CHECK_OK(ctx, px_integrator_step(b, rhs_exp_sin, &d, s * dt, dt, yb));
  }
  px_test_download(ctx, ya, d.p, NCOMP, va);
  px_test_download(ctx, yb, d.p, NCOMP, vb);
  PX_CHECK_MSG(memcmp(va, vb, sizeof va) == 0,
               "ABM4 continued from an exported history differs from the uninterrupted run");
  PX_CHECK(px_integrator_steps(b) == 12);
  /* accurate too (RK4 start-up then ABM4): relative error ~1.6e-7 at dt = 0.05 */
  for (i = 0; i < NCOMP; ++i) PX_CHECK_REL(va[i], y0_of(i) * exp(sin(12 * dt)), 1e-6);

  /* a different dt restarts the start-up, keeping f at the current point */
  PX_CHECK_OK(ctx, px_integrator_step(a, rhs_exp_sin, &d, 12 * dt, 0.5 * dt, ya));
  PX_CHECK(px_integrator_history_length(a) == 2);
  PX_CHECK(px_integrator_dt(a) == 0.5 * dt);
  px_integrator_reset(a);
  PX_CHECK(px_integrator_history_length(a) == 0 && px_integrator_steps(a) == 13);

  /* misuse */
  PX_CHECK_STATUS(ctx, px_integrator_set_state(b, 1, dt, 5), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_integrator_history_read(a, 0, hist[0]), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_integrator_history_read(b, 4, hist[0]), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_integrator_step(b, NULL, &d, 0.0, dt, yb), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_integrator_step(b, rhs_exp_sin, &d, 0.0, 0.0, yb), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_integrator_step(b, rhs_exp_sin, &d, 0.0, NAN, yb), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_integrator_step(b, rhs_exp_sin, &d, 0.0, dt, NULL), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_integrator_step_verlet(b, accel_oscillator, &d, 0.0, dt, ya, yb),
                  PX_STATUS_INVALID);
  PX_CHECK(px_integrator_history_length(b) == 4);
  PX_CHECK_STATUS(ctx, px_integrator_step(b, rhs_fails, &d, 0.25, dt, yb), PX_STATUS_NUMERIC);
  PX_CHECK(px_integrator_history_length(b) == 0 && px_integrator_steps(b) == 12);
  /* ABM4 path: the first evaluation is the predictor's, at t + dt */
  PX_CHECK_MSG(
      strstr(px_context_message(ctx), "abm4 step 12: right-hand side at t = 0.2999") != NULL,
      "message: %s", px_context_message(ctx));
  PX_CHECK(strstr(px_context_message(ctx), "refuses t = 0.3") != NULL);
  {
    struct px_buffer *small = NULL;
    struct px_integrator *c = NULL;
    PX_CHECK_OK(ctx, px_buffer_create(be, "small", 8 * (NCOMP - 1), &small));
    PX_CHECK_STATUS(ctx, px_integrator_step(b, rhs_exp_sin, &d, 0.0, dt, small), PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_integrator_create(be, PX_INTEGRATOR_RK4, PX_DTYPE_U32, 4, &c),
                    PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx,
                    px_integrator_create(be, (enum px_integrator_method)9, PX_DTYPE_F64, 4, &c),
                    PX_STATUS_INVALID);
    PX_CHECK_OK(ctx, px_integrator_create(be, PX_INTEGRATOR_VERLET, PX_DTYPE_F64, NCOMP, &c));
    PX_CHECK_STATUS(ctx, px_integrator_step(c, rhs_exp_sin, &d, 0.0, dt, ya), PX_STATUS_INVALID);
    PX_CHECK_STATUS(ctx, px_integrator_step_verlet(c, accel_oscillator, &d, 0.0, dt, ya, ya),
                    PX_STATUS_INVALID);
    /* resize: n follows, history gone */
    PX_CHECK_OK(ctx, px_integrator_resize(b, NCOMP - 1));
    PX_CHECK(px_integrator_size(b) == NCOMP - 1 && px_integrator_history_length(b) == 0);
    px_integrator_free(c);
    px_buffer_free(small);
  }
  {
    enum px_integrator_method m;
    PX_CHECK_OK(ctx, px_integrator_method_parse("abm4", &m));
    PX_CHECK(m == PX_INTEGRATOR_ABM4);
    PX_CHECK(px_integrator_method_parse("rk5", &m) == PX_STATUS_INVALID);
  }
  px_integrator_free(a);
  px_integrator_free(b);
  px_buffer_free(ya);
  px_buffer_free(yb);
}

/* Verlet's cached acceleration is history too. */
static void test_verlet_checkpoint(struct px_context *ctx, struct px_backend *be) {
  struct rhs_data d;
  struct px_integrator *a = NULL, *b = NULL;
  struct px_buffer *xa, *va, *xb, *vb;
  double x[NCOMP], v[NCOMP], acc[NCOMP], r1[NCOMP], r2[NCOMP], dt = 0.01;
  size_t i;
  int s;
  d.p = PX_PRECISION_DOUBLE;
  d.ctx = ctx;
  d.calls = 0;
  for (i = 0; i < NCOMP; ++i) {
    x[i] = y0_of(i);
    v[i] = 0.1;
  }
  xa = px_test_upload(ctx, be, "xa", d.p, NCOMP, x);
  va = px_test_upload(ctx, be, "va", d.p, NCOMP, v);
  PX_CHECK_OK(ctx, px_integrator_create(be, PX_INTEGRATOR_VERLET, PX_DTYPE_F64, NCOMP, &a));
  PX_CHECK_OK(ctx, px_integrator_create(be, PX_INTEGRATOR_VERLET, PX_DTYPE_F64, NCOMP, &b));
  if (!a || !b) return;
  for (s = 0; s < 5; ++s)
    PX_CHECK_OK(ctx, px_integrator_step_verlet(a, accel_oscillator, &d, s * dt, dt, xa, va));
  PX_CHECK(px_integrator_history_length(a) == 1);
  PX_CHECK_OK(ctx, px_integrator_history_read(a, 0, acc));
  px_test_download(ctx, xa, d.p, NCOMP, x);
  px_test_download(ctx, va, d.p, NCOMP, v);
  xb = px_test_upload(ctx, be, "xb", d.p, NCOMP, x);
  vb = px_test_upload(ctx, be, "vb", d.p, NCOMP, v);
  PX_CHECK_OK(ctx, px_integrator_set_state(b, 5, dt, 1));
  PX_CHECK_OK(ctx, px_integrator_history_write(b, 0, acc));
  d.calls = 0;
  for (s = 5; s < 10; ++s) {
    PX_CHECK_OK(ctx, px_integrator_step_verlet(a, accel_oscillator, &d, s * dt, dt, xa, va));
    PX_CHECK_OK(ctx, px_integrator_step_verlet(b, accel_oscillator, &d, s * dt, dt, xb, vb));
  }
  PX_CHECK(d.calls == 10); /* the restored one did not recompute a_n */
  px_test_download(ctx, xa, d.p, NCOMP, r1);
  px_test_download(ctx, xb, d.p, NCOMP, r2);
  PX_CHECK(memcmp(r1, r2, sizeof r1) == 0);
  px_test_download(ctx, va, d.p, NCOMP, r1);
  px_test_download(ctx, vb, d.p, NCOMP, r2);
  PX_CHECK(memcmp(r1, r2, sizeof r1) == 0);
  px_integrator_free(a);
  px_integrator_free(b);
  px_buffer_free(xa);
  px_buffer_free(va);
  px_buffer_free(xb);
  px_buffer_free(vb);
}

int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  struct px_backend *be;
  const char *name = argc > 1 ? argv[1] : "cpu";
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  be = px_test_backend(ctx, name, 0);
  test_orders(ctx, be);
  test_checkpoint(ctx, be);
  test_verlet_checkpoint(ctx, be);
  px_backend_free(be);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_compute_integrate");
}
