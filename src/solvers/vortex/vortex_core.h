/* The vortex-element engine: state and time step of 2D viscous flow around
 * fixed profiles by the viscous vortex domains (VVD) method, on plain arrays.
 * The solver glue (vortex.c) builds it from a case and adds outputs and
 * checkpoints; tests and benchmarks drive it directly.
 *
 * One step from t to t + dt (the seven blocks of the original code):
 *  1. generation: right-hand side from the free stream and the wake at the
 *     panels, back-substitution (vortex_panels.h), the sheet gamma_k L_k shed
 *     as new vortices a distance delta off each panel;
 *  2. convective velocities V = V_inf(t) + sum of smoothed vortices; a newborn
 *     vortex moves with the mean of the two limits of the sheet, gamma tau / 2;
 *  3. diffusive velocities (VVD): W = nu (I2/(e I1) + I3/I0), |W| <= 1.5 V_ref;
 *  4. loads from the vorticity flux and the wall friction;
 *  5. explicit Euler: r += (V + W) dt;
 *  6. non-penetration: a vortex whose path crosses a panel is removed and its
 *     circulation credited to that panel;
 *  7. restructuring: far and empty vortices removed, close pairs merged.
 * Every loop computes each target on its own (no atomics) and reductions run
 * in a fixed order, so results do not depend on the thread count. */
#ifndef PX_VORTEX_CORE_H
#define PX_VORTEX_CORE_H

#include <stddef.h>
#include <stdint.h>

#include "partix/backend.h"
#include "partix/context.h"
#include "partix/nbody.h"
#include "partix/types.h"
#include "core/tuner.h"
#include "solvers/vortex/vortex_panels.h"
#include "solvers/vortex/vortex_profile.h"
#include "solvers/vortex/vortex_tree.h"

enum px_vortex_ramp {
  PX_VORTEX_RAMP_IMPULSE = 0, /* full speed from t = 0 */
  PX_VORTEX_RAMP_LINEAR = 1,  /* V_inf t / T for t < T */
  PX_VORTEX_RAMP_COSINE = 2   /* V_inf (1 - cos(pi t / T)) / 2 for t < T */
};

/* the VVD's particle term away from walls (px_vortex_config.vvd_moments;
 * order = the case file's names) */
enum px_vortex_moments {
  PX_VORTEX_MOMENTS_NONE = 0,      /* I2 / (eps* I1), as published */
  PX_VORTEX_MOMENTS_WAKE = 1,      /* eps* -> M1 / (2 M0), the kernel's discrete moments */
  PX_VORTEX_MOMENTS_COVARIANCE = 2 /* nu V^-1 m, Gaussian-weighted, same sign */
};

/* the case file's names of enum px_vortex_moments, in its order, NULL-ended */
extern const char *const px_vortex_moment_names[];

#define PX_VORTEX_MAX_BODIES 64

