/* The serial parts of a step shared by the host engines (vortex_host.h):
 * the sheet's solve and shedding, the exact sheet near the wall, the
 * newborns' velocity, the loads' sums, the move (Euler, Heun), the absorbed
 * circulation, and restructuring's removal, merges and compaction. */
#include "solvers/vortex/vortex_host.h"

#include <math.h>
#include <omp.h>
#include <string.h>

#include "partix/memory.h"
#include "partix/timer.h"
#include "solvers/vortex/vortex_core_impl.h"
#include "solvers/vortex/vortex_ranks.h"

#define PX_REAL double
#include "kernels/px_kernel.h"
#include "solvers/vortex/vortex_kernel.h"

/* ------------------------------------------------------------------------- */
/* The step's start */

/* Room for the step's newborns; a non-finite vortex stops the run here, named,
 * before its velocity spreads to the others. */
/* Wake loops from this size on run on the engine's threads (each vortex's
 * result its own: the same bits on any number); below, a team's start
 * costs more than the loop. */
#define VX_HOST_PARALLEL 16384

/* The first vortex i with a[i], b[i] or c[i] not finite, SIZE_MAX when
 * none (a pass on all threads, then, only where one is bad, a scan for the
 * first; two arrays: pass one of them twice). */
static size_t wake_nonfinite(const struct px_vortex_engine *e, const double *a, const double *b,
                             const double *c) {
  const size_t n = e->w.n;
  unsigned ok = 1u;
#pragma omp parallel for num_threads(e->cfg.threads) reduction(& : ok) if (n >= VX_HOST_PARALLEL)
  for (size_t i = 0; i < n; ++i)
    ok &= (unsigned)(isfinite(a[i]) && isfinite(b[i]) && isfinite(c[i]));
  for (size_t i = 0; !ok && i < n; ++i)
    if (!isfinite(a[i]) || !isfinite(b[i]) || !isfinite(c[i])) return i;
  return SIZE_MAX;
}

enum px_status px_vortex_host_begin(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  PX_TRY(px_vortex_ensure_work(e, w->n + e->pan.n));
  const size_t i = wake_nonfinite(e, w->x, w->y, w->g);
  if (i != SIZE_MAX)
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "step %ld: vortex %zu has a non-finite position or circulation "
                           "(x = %g, y = %g, Gamma = %g)",
                           e->step, i, w->x[i], w->y[i], w->g[i]);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 1: the sheet */

void px_vortex_gauss_points(struct px_vortex_engine *e) {
  static const double gauss2 = 0.21132486540518711775; /* (1 - 1/sqrt 3)/2 */
  const struct px_vortex_panels *p = &e->pan;
  double *gx = e->rhs_u, *gy = e->rhs_v;
  for (size_t i = 0; i < p->n; ++i) {
    double dx = p->x1[i] - p->x0[i], dy = p->y1[i] - p->y0[i];
    gx[2 * i] = p->x0[i] + gauss2 * dx;
    gy[2 * i] = p->y0[i] + gauss2 * dy;
    gx[2 * i + 1] = p->x1[i] - gauss2 * dx;
    gy[2 * i + 1] = p->y1[i] - gauss2 * dy;
  }
}

void px_vortex_newborn_cap_warn(struct px_vortex_engine *e, const double *sol) {
  if (e->cap_warned) return;
  const struct px_vortex_panels *p = &e->pan;
  const double gmax = e->cfg.gamma_max;
  double worst = 0.0;
  size_t k_worst = 0, capped = 0;
  for (size_t k = 0; k < p->n; ++k) {
    double gl = fabs(sol[k] * p->len[k]);
    if (!vx_newborn_capped(gl, gmax)) continue;
    ++capped;
    if (gl > worst) {
      worst = gl;
      k_worst = k;
    }
  }
  if (!capped) return;
  e->cap_warned = 1;
  px_log(e->ctx, PX_LOG_LEVEL_WARN,
         "step %ld: vortex.gamma_max = %g m^2/s asks for more than %d newborn vortices on %zu "
         "of %zu panels; each sheds at most %d, so their newborns are stronger than gamma_max: "
         "the effective gamma_max is up to %g m^2/s (panel %zu of body %d, |gamma L| = %g "
         "m^2/s), and a smaller gamma_max refines no further there (docs/vortex.md, \"Near-wall "
         "resolution\"; warned once a run)",
         e->step, gmax, VX_NEWBORN_MAX, capped, p->n, VX_NEWBORN_MAX, worst / VX_NEWBORN_MAX,
         k_worst, p->body[k_worst], worst);
}

enum px_status px_vortex_sheet_shed(struct px_vortex_engine *e, double vx, double vy,
                                    const double *absorbed) {
  struct px_context *ctx = e->ctx;
  const struct px_vortex_panels *p = &e->pan;
  struct px_vortex_wake *w = &e->w;
  size_t n = p->n;
  double *rhs = e->sol;
  for (size_t b = 0; b < p->nbody; ++b) {
    double s = 0.0;
    for (size_t k = p->first[b]; k < p->first[b + 1] && absorbed; ++k) s += absorbed[k];
    rhs[n + b] = s;
  }
  for (size_t i = 0; i < p->nsys; ++i)
    if (!isfinite(rhs[i]))
      return px_context_fail(ctx, PX_STATUS_NUMERIC,
                             "step %ld: non-finite velocity at panel %zu (free stream (%g, %g)); "
                             "the wake holds non-finite values",
                             e->step, i, vx, vy);
  if (e->cfg.precision == PX_PRECISION_SINGLE) {
    float *fr = e->fwork;
    for (size_t i = 0; i < p->nsys; ++i) fr[i] = (float)rhs[i];
    PX_TRY(px_vortex_panels_solve_f(ctx, p, fr));
    for (size_t i = 0; i < p->nsys; ++i) rhs[i] = fr[i];
  } else {
    PX_TRY(px_vortex_panels_solve(ctx, p, rhs, e->cfg.threads));
  }
  /* runaway check: the sheet intensity is a slip velocity */
  for (size_t k = 0; k < n; ++k) {
    if (!isfinite(rhs[k]) || fabs(rhs[k]) > 1e3 * e->cfg.vref)
      return px_context_fail(ctx, PX_STATUS_NUMERIC,
                             "step %ld: runaway vorticity generation: sheet intensity %g on panel "
                             "%zu of body %d (more than 1000 v_ref); the wake is unstable: reduce "
                             "dt or check eps, eps_col and gamma_max",
                             e->step, rhs[k], k, p->body[k]);
  }
  px_vortex_newborn_cap_warn(e, rhs);
  /* shed: gamma_k L_k as m_k vortices a distance delta off the panel */
  size_t add = 0;
  for (size_t k = 0; k < n; ++k)
    add += (size_t)vx_newborn_count(fabs(rhs[k] * p->len[k]), e->cfg.gamma_max,
                                    e->cfg.vortex_per_panel);
  PX_TRY(px_vortex_wake_reserve(ctx, w, w->n + add));
  size_t q = w->n;
  for (size_t k = 0; k < n; ++k) {
    double gl = rhs[k] * p->len[k];
    size_t m = (size_t)vx_newborn_count(fabs(gl), e->cfg.gamma_max, e->cfg.vortex_per_panel);
    double nx = p->ty[k], ny = -p->tx[k];
    e->born_first[k] = q;
    for (size_t j = 0; j < m; ++j) {
      double f = ((double)j + 0.5) / (double)m;
      w->x[q] = p->x0[k] + f * (p->x1[k] - p->x0[k]) + e->cfg.delta * nx;
      w->y[q] = p->y0[k] + f * (p->y1[k] - p->y0[k]) + e->cfg.delta * ny;
      w->g[q] = gl / (double)m;
      w->born[q] = (int32_t)k;
      ++q;
    }
  }
  e->born_first[n] = q;
  e->n_born = add;
  w->n = q;
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 2: near the wall, and the newborns */

enum px_status px_vortex_newborn_convective(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *p = &e->pan;
  for (size_t i = w->n - e->n_born; i < w->n; ++i) {
    size_t k = (size_t)w->born[i];
    w->u[i] = 0.5 * e->sol[k] * p->tx[k];
    w->v[i] = 0.5 * e->sol[k] * p->ty[k];
  }
  const size_t i = wake_nonfinite(e, w->u, w->v, w->u);
  if (i != SIZE_MAX)
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "step %ld: vortex %zu at (%g, %g) has a non-finite convective "
                           "velocity (%g, %g)",
                           e->step, i, w->x[i], w->y[i], w->u[i], w->v[i]);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 4: loads */

void px_vortex_panel_radius(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  size_t n = e->pan.n, nold = w->n - e->n_born;
  for (size_t k = 0; k < n; ++k) e->pe[k] = 0.0;
  for (size_t k = 0; k < n; ++k) e->omega[k] = 0.0; /* used as a counter first */
  for (size_t i = nold; i < w->n; ++i) {
    size_t k = (size_t)w->born[i];
    e->pe[k] += w->e[i];
    e->omega[k] += 1.0;
  }
  for (size_t k = 0; k < n; ++k)
    e->pe[k] = e->omega[k] > 0.0 ? e->pe[k] / e->omega[k] : e->cfg.eps_min;
}

/* The forces of the vortex-impulse form and the impulse diagnostics. */
void px_vortex_forces(struct px_vortex_engine *e) {
  const struct px_vortex_wake *w = &e->w;
  const struct px_vortex_panels *p = &e->pan;
  /* forces: F = (rho/dt) sum_k delta_k (k x r_k) with delta_k = gamma_k L_k -
   * absorbed_k, the vorticity flux through panel k in the step (Dynnikova's
   * vortex-impulse form; VM2D Mechanics2DRigidImmovable), plus the friction.
   * The force is the rate of change of the vortex impulse rho sum Gamma_i
   * (k x r_i): generation gives the flux term, the motion of the vortices
   * rho sum Gamma_i (k x (V_i + W_i)), whose convective part vanishes (the
   * pair sums are antisymmetric, the circulation sums to zero) and whose
   * diffusive part is the friction: rho sum Gamma_i (k x W_i) is the viscous
   * stress at the wall in the continuum limit (sum Gamma W = -nu int grad omega
   * dA = nu contour integral of omega n). That drift term is the default
   * friction (below); rho nu omega_k L_k tau_k with the wall-vorticity estimate
   * is the alternative (friction_wall). Moment likewise, with
   * rho sum Gamma_i (r_i - c) . W_i. */
  double rho = e->cfg.rho, dt = e->cfg.dt, nu = e->cfg.nu;
  double q = 0.5 * rho * e->cfg.vref * e->cfg.vref;
  for (size_t b = 0; b < p->nbody; ++b) {
    double cx = e->cfg.moment_center[b][0], cy = e->cfg.moment_center[b][1];
    double fx = 0.0, fy = 0.0, m = 0.0, ffx = 0.0, ffy = 0.0, fm = 0.0;
    for (size_t k = p->first[b]; k < p->first[b + 1]; ++k) {
      double d = e->sol[k] * p->len[k] - e->through[k];
      double rx = 0.5 * (p->x0[k] + p->x1[k]) - cx, ry = 0.5 * (p->y0[k] + p->y1[k]) - cy;
      fx += -d * ry;
      fy += d * rx;
      m += 0.5 * d * (rx * rx + ry * ry);
      double tf = rho * nu * e->omega[k] * p->len[k];
      ffx += tf * p->tx[k];
      ffy += tf * p->ty[k];
      fm += tf * (rx * p->ty[k] - ry * p->tx[k]);
    }
    struct px_vortex_loads *L = &e->loads[b];
    L->fx_wall = ffx;
    L->fy_wall = ffy;
    L->fx_fric = ffx;
    L->fy_fric = ffy;
    L->m_fric = fm;
    L->fx = rho / dt * fx + ffx;
    L->fy = rho / dt * fy + ffy;
    L->m = rho / dt * m + fm;
    double c = e->cfg.ref_length[b];
    L->cx = L->fx / (q * c);
    L->cy = L->fy / (q * c);
    L->cm = L->m / (q * c * c);
    double ab = 0.0;
    for (size_t k = p->first[b]; k < p->first[b + 1]; ++k) ab += e->through[k];
    L->absorbed = ab;
  }
  /* impulse balance of the vortices' own motion, rho sum Gamma_i (k x V_i)
   * and rho sum Gamma_i (k x W_i), per body: each vortex counts for the body
   * whose moment centre is nearest (one body: all of them) */
  {
    double cv[2 * PX_VORTEX_MAX_BODIES], dfv[3 * PX_VORTEX_MAX_BODIES];
    memset(cv, 0, sizeof cv);
    memset(dfv, 0, sizeof dfv);
    for (size_t i = 0; i < w->n; ++i) {
      size_t bb = 0;
      double best = INFINITY;
      for (size_t b = 0; b < p->nbody && p->nbody > 1; ++b) {
        double dx = w->x[i] - e->cfg.moment_center[b][0], dy = w->y[i] - e->cfg.moment_center[b][1];
        if (dx * dx + dy * dy < best) {
          best = dx * dx + dy * dy;
          bb = b;
        }
      }
      double g = w->g[i];
      cv[2 * bb] += -g * w->v[i];
      cv[2 * bb + 1] += g * w->u[i];
      dfv[3 * bb] += -g * w->wv[i];
      dfv[3 * bb + 1] += g * w->wu[i];
      dfv[3 * bb + 2] += g * ((w->x[i] - e->cfg.moment_center[bb][0]) * w->wu[i] +
                              (w->y[i] - e->cfg.moment_center[bb][1]) * w->wv[i]);
    }
    for (size_t b = 0; b < p->nbody; ++b) {
      struct px_vortex_loads *L = &e->loads[b];
      L->fx_conv = rho * cv[2 * b];
      L->fy_conv = rho * cv[2 * b + 1];
      L->fx_diff = rho * dfv[3 * b];
      L->fy_diff = rho * dfv[3 * b + 1];
      if (!e->cfg.friction_wall) {
        /* the friction the model's momentum balance implies (default) */
        L->fx += L->fx_diff - L->fx_fric;
        L->fy += L->fy_diff - L->fy_fric;
        L->m += rho * dfv[3 * b + 2] - L->m_fric;
        L->fx_fric = L->fx_diff;
        L->fy_fric = L->fy_diff;
        L->m_fric = rho * dfv[3 * b + 2];
        double c = e->cfg.ref_length[b];
        L->cx = L->fx / (q * c);
        L->cy = L->fy / (q * c);
        L->cm = L->m / (q * c * c);
      }
    }
  }
}

/* ------------------------------------------------------------------------- */
/* Block 5: the move */

/* Block 5 with rk2: Heun's method. The first stage's velocities V1 and W1
 * are those of the step's start; the predictor moves every vortex by (V1 +
 * W1) dt (unless that move crosses a panel, see below), a second sheet is
 * solved for the predicted wake (no absorbed circulation to return, the free
 * stream of the step's end) and shed as temporary vortices on the panels,
 * whose field, with the exact-sheet correction near the wall, gives V2 at the
 * predicted positions, and the VVD of the predicted wake with them gives W2
 * (the diffusive block once more, timed as such); the vortices then move from
 * their start by ((V1 + V2) / 2 + (W1 + W2) / 2) dt into xn, and the
 * temporaries go. The first stage's sheet stays the step's sheet (loads,
 * pressure). Until 2026-11-26 the diffusion stayed explicit Euler (W1 alone):
 * the lift amplitude of the cylinder at Re = 100 then still moved by 5% from
 * dt = 0.02 to 0.01 (docs/notes/vortex.md, "Time stepping"). */
static enum px_status heun(struct px_vortex_engine *e, const struct px_vortex_stages *st) {
  struct px_vortex_wake *w = &e->w;
  struct px_context *ctx = e->ctx;
  const size_t n1 = w->n, np = e->pan.n, ns = e->pan.nsys;
  const double dt = e->cfg.dt;
  if (n1 > e->rk_cap || !e->rk) {
    px_mem_free(ctx, e->rk);
    e->rk_cap = n1 + n1 / 2 + 64;
    e->rk = px_mem_alloc(ctx, "vortex.work", (6 * e->rk_cap + ns) * sizeof(double));
    if (!e->rk) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (rk2 stage)");
  }
  if (!e->rk_born) {
    e->rk_born = px_mem_alloc(ctx, "vortex.work", (np + 1) * sizeof(size_t));
    if (!e->rk_born) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (rk2 stage)");
  }
  double *x1 = e->rk, *y1 = x1 + e->rk_cap, *u1 = y1 + e->rk_cap, *v1 = u1 + e->rk_cap;
  double *wu1 = v1 + e->rk_cap, *wv1 = wu1 + e->rk_cap, *sol1 = wv1 + e->rk_cap;
  memcpy(x1, w->x, n1 * sizeof(double));
  memcpy(y1, w->y, n1 * sizeof(double));
  memcpy(u1, w->u, n1 * sizeof(double));
  memcpy(v1, w->v, n1 * sizeof(double));
  memcpy(wu1, w->wu, n1 * sizeof(double));
  memcpy(wv1, w->wv, n1 * sizeof(double));
  memcpy(sol1, e->sol, ns * sizeof(double));
  if (np > 0) memcpy(e->rk_born, e->born_first, (np + 1) * sizeof(size_t));
  const size_t born1 = e->n_born;
  /* The predictor. A vortex whose predicted move crosses a panel would be
   * absorbed at the step's end; left inside the body it would sit next to the
   * panels' control points and bend the second sheet and its neighbours'
   * second-stage velocities (about 1% of the vortices per step on the
   * cylinder and the airfoil; on the NACA case C_y went from Euler's 0.29 to
   * 0.44). It waits at its start position instead, where the second stage
   * evaluates the predicted field. */
  /* The crossing tests over this rank's contiguous share of the vortices
   * (vortex_ranks.h; all of them on one rank) into e->hit (free until the
   * non-penetration block), gathered: 4 bytes a vortex; every rank then
   * moves every vortex alike. */
  int oom = 0;
  size_t lo = 0, hi = n1;
  px_vortex_ranks_share(e, n1, &lo, &hi);
  /* the predicted positions into xn, yn (free until the step's end) */
  double *qx = e->xn, *qy = e->yn;
#pragma omp parallel for num_threads(e->cfg.threads) if (n1 >= VX_HOST_PARALLEL)
  for (size_t i = 0; i < n1; ++i) {
    qx[i] = x1[i] + (u1[i] + wu1[i]) * dt;
    qy[i] = y1[i] + (v1[i] + wv1[i]) * dt;
  }
  if (np > 0 && st->crossings) {
    st->crossings(e, x1, y1, qx, qy, lo, hi, e->hit, &oom);
  } else {
#pragma omp parallel for num_threads(e->cfg.threads) schedule(dynamic, 256)
    for (long li = (long)lo; li < (long)hi; ++li) {
      size_t i = (size_t)li;
      e->hit[i] = np > 0 ? st->crossed(e, x1[i], y1[i], qx[i], qy[i], &oom) : -1;
    }
  }
  enum px_status s =
      oom ? px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)") : PX_STATUS_OK;
  PX_TRY(px_vortex_ranks_gather_runs(e, s, n1, lo, hi, e->hit, sizeof(int32_t)));
#pragma omp parallel for num_threads(e->cfg.threads) if (n1 >= VX_HOST_PARALLEL)
  for (size_t i = 0; i < n1; ++i) {
    w->x[i] = e->hit[i] >= 0 ? x1[i] : qx[i];
    w->y[i] = e->hit[i] >= 0 ? y1[i] : qy[i];
  }
  double vx, vy;
  px_vortex_vinf(&e->cfg, e->time + dt, &vx, &vy);
  s = st->generation(e, vx, vy, NULL);
  if (s == PX_STATUS_OK) s = px_vortex_ensure_work(e, w->n);
  if (s == PX_STATUS_OK) s = st->convective(e, vx, vy);
  if (s == PX_STATUS_OK) { /* W2: counted in the diffusive block, not in the move's */
    double t0 = px_time_now(), c0 = px_vortex_cpu_seconds();
    s = st->diffusive(e);
    double t = px_time_now() - t0, c = px_vortex_cpu_seconds() - c0;
    e->block_time[PX_VORTEX_BLOCK_DIFFUSIVE] += t;
    e->block_cpu[PX_VORTEX_BLOCK_DIFFUSIVE] += c;
    e->block_time[PX_VORTEX_BLOCK_MOVE] -= t;
    e->block_cpu[PX_VORTEX_BLOCK_MOVE] -= c;
  }
  if (s == PX_STATUS_OK)
#pragma omp parallel for num_threads(e->cfg.threads) if (n1 >= VX_HOST_PARALLEL)
    for (size_t i = 0; i < n1; ++i) {
      double um = 0.5 * (u1[i] + w->u[i]), vm = 0.5 * (v1[i] + w->v[i]);
      double wum = 0.5 * (wu1[i] + w->wu[i]), wvm = 0.5 * (wv1[i] + w->wv[i]);
      e->xn[i] = x1[i] + (um + wum) * dt;
      e->yn[i] = y1[i] + (vm + wvm) * dt;
      w->u[i] = um;
      w->v[i] = vm;
      w->wu[i] = wum;
      w->wv[i] = wvm;
    }
  /* back to the step's wake and sheet (also after a failure: the state stays
   * the step's start for the diagnosis and the checkpoint) */
  if (s != PX_STATUS_OK) {
    memcpy(w->u, u1, n1 * sizeof(double));
    memcpy(w->v, v1, n1 * sizeof(double));
    memcpy(w->wu, wu1, n1 * sizeof(double));
    memcpy(w->wv, wv1, n1 * sizeof(double));
  }
  w->n = n1;
  memcpy(w->x, x1, n1 * sizeof(double));
  memcpy(w->y, y1, n1 * sizeof(double));
  memcpy(e->sol, sol1, ns * sizeof(double));
  if (np > 0) memcpy(e->born_first, e->rk_born, (np + 1) * sizeof(size_t));
  e->n_born = born1;
  return s;
}