struct px_vortex_config {
  double rho;     /* density [kg/m^3] */
  double nu;      /* kinematic viscosity [m^2/s] (> 0) */
  double vinf[2]; /* free stream at full speed [m/s] */
  enum px_vortex_ramp ramp;
  double ramp_time;        /* T of the linear/cosine ramp [s] */
  double vref;             /* reference speed (diffusive cap, coefficients) [m/s] */
  double dt;               /* time step [s] */
  double eps;              /* core radius of the smoothed Biot-Savart kernel [m] */
  double eps_col;          /* merge radius of same-sign vortices [m] */
  double eps_col_opposite; /* merge radius of opposite-sign vortices [m] (0: 2 eps_col, as
                              VM2D) */
  double eps_min;          /* lower bound of eps* [m] (0: px_vortex_eps_min_default; VM2D
                              uses 2 eps_col) */
  double gamma_max;        /* largest circulation of a merged or newborn vortex [m^2/s] */
  double delta;            /* distance of newborn vortices from the wall [m] */
  int vortex_per_panel;    /* newborn vortices per panel (at least) */
  double dist_far;         /* vortices farther than this from the bodies' centre are dropped [m] */
  double cutoff;           /* VVD neighbourhood radius in units of eps* (8) */
  int sheet_exact;         /* near the wall, old vortices feel the newborn sheet as the exact
                              panel integral (as VM2D) instead of as smoothed vortices */
  int rk2;                 /* the move by Heun's method (second order): a predictor step, a
                              sheet solved for the predicted wake, the mean of both stages'
                              convective and diffusive velocities */
  int newborn_rayleigh;    /* a newborn vortex's diffusive velocity in its first step is the mean
                              drift of a vortex sheet diffusing from a flat wall, 2 sqrt(nu /
                              (pi dt)) along the panel normal (Rayleigh, 1), instead of its VVD
                              velocity (0, default, as VM2D) */
  int vvd_moments;         /* enum px_vortex_moments: the VVD's particle term away from walls
                              (no panel within reach); NONE (default): I2 / (eps* I1) as
                              published (VM2D); WAKE: I2 / (I1 M1 / (2 M0)) with the kernel's
                              discrete moments M0 = sum exp(-r/eps*), M1 = sum r exp(-r/eps*)
                              of the vortex's own neighbours, exact for linear vorticity on any
                              isotropic neighbourhood (eps* over-diffuses lattice-like sets by
                              ~11%); COVARIANCE: nu V^-1 m from the Gaussian-weighted mean and
                              covariance of its same-sign neighbours, exact for Gaussian
                              vorticity at any resolution (docs/notes/vortex.md, "The VVD's diffusion
                              rate") */
  int self_in_i1;          /* the vortex itself counts in I1 (default 0, as VM2D: with it the
                              Lamb-Oseen test diffuses too slowly, 8% error against 2.5%) */
  int friction_wall;       /* friction from the wall-vorticity estimate (1) instead of the
                              impulse balance's diffusive drift (0, default); see loads() */
  enum px_precision precision;
  /* The wake's velocity sums (convective velocities, the panels' right-hand
   * side): direct pair sum, fast multipole method, or auto (per sum: direct
   * on opencl and for small sums, FMM above; docs/notes/vortex.md,
   * "Accuracy/speed trade-off of the velocity sums"). */
  enum px_nbody_method method;
  double tolerance; /* FMM: relative L2 error of the sums (1e-12 .. 0.1, default 1e-6);
                       below 1e-5 the FMM sums in double even in single/mixed precision */
  int threads;
  int tune; /* 1: each step on 1 or `threads` threads, the faster measured
               (core/tuner.h; the same bits on any count); 0: always `threads` */
  /* per body */
  double ref_length[PX_VORTEX_MAX_BODIES]; /* for the coefficients [m] */
  double moment_center[PX_VORTEX_MAX_BODIES][2];
};

/* The floor of eps* when the config leaves eps_min at 0: 0.05 L (L the
 * smallest mean panel length of the bodies; 0 without bodies), at least
 * 0.5 sqrt(nu dt). A vortex near a wall moves about eps* nu dt / eps*^2 per
 * step, so a floor far below sqrt(nu dt) lets the near-wall diffusion
 * overshoot (vortices pushed through the wall), and refining gamma_max then
 * makes the friction grow instead of converging (docs/notes/vortex.md, "The
 * gamma_max jump"). The engine warns when nu dt / eps_min^2 > 16. With L = 0:
 * the floor 0.5 sqrt(nu dt) alone. */
double px_vortex_eps_min_default(double nu, double dt, double L);

/* Defaults that do not depend on the problem (the rest must be set): the
 * method as published (VM2D), which the engine-level tests and benchmarks
 * measure: explicit Euler and vvd_moments NONE. The case file's defaults
 * (vortex.c) are the validated settings instead, scheme rk2 and
 * vvd_moments wake (docs/vortex.md, "Parameters and how to choose them"). */
void px_vortex_config_defaults(struct px_vortex_config *cfg);

/* Loads on one body at the last step (global axes; moment counter-clockwise
 * about the body's moment centre). */