enum px_status px_vortex_move(struct px_vortex_engine *e, const struct px_vortex_stages *st) {
  struct px_vortex_wake *w = &e->w;
  if (e->cfg.rk2) return heun(e, st);
  const double dt = e->cfg.dt;
  const size_t n = w->n;
#pragma omp parallel for num_threads(e->cfg.threads) if (n >= VX_HOST_PARALLEL)
  for (size_t i = 0; i < n; ++i) {
    e->xn[i] = w->x[i] + (w->u[i] + w->wu[i]) * dt;
    e->yn[i] = w->y[i] + (w->v[i] + w->wv[i]) * dt;
  }
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------------- */
/* Block 6: non-penetration */

void px_vortex_absorb(struct px_vortex_engine *e) {
  const struct px_vortex_wake *w = &e->w;
  for (size_t k = 0; k < e->pan.n; ++k) e->through[k] = 0.0;
  size_t na = 0;
  for (size_t i = 0; i < w->n; ++i)
    if (e->hit[i] >= 0) {
      e->through[e->hit[i]] += w->g[i];
      ++na;
    }
  e->n_absorbed = na;
}

/* ------------------------------------------------------------------------- */
/* Block 7: restructuring */

size_t px_vortex_drop(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  const size_t n = w->n;
  const double far2 = e->cfg.dist_far * e->cfg.dist_far;
  /* per thread of at most 64: survivors and far ones of its share */
  enum { TEAM = 64 };
  size_t cnt[2 * TEAM];
  const int threads =
      n < VX_HOST_PARALLEL ? 1 : (e->cfg.threads < TEAM ? e->cfg.threads : (int)TEAM);
  size_t m = 0, nfar = 0;
  /* each thread its contiguous share: the survivors marked (e->flag) and
   * counted, then, after every share has read e->hit, its survivors'
   * positions and old indices written after those of the shares before it
   * (the serial order; nothing read in the second pass is written) */
#pragma omp parallel num_threads(threads)
  {
    const size_t id = (size_t)omp_get_thread_num(), team = (size_t)omp_get_num_threads();
    const size_t lo = n * id / team, hi = n * (id + 1) / team;
    size_t c = 0, f = 0;
    for (size_t i = lo; i < hi; ++i) {
      const double dx = e->xn[i] - e->center[0], dy = e->yn[i] - e->center[1];
      const int live = e->hit[i] < 0 && w->g[i] != 0.0, near = !(dx * dx + dy * dy > far2);
      e->flag[i] = (uint8_t)(live && near);
      c += (size_t)(live && near);
      f += (size_t)(live && !near);
    }
    cnt[2 * id] = c;
    cnt[2 * id + 1] = f;
#pragma omp barrier
    size_t k = 0;
    for (size_t j = 0; j < id; ++j) k += cnt[2 * j];
    for (size_t i = lo; i < hi; ++i) {
      if (!e->flag[i]) continue;
      w->x[k] = e->xn[i];
      w->y[k] = e->yn[i];
      e->hit[k] = (int32_t)i;
      ++k;
    }
#pragma omp single
    for (size_t j = 0; j < team; ++j) {
      m += cnt[2 * j];
      nfar += cnt[2 * j + 1];
    }
  }
  w->n = m;
  e->n_far = nfar;
  e->n_merged = 0;
  return m;
}

void px_vortex_drop_finish(struct px_vortex_engine *e) {
  struct px_vortex_wake *w = &e->w;
  /* ascending: old index hit[k] >= k, not yet overwritten */
  for (size_t k = 0; k < w->n; ++k) {
    const size_t i = (size_t)e->hit[k];
    w->g[k] = w->g[i];
    w->u[k] = w->u[i];
    w->v[k] = w->v[i];
    w->wu[k] = w->wu[i];
    w->wv[k] = w->wv[i];
    w->e[k] = w->e[i];
    w->born[k] = -1;
  }
}

enum px_status px_vortex_merge(struct px_vortex_engine *e, px_vortex_crossed_fn crossed) {
  struct px_vortex_wake *w = &e->w;
  struct px_context *ctx = e->ctx;
  const size_t m = w->n;
  const struct px_vortex_tree *t = &e->tree;
  int oom = 0;
  /* sequential merge in sorted order (deterministic) */
  memset(e->flag, 0, m);
  double *nx = e->xn, *ny = e->yn; /* reused: positions in sorted order */
  size_t merged = 0;
  memcpy(nx, t->sx, m * sizeof *nx);
  memcpy(ny, t->sy, m * sizeof *ny);
  for (size_t sp = 0; sp < m; ++sp) {
    if (e->flag[sp]) continue;
    int32_t sq = e->partner[sp];
    if (sq < 0 || e->flag[sq]) continue;
    size_t i = (size_t)e->hit[t->order[sp]], j = (size_t)e->hit[t->order[(size_t)sq]];
    double gi = w->g[i], gj = w->g[j], g = gi + gj;
    double x, y;
    vx_merge_position(gi, gj, nx[sp], ny[sp], nx[sq], ny[sq], &x, &y);
    /* a merge must not carry circulation into a body */
    if (crossed(e, nx[sp], ny[sp], x, y, &oom) >= 0 || crossed(e, nx[sq], ny[sq], x, y, &oom) >= 0)
      continue;
    nx[sp] = x;
    ny[sp] = y;
    w->g[i] = g;
    w->g[j] = 0.0;
    e->flag[sp] = e->flag[sq] = 1;
    ++merged;
  }
  if (oom) {
    px_vortex_drop_finish(e);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (neighbour lists)");
  }
  e->n_merged = merged;
  /* compact in sorted (Morton) order: keeps the wake spatially coherent */
  /* gather into sorted order through scratch (the diffusive velocities are
   * not needed any more); the convective velocities are kept for outputs */
  double *tg = w->wu, *te = w->wv, *tu = w->s1, *tv = w->s2;
  const int threads = m >= VX_HOST_PARALLEL ? e->cfg.threads : 1;
  size_t *cnt = px_mem_alloc(ctx, "vortex.work", (size_t)(threads + 1) * sizeof(size_t));
  if (!cnt) {
    px_vortex_drop_finish(e);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory (merge)");
  }
  /* each thread its contiguous share: gathered, its survivors counted, then
   * written after those of the shares before it (the serial order) */
#pragma omp parallel num_threads(threads)
  {
    const size_t id = (size_t)omp_get_thread_num(), team = (size_t)omp_get_num_threads();
    const size_t lo = m * id / team, hi = m * (id + 1) / team;
    size_t c = 0, k = 0;
    for (size_t sp = lo; sp < hi; ++sp) {
      size_t i = (size_t)e->hit[t->order[sp]];
      tg[sp] = w->g[i];
      te[sp] = w->e[i];
      tu[sp] = w->u[i];
      tv[sp] = w->v[i];
      c += tg[sp] != 0.0;
    }
    cnt[id] = c;
#pragma omp barrier
    for (size_t j = 0; j < id; ++j) k += cnt[j];
    for (size_t sp = lo; sp < hi; ++sp) {
      if (tg[sp] == 0.0) continue;
      w->x[k] = nx[sp];
      w->y[k] = ny[sp];
      w->g[k] = tg[sp];
      w->e[k] = te[sp];
      w->u[k] = tu[sp];
      w->v[k] = tv[sp];
      ++k;
    }
#pragma omp barrier
    /* the diffusive velocities' scratch emptied after every share is read */
    const size_t n2 = k - c; /* this share's first output */
    for (size_t i = n2; i < k; ++i) {
      w->wu[i] = w->wv[i] = 0.0;
      w->born[i] = -1;
    }
#pragma omp single
    {
      size_t total = 0;
      for (size_t j = 0; j < team; ++j) total += cnt[j];
      w->n = total;
    }
  }
  px_mem_free(ctx, cnt);
  return PX_STATUS_OK;
}

enum px_status px_vortex_diffusive_finite(struct px_vortex_engine *e) {
  const struct px_vortex_wake *w = &e->w;
  const size_t i = wake_nonfinite(e, w->wu, w->wv, w->wu);
  if (i != SIZE_MAX)
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "step %ld: vortex %zu at (%g, %g) has a non-finite diffusive "
                           "velocity (eps* = %g)",
                           e->step, i, w->x[i], w->y[i], w->e[i]);
  return PX_STATUS_OK;
}