struct px_vortex_loads {
  double fx, fy, m;                /* total force [N/m] and moment [N] per unit span */
  double fx_fric, fy_fric, m_fric; /* viscous friction part */
  double cx, cy, cm;               /* coefficients with 0.5 rho V_ref^2 ref_length (^2 for cm) */
  double absorbed;                 /* circulation absorbed by the body in the step [m^2/s] */
  /* diagnostics (per body: each vortex counts for the nearest moment centre;
   * the convective part on the cpu backend only): the rate of change
   * of the wake's impulse from the vortices' own motion, rho sum Gamma_i
   * (-v_i, u_i), split into its convective part (zero up to round-off: the
   * pair sums are antisymmetric and the circulation sums to zero) and its
   * diffusive (VVD) part, the friction implied by the model's momentum
   * balance F = (rho/dt) sum delta_k (k x r_k) + rho sum Gamma_i (k x W_i)
   * [N/m] */
  double fx_conv, fy_conv, fx_diff, fy_diff;
  /* the friction from the VVD estimate of the wall vorticity, rho nu omega_k
   * L_k tau_k summed over the body's panels (used as the friction with
   * friction_wall) [N/m] */
  double fx_wall, fy_wall;
};

/* Timers of the blocks of a step. */
enum px_vortex_block {
  PX_VORTEX_BLOCK_GENERATION = 0,
  PX_VORTEX_BLOCK_CONVECTIVE,
  PX_VORTEX_BLOCK_DIFFUSIVE,
  PX_VORTEX_BLOCK_LOADS,
  PX_VORTEX_BLOCK_MOVE,
  PX_VORTEX_BLOCK_INSIDE,
  PX_VORTEX_BLOCK_RESTRUCT,
  PX_VORTEX_BLOCK_COUNT_
};
const char *px_vortex_block_name(enum px_vortex_block b);

/* The wake: structure of arrays, all owned. */
struct px_vortex_wake {
  size_t n, cap;
  double *x, *y, *g; /* position [m], circulation [m^2/s] */
  double *u, *v;     /* convective velocity of the last step [m/s] */
  double *wu, *wv;   /* diffusive velocity of the last step [m/s] */
  double *e;         /* eps* of the last step [m] */
  double *s1, *s2;   /* scratch */
  int32_t *born;     /* panel a vortex was born on in this step, -1 otherwise */
};

struct px_vortex_nbuf {
  uint32_t *p; /* owned */
  size_t cap;
  /* owned: candidate lists of a leaf's group query and their per-vortex
   * subsets (diffusive block): leaves, panels */
  uint32_t *gl, *fl, *gp, *fp;
  size_t gl_cap, fl_cap, gp_cap, fp_cap;
  double *pd; /* owned: packed VVD neighbours (3 arrays of pd_cap) */
  size_t pd_cap;
  double *pc; /* owned: centres of a group's candidate panels (2 arrays of pc_cap) */
  size_t pc_cap;
  double *lb; /* owned: boxes of a group's candidate leaves, scratch and their point
                 ranges (6 arrays of lb_cap, px_vortex_vvd_leaf_boxes) */
  size_t lb_cap;
  uint32_t *ol; /* owned: the leaves, then panels, of one vortex's own query */
  size_t ol_cap;
  uint32_t *sl; /* owned: the leaves of a query for several groups (VVD) */
  size_t sl_cap;
  double *sb; /* owned: the boxes of sl's leaves (merge search; as lb) */
  size_t sb_cap;
};

struct px_vortex_engine_i;
struct px_comm;

struct px_vortex_engine {
  struct px_context *ctx;               /* borrowed */
  const struct px_vortex_engine_i *ops; /* static: the blocks of a step on this backend
                                           (vortex_engine.h) */
  void *dev;                            /* owned or NULL: the engine's own state (ops->create) */
  struct px_backend *be;                /* borrowed: runs the N-body sums (px_nbody_direct) */
  enum px_precision nb_prec;            /* precision of the pair sums */
  struct px_nbody *nbe;    /* owned: evaluator of the pair sums (cfg.method, cfg.tolerance) */
  struct px_buffer *nb[9]; /* owned: sources x, y, Gamma; outputs u, v; targets x, y; u, v */
  size_t nb_cap[2];        /* elements allocated: sources/outputs, extra targets */
  struct px_vortex_config cfg;
  size_t nbody;
  struct px_vortex_contour body[PX_VORTEX_MAX_BODIES]; /* owned copies */
  struct px_vortex_panels pan;
  struct px_vortex_wake w;
  struct px_vortex_tree tree;  /* over the wake (rebuilt as needed) */
  struct px_vortex_tree ptree; /* over panel midpoints (fixed bodies) */
  double center[2];            /* centre of the bodies' boxes (far removal) */
  double stream_dir[2];        /* unit free-stream direction */
  double s_right, span;        /* downstream end of the bodies and their size (merge growth) */
  /* per panel (owned) */
  double *sol;           /* n + nbody: gamma_k then R_b of the last generation */
  double *through;       /* circulation absorbed by each panel in the last step */
  double *omega;         /* mean wall vorticity over each panel in the last step [1/s] */
  double *pe;            /* panel domain radius (mean eps* of its newborn vortices) */
  size_t *born_first;    /* owned: first newborn vortex of each panel in this step (n + 1) */
  double *rhs_u, *rhs_v; /* work: far-field velocities at 2 Gauss points per panel */
  float *fwork;          /* work: single-precision right-hand side */
  size_t fwork_cap;
  double *dwork;
  size_t dwork_cap;
  struct px_vortex_nbuf *nbuf; /* work: one neighbour list per thread */
  int nthreads;
  struct px_tuner tuner; /* set up at the first step from cfg.threads (an engine
                            may lower it at creation); sets cfg.threads per step */
  double *xn, *yn;       /* work: positions after the move */
  double *rk;            /* work (rk2): positions, convective and diffusive velocities at the
                            step's start (6 x rk_cap), then the first stage's sheet (n + nbody) */
  size_t rk_cap;
  size_t *rk_born;  /* work (rk2): the first stage's born_first (n + 1) */
  int32_t *hit;     /* work: panel crossed by each vortex */
  int32_t *partner; /* work: merge partner */
  uint8_t *flag;    /* work */
  /* state */
  long step;
  double time;
  double last_vinf[2];
  struct px_vortex_loads loads[PX_VORTEX_MAX_BODIES];
  double block_time[PX_VORTEX_BLOCK_COUNT_]; /* accumulated seconds */
  double diffusive_time[2]; /* accumulated seconds of the diffusive block's parts: tree build,
                               eps* and VVD sums (one search; cpu backend) */
  double block_cpu[PX_VORTEX_BLOCK_COUNT_]; /* accumulated process CPU seconds (cpu backend;
                                               all threads: on a shared machine the
                                               undisturbed cost) */
  /* The run's ranks (vortex_ranks.h): each holds the whole wake and sums
   * its share of the convective (FMM) and diffusive targets. */
  struct px_comm *comm; /* borrowed: px_context_comm(ctx), a single rank by default */
  double comm_bytes;    /* received by this rank in the split sums' gathers */
  double comm_last;     /* of them, in the gathers of step comm_step */
  long comm_step;
  /* the last split of the convective [0] and diffusive [1] sums: vortices,
   * the fewest and the most targets of a rank */
  size_t split_n[2], split_min[2], split_max[2];
  /* convective sums run (cpu engine) and of them, those that extended the
   * generation's FMM sum (px_nbody_velocity_extend) */
  long conv_sums, conv_extended;
  /* diagnostics of the last step */
  size_t n_born, n_absorbed, n_far, n_merged;
  int cap_warned;     /* a panel's newborns were capped (VX_NEWBORN_MAX): warned once */
  double circulation; /* total circulation of the wake */
};

/* Build from checked, counter-clockwise contours (copied). Factors the
 * matrix. The engine of the backend is picked here, once (vortex_engine.c,
 * which holds the functions down to px_vortex_engine_velocity). */
enum px_status px_vortex_engine_create(struct px_context *ctx, struct px_backend *be,
                                       const struct px_vortex_config *cfg,
                                       const struct px_vortex_contour *bodies, size_t nbody,
                                       struct px_vortex_engine **out);
void px_vortex_engine_free(struct px_vortex_engine *e);
/* Check the configuration (PX_STATUS_CONFIG with a message naming the key). */
enum px_status px_vortex_config_check(struct px_context *ctx, const struct px_vortex_config *cfg);

/* Free stream at time t (ramps). */
void px_vortex_vinf(const struct px_vortex_config *cfg, double t, double *vx, double *vy);

/* One time step from e->time to e->time + dt. */
enum px_status px_vortex_engine_step(struct px_vortex_engine *e);

/* Bring the host copy of the wake (and sheet, absorbed circulation, wall
 * vorticity) up to date when the step runs on a device; no-op on cpu. */
enum px_status px_vortex_engine_sync(struct px_vortex_engine *e);
/* The host wake was changed (checkpoint load): the device takes it over. */
void px_vortex_engine_host_changed(struct px_vortex_engine *e);

/* Add vortices (initial wakes, tests). */
enum px_status px_vortex_engine_add(struct px_vortex_engine *e, size_t n, const double *x,
                                    const double *y, const double *g);

/* Velocity (convective, from the wake and the free stream at the engine's
 * time) at arbitrary points. */
enum px_status px_vortex_engine_velocity(struct px_vortex_engine *e, size_t n, const double *x,
                                         const double *y, double *u, double *v);

/* CPU time of the process (all threads) [s]: the blocks' block_cpu. */
double px_vortex_cpu_seconds(void);

/* Internals shared with tests. */
enum px_status px_vortex_wake_reserve(struct px_context *ctx, struct px_vortex_wake *w, size_t n);
void px_vortex_wake_free(struct px_context *ctx, struct px_vortex_wake *w);
/* The diffusive velocity a newborn vortex gets in its first step with
 * newborn_rayleigh (0 without): 2 sqrt(nu / (pi dt)) along its panel's
 * normal. */
double px_vortex_newborn_drift(const struct px_vortex_config *cfg);
/* Diffusive velocities of all wake vortices, and (compute_eps) their eps*
 * from their 3 nearest neighbours into e->w.e (else e->w.e must be filled;
 * where it holds the eps* of the step before, it guides the search). No cap
 * is applied when vcap <= 0. */
enum px_status px_vortex_engine_diffusive(struct px_vortex_engine *e, int compute_eps, double vcap);

/* Wall terms of the VVD at (x, y) with domain radius e and cutoff `cut` (in
 * units of e): over the panels idx[0..n) of p, I3 = sum of S3 times the
 * outward normal into *i3x, *i3y and sum of S0 into *s0, S3 and S0 those of
 * vx_panel_wall (vortex_kernel.h), summed in vectorized loops
 * (vortex_wall.c). */
void px_vortex_wall_sum(const struct px_vortex_panels *p, const uint32_t *idx, size_t n, double x,
                        double y, double e, double cut, double *i3x, double *i3y, double *s0);
/* The same lists summed by the scalar listing, which the AVX-512 one must
 * match to the bit (the test; the same as px_vortex_wall_sum where not built
 * for AVX-512). */
void px_vortex_wall_sum_plain(const struct px_vortex_panels *p, const uint32_t *idx, size_t n,
                              double x, double y, double e, double cut, double *i3x, double *i3y,
                              double *s0);

/* Neighbour selection of the VVD (vortex_vvd.c). Leaves of a group query
 * (sorted, ascending) and their boxes: lb holds 6 arrays of cap >= nl + 8 (x0,
 * x1, y0, y1, scratch, the point ranges lo | hi << 32 as uint64_t);
 * vvd_leaf_boxes fills boxes and ranges of leaves[0..nl). vvd_leaf_runs:
 * those within sqrt(r2) of (xi, yi) as runs of consecutive sorted positions
 * (pairs lo, hi; touching leaves merged; room for 2 nl), returns the run
 * count (AVX-512 compress of the ranges where built for it; _plain: the
 * scalar reference, the same runs). vvd_pack packs, for the sorted
 * positions of the nr runs (pairs lo, hi) other than skip within sqrt(r2max)
 * of (xi, yi), the offsets (xi - x, yi - y) and circulations into pdx, pdy,
 * pg from 0 and returns their count; the arrays need 8 entries of slack past
 * the last candidate (a vector store). _plain is the scalar reference for
 * one run, appending at np; both give the same list. */
void px_vortex_vvd_leaf_boxes(const struct px_vortex_tree *t, const uint32_t *leaves, size_t nl,
                              double *lb, size_t cap);
size_t px_vortex_vvd_leaf_runs(const struct px_vortex_tree *t, const uint32_t *leaves, double *lb,
                               size_t nl, size_t cap, double xi, double yi, double r2,
                               uint32_t *runs);
size_t px_vortex_vvd_leaf_runs_plain(const struct px_vortex_tree *t, const uint32_t *leaves,
                                     double *lb, size_t nl, size_t cap, double xi, double yi,
                                     double r2, uint32_t *runs);
/* vvd_leaves_within: those of leaves[0..nl) (boxes in lb, as for
 * vvd_leaf_runs) whose box lies within sqrt(r2) of (xi, yi), in their order,
 * into out (room for nl + 8): px_vortex_tree_leaves_of's list for r2 = r^2
 * (AVX-512 compress where built for it). */
size_t px_vortex_vvd_leaves_within(const uint32_t *leaves, const double *lb, size_t nl, size_t cap,
                                   double xi, double yi, double r2, uint32_t *out);
size_t px_vortex_vvd_pack(const double *sx, const double *sy, const double *sg,
                          const uint32_t *runs, size_t nr, uint32_t skip, double xi, double yi,
                          double r2max, double *pdx, double *pdy, double *pg);
size_t px_vortex_vvd_pack_plain(const double *sx, const double *sy, const double *sg, uint32_t lo,
                                uint32_t hi, uint32_t skip, double xi, double yi, double r2max,
                                double *pdx, double *pdy, double *pg, size_t np, double *low);
/* vvd_near: the same candidates' smallest squared distances, no list: into
 * low, PX_VORTEX_VVD_LOW entries (vvd_pack_plain's low, NULL: not wanted,
 * keeps track of them from what they hold, all INFINITY before a vortex's
 * first run; layouts differ); vvd_low3 reduces them to the 3 smallest,
 * ascending (the distances of eps*: the 3 nearest of a vortex, searched
 * within a radius much smaller than its neighbourhood's). */
#define PX_VORTEX_VVD_LOW 24
void px_vortex_vvd_near(const double *sx, const double *sy, const uint32_t *runs, size_t nr,
                        uint32_t skip, double xi, double yi, double r2max, double *low);
void px_vortex_vvd_low3(const double *low, double *d2);

/* r = sqrt(dx^2 + dy^2) and (rinv not NULL) rinv = 1 / r of n entries, both 0
 * where dx^2 + dy^2 <= max(tiny2, DBL_MIN). AVX-512 (where built for it): by
 * the reciprocal square root's estimate and two Newton steps, within a few
 * ulp of _plain, the scalar reference. The distances of the VVD's pair and
 * wall sums. */
void px_vortex_radii(const double *dx, const double *dy, size_t n, double tiny2, double *r,
                     double *rinv);
void px_vortex_radii_plain(const double *dx, const double *dy, size_t n, double tiny2, double *r,
                           double *rinv);

/* The entries idx[q] (q < n) whose point (cx[q], cy[q]) lies within sqrt(r2)
 * of (xi, yi), in order, into out (n + 8 entries of room); returns their
 * count. AVX-512 compress where built for it; _plain is the scalar reference
 * (the same list). The panels near a vortex in the VVD's wall terms. */
size_t px_vortex_vvd_filter(const double *cx, const double *cy, const uint32_t *idx, size_t n,
                            double xi, double yi, double r2, uint32_t *out);
size_t px_vortex_vvd_filter_plain(const double *cx, const double *cy, const uint32_t *idx, size_t n,
                                  double xi, double yi, double r2, uint32_t *out);

/* Sum over the points lst[0..n) (sorted positions: coordinates sx, sy, the
 * circulation g[order[.]]) of Gamma S3 of panel k with domain radius e (S3 of
 * vx_panel_wall, vectorized as px_vortex_wall_sum): the wall vorticity
 * estimate's integral (loads). */
double px_vortex_wall_s3_sum(const struct px_vortex_panels *p, size_t k, const double *sx,
                             const double *sy, const double *g, const uint32_t *order,
                             const uint32_t *lst, size_t n, double e, double cut);
double px_vortex_wall_s3_sum_plain(const struct px_vortex_panels *p, size_t k, const double *sx,
                                   const double *sy, const double *g, const uint32_t *order,
                                   const uint32_t *lst, size_t n, double e, double cut);

/* atan2 by a branch-free polynomial (vortex_wall.c), exposed for its test. */
double px_vortex_atan2(double y, double x);

#endif
