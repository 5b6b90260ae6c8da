/* The granular system on the cpu backend: particles (structure of arrays,
 * periodically reordered by cell), the half neighbour list with contact
 * histories, the boundary contours and their motion, and the time step.
 *
 * Precision: `double` keeps everything in double; `mixed` integrates the
 * state in double and evaluates contacts in float; `single` does both in
 * float. Arrays of reals are `union px_gran_reals`: the loops of cpu_loops.h
 * (one instantiation per precision) reach them through a typed accessor
 * (PX_GRAN_SA / PX_GRAN_CA), generic host code (allocation, permutation,
 * checkpoints) through the raw pointer `.p` of the array table.
 *
 * Neighbour list: a Verlet list with skin. At a rebuild the particles are
 * binned on a uniform grid (cell >= largest cutoff) and counting-sorted by
 * cell (O(N), stable, deterministic) by the platform's neighbour grid
 * (partix/neighbors.h), and reordered, and for each particle i the
 * partners j > i within r_i + r_j + skin are listed (CSR by i), with the
 * transposed list (pairs where a particle is the partner) for the force
 * accumulation. Contact histories move to the new list by the persistent ids
 * of both particles. The list is rebuilt when a particle may have moved half
 * the skin relative to another particle or a wall since the last rebuild.
 *
 * Forces without races: pass 1 evaluates every pair once (SIMD over pairs)
 * into per-pair force records; pass 2 sums, per particle, its own pairs and
 * (negated) those where it is the partner. Both passes are split into fixed
 * contiguous ranges per thread, so the sums have a fixed order and a run is
 * bit-reproducible for a given thread count. */
#ifndef PX_GRAN_SYSTEM_H
#define PX_GRAN_SYSTEM_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "partix/types.h"
#include "core/comm.h"
#include "core/tuner.h"
#include "solvers/granular/geometry.h"
#include "solvers/granular/motion.h"

/* Largest neighbour-list skin, in largest radii (pairs per disc grow with
 * the square of radius + skin). */
#define PX_GRAN_SKIN_MAX 10.0
/* Wall candidates of one particle a rebuild may list (px_gran_build_walls). */
#define PX_GRAN_WCAND_MAX 512
/* Partners per particle the pair search keeps for the list's fill (the
 * default of px_gran_sys.pcache_n). */
#define PX_GRAN_PCACHE 8

enum px_gran_integrator {
  PX_GRAN_INTEGRATOR_VERLET = 0, /* velocity Verlet, one force evaluation per step */
  PX_GRAN_INTEGRATOR_ABM4 = 1    /* Adams–Bashforth–Moulton 4 PECE, two per step */
};

/* A contact law as given by the user (double). */
struct px_gran_law_spec {
  int normal;      /* PX_GRAN_NORMAL_* */
  int tangential;  /* PX_GRAN_TANGENTIAL_* */
  int clamp;       /* no attractive normal force */
  double kn;       /* [N/m] (hysteretic: loading k1) */
  double e;        /* restitution: linear -> damping; hysteretic -> k2 = kn/e^2 if k2 == 0 */
  double k2;       /* hysteretic unloading (max) stiffness [N/m], 0: from e */
  double phif;     /* Luding phi_f (0: constant k2, Walton–Braun) */
  double damping;  /* hysteretic: extra viscous damping ratio zeta [-] */
  double kt_ratio; /* k_t / k_n [-] */
  double ct_ratio; /* c_t / c_n [-] */
  double mu;       /* [-] */
  double gt;       /* viscous tangential coefficient [N s/m] */
  double mur;      /* rolling friction [-] */
  double kr;       /* rolling stiffness factor, k_r = kr kn R*^2 [-] */
};

/* Per-segment statistics parameters. */
struct px_gran_stats_spec {
  double start;     /* accumulate from this time on [s] */
  double vmin;      /* impacts slower than this (normal) are not counted [m/s] */
  double finnie_k;  /* Finnie: removed volume = k m V^n f(alpha) [m^3 / (kg (m/s)^n)] */
  double finnie_n;  /* exponent n (2 in Finnie 1960) */
  double archard_k; /* Archard wear coefficient K [-] */
  double hardness;  /* H [Pa]: Archard volume = K/H * integral(fn |vt| dt) */
};

/* Per-segment accumulators (double, owned arrays of nseg). */
struct px_gran_stats {
  double *impacts;                   /* number of impacts */
  double *vn_sum, *vn2_sum, *vn_max; /* normal impact speed [m/s] */
  double *vt_sum;                    /* tangential speed at impact [m/s] */
  double *en;                        /* sum of m vn^2 / 2 [J] */
  double *et;                        /* sum of m vt^2 / 2 [J] */
  double *finnie;                    /* sum of m V^n f(alpha) [kg (m/s)^n] */
  double *impulse;                   /* normal impulse [N s] */
  double *slide;                     /* sliding (friction) work [J] */
  double *archard;                   /* integral fn |vt| dt [N m] */
  double *ctime;                     /* contact time [s] */
  double *dur_sum;                   /* sum of durations of the impacts started here [s] */
  double *ended;                     /* contacts started here that ended */
  double *t_first, *t_last;          /* first and last impact time [s] (-1: none) */
  double t_begin;                    /* when accumulation started [s] */
};

/* An array of reals whose element type is fixed at run time by the
 * system's precision: `f` when the array holds floats, `d` when it holds
 * doubles (which one: state or contact precision, as each field says), `p`
 * for code that only moves bytes. Owned by the system. */
union px_gran_reals {
  float *f;
  double *d;
  void *p;
};

/* Element i of an array of reals whose elements have es bytes (the
 * precision the array has), as a double; and the store (rounded to float
 * for a float array). For host code that serves every precision. */
static inline double px_gran_reals_get(union px_gran_reals a, size_t i, size_t es) {
  return es == sizeof(double) ? a.d[i] : (double)a.f[i];
}
static inline void px_gran_reals_set(union px_gran_reals a, size_t i, size_t es, double v) {
  if (es == sizeof(double))
    a.d[i] = v;
  else
    a.f[i] = (float)v;
}

/* Wall-slot arrays (PX_GRAN_WSLOTS per particle). */
struct px_gran_slots_mem {
  int *seg, *seg0, *step0;
  union px_gran_reals t0, te, xi, th, dm, dp, imp, slw, arc, tim; /* contact precision */
};

struct px_gran_sys {
  struct px_context *ctx; /* borrowed */
  enum px_precision precision;
  int threads;
  size_t ssize, csize; /* bytes of a state / contact real */

  /* particles */
  size_t n, cap;
  union px_gran_reals x, y, vx, vy, w; /* state [m], [m/s], [rad/s] */
  union px_gran_reals fx, fy, tq;      /* accelerations a = F/m + g, alpha = T/I */
  union px_gran_reals ax0, ay0, aw0;   /* scratch accelerations */
  union px_gran_reals ff;              /* force and torque accumulators, 4 per particle:
                                          fx, fy [N], torque [N m], a scratch lane (contact
                                          precision) */
  union px_gran_reals r, m, im, iI;    /* radius [m], mass [kg], 1/m, 1/I (contact precision) */
  union px_gran_reals xr, yr;          /* positions at the last rebuild (state) */
  int32_t *id;                         /* persistent id of the particle in each slot */
  int32_t *where;                      /* slot of each persistent id */
  /* ABM4 history: derivatives f_{n-1..n-3} of x, y, vx, vy, w: hist[k][d] */
  union px_gran_reals hist[3][5]; /* state precision */
  union px_gran_reals xp[5];      /* predictor state x, y, vx, vy, w */
  union px_gran_reals fa[3];      /* accelerations at the predictor */
  long abm_steps;                 /* steps taken by ABM (start-up when < 3) */
  int with_abm;                   /* ABM arrays allocated (fixed at the first add) */

  /* half neighbour list */
  size_t npairs, pcap;
  int32_t *pstart;                        /* n + 1 */
  int32_t *pcache;                        /* rebuild scratch: the first pcache_n partners
                                             of each particle (n of them) */
  int pcache_n;                           /* PX_GRAN_PCACHE (tests: fewer, so that the
                                             search's second pass runs) */
  int32_t *pi, *pj;                       /* pair ends (pi sorted) */
  union px_gran_reals pxi, pth, pdm, pdp; /* contact history (contact precision) */
  union px_gran_reals pfx, pfy, pti, ptj; /* per-pair force on i and torques (contact precision) */
  union px_gran_reals phist_scratch;      /* 4 npairs: histories of a predictor evaluation */
  union px_gran_reals pri, prj, pme, pre; /* per pair: radii, normal damping coefficient
                                        c_n = 2 zeta sqrt(m* kn) and reduced radius
                                        (set at rebuilds; contact precision) */
  union px_gran_reals pdxr, pdyr;         /* per pair: x_i - x_j at the rebuild */
  union px_gran_reals fox, fvx, fvw;      /* mixed, for the pair loops: float offsets from
                                             xr/yr and float velocities, (x, y) pairs
                                             interleaved in fox and fvx (2n reals) */
  int nranges;                            /* fixed particle ranges of the work split */
  int active;                             /* threads used now (1..threads): results do not
                                             depend on it (fixed ranges) */
  /* thread-count tuning (core/tuner.h): on a machine shared with other
   * processes, OpenMP barriers can make several threads far slower than
   * one; set up at the first step from `threads` and `tune` */
  struct px_tuner tuner;
  int tune;            /* 1: tune the thread count (default); 0: always
                          run `threads` (benchmarks, a thread count the user fixed) */
  long steps_parallel; /* steps run with more than one thread */
  /* Work split: s->nranges fixed particle ranges rng_i[t]..rng_i[t+1], their
   * near-wall particles near[rng_q[t]..rng_q[t+1]), and the pairs of earlier
   * ranges whose partner j lies in range t: xpair[xstart[t]..xstart[t+1]). */
  size_t *rng_i, *rng_q;
  /* Per range t: the last range holding a partner of its pairs (>= t), and
   * the first range whose pairs reach its discs (<= t) (cpu_loops.h). */
  int *rng_hi, *rng_lo;
  int32_t *xstart, *xpair;

  /* walls */
  const struct px_gran_geom *geom;      /* borrowed */
  const struct px_gran_motion *motions; /* borrowed, per body */
  size_t nbodies;
  double *frames;              /* per contour, at the current force evaluation (double) */
  union px_gran_reals sframes; /* same in state precision */
  double *frames_ref;          /* at the last rebuild */
  double *c_radius;            /* max distance of a contour's vertices from its pivot [m] */
  union px_gran_reals seg_ax, seg_ay, seg_tx, seg_ty, seg_len, seg_tpx, seg_tpy; /* state prec. */
  int *seg_cfirst, *seg_ccount;                                                  /* per contour */
  int32_t *wstart, *wcand; /* wall candidates per particle (CSR) */
  size_t nwcand, wcap;
  int32_t *near; /* particles with candidates */
  size_t nnear;
  struct px_gran_slots_mem slots;

  /* cell grid of the rebuilds: the platform's neighbour grid
   * (src/neighbors) on a cpu backend of its own, reshaped to the particles'
   * box at every rebuild; it bins them and sorts them by cell (stable
   * counting sort) */
  struct px_backend *gbe;        /* owned (created at the first rebuild) */
  struct px_grid *grid;          /* owned */
  struct px_buffer *gpos[2];     /* owned: x, y as double, the grid's input */
  struct px_buffer *gcell;       /* owned: cell of each particle in the new order (u32) */
  const uint32_t *order;         /* borrowed from grid: new slot i is old particle order[i] */
  const uint32_t *cell;          /* borrowed from gcell: cell of slot i */
  const uint32_t *cstart, *cend; /* borrowed from grid: slots [cstart[c], cend[c]) are cell c's */
  double gx0, gy0, gh;           /* grid origin and cell size [m] */
  int gnx, gny;
  void *scratch; /* permutation scratch */
  size_t scratch_bytes;

  /* physics */
  struct px_gran_law_spec pp, pw; /* particle–particle, particle–wall */
  double pp_zeta2;                /* 2 zeta of the pair law (set by prepare) */
  double gravity[2];              /* [m/s^2] */
  double skin;                    /* [m] */
  double rmax, rmin;
  enum px_gran_integrator integrator;
  int reorder; /* reorder particles by cell at rebuilds */

  /* time */
  long step;       /* steps done */
  int32_t fail_id; /* id of the particle a CONFIG failure of prepare
                      names (out of place, overlapping), else -1 */
  double t;        /* [s] */
  double dt;       /* [s] */
  long rebuilds;
  int need_rebuild;

  /* events and statistics */
  int *ev_i;                /* per thread buffers, merged in thread order */
  union px_gran_reals ev_r; /* contact precision */
  size_t *ev_n, ev_cap;     /* per thread count; capacity per thread */
  size_t ev_overflow;
  struct px_gran_stats_spec sspec;
  struct px_gran_stats stats;
  int stats_on;
  int impact_log_on;
  void (*impact_log)(void *user, int seg, int id, double t, double vn, double vt, double m);
  void *impact_log_user;

  /* reactions of the contours: force of the media on each contour [N]
   * (double, 2 per contour; per thread partial sums first) */
  double *cforce, *cforce_t;
  size_t ncontours;

  /* diagnostics of the last step */
  double max_overlap_ratio; /* largest delta / r seen (pairs and walls) */
  long escaped_id;          /* >= 0: a particle found behind a wall */

  const struct px_gran_cpu_ops *ops;
  char arr_names[72][48]; /* checkpoint names of the per-particle arrays */

  /* Ranks of a run (system_ranks.c): rank r owns the work ranges
   * [nranges r / K, nranges (r+1) / K) (cell-sorted slots: strips of the
   * container of about N/K discs, recut at every rebuild), holds every array
   * globally (replicated storage) and computes only its own. */
  struct px_comm *comm;      /* borrowed: the context's communicator */
  int nrank, rank;           /* K and this rank */
  int dist;                  /* 1 inside a step with K > 1: the loops run own ranges only */
  struct px_gran_plan *plan; /* owned: ghost and pair-record lists (NULL: none yet) */
  int plan_ok;               /* plan matches the current lists */
  size_t ev_lost_synced;     /* ev_overflow when the ranks last agreed on it */
};

/* Precision-specific loops (cpu_loops.h). */
struct px_gran_cpu_ops {
  /* One force evaluation at positions/velocities (x,y,vx,vy,w) arrays given:
   * writes accelerations into ax, ay, aw. commit: update contact histories
   * and wall statistics. */
  enum px_status (*forces)(struct px_gran_sys *s, const union px_gran_reals st[5],
                           const union px_gran_reals acc[3], int commit, int kick);
  /* A velocity Verlet step (one parallel region): largest squared
   * displacement since the rebuild and largest squared speed. */
  enum px_status (*vv_step)(struct px_gran_sys *s, double *maxdisp2, double *maxv2);
  /* ABM4 parts: stage 0 predict into xp; stage 1 correct into x (with
   * s->dist, this rank's own discs only: maxdisp2 is theirs). */
  void (*abm_predict)(struct px_gran_sys *s);
  void (*abm_correct)(struct px_gran_sys *s, double *maxdisp2);
  /* Pair candidates of the rebuild: count (pass 0) or fill (pass 1). */
  void (*build_pairs)(struct px_gran_sys *s, double cut_extra, int pass, int32_t *count);
  /* Kinetic energy (translation, rotation) [J], and the first non-finite
   * particle (or -1). */
  void (*energy)(const struct px_gran_sys *s, double *ek_t, double *ek_r, long *bad);
  /* The i-th particle's values as double. */
  void (*get)(const struct px_gran_sys *s, size_t i, double out[8]);
  void (*set)(struct px_gran_sys *s, size_t i, const double in[8]);
  /* Elastic energy of all contacts (linear law, kn delta^2 / 2) [J]. */
  double (*elastic)(struct px_gran_sys *s);
};

extern const struct px_gran_cpu_ops px_gran_cpu_ops_f64;
extern const struct px_gran_cpu_ops px_gran_cpu_ops_f32;
extern const struct px_gran_cpu_ops px_gran_cpu_ops_mixed;

/* Indices of px_gran_cpu_ops.get/set records. */
#define PX_GRAN_P_X 0
#define PX_GRAN_P_Y 1
#define PX_GRAN_P_VX 2
#define PX_GRAN_P_VY 3
#define PX_GRAN_P_W 4
#define PX_GRAN_P_R 5
#define PX_GRAN_P_M 6
#define PX_GRAN_P_ID 7

/* Create an empty system. */
enum px_status px_gran_sys_create(struct px_context *ctx, enum px_precision precision, int threads,
                                  struct px_gran_sys **out);
void px_gran_sys_free(struct px_gran_sys *s);

/* Add particles: x, y [m], radius [m], mass [kg]; velocities zero. Ids are
 * assigned in order (0, 1, ...). */
enum px_status px_gran_sys_add(struct px_gran_sys *s, size_t n, const double *x, const double *y,
                               const double *r, const double *m);
/* Set velocity and spin of the particle with persistent id. */
enum px_status px_gran_sys_set_velocity(struct px_gran_sys *s, int32_t id, double vx, double vy,
                                        double w);
/* Boundaries (borrowed; may be NULL for none). motions[b] for body b. */
void px_gran_sys_set_walls(struct px_gran_sys *s, const struct px_gran_geom *g,
                           const struct px_gran_motion *motions, size_t nbodies);

/* Validate the laws (e <= 1, stiffness > 0, ...), derive the time step if
 * dt <= 0 (t_c / steps_per_contact), check dt against the stability limit,
 * check initial overlaps and positions, and prepare the lists. Messages
 * name `where` (e.g. the case section). */
enum px_status px_gran_sys_prepare(struct px_gran_sys *s, double dt, double steps_per_contact);
/* Contact duration of the lightest pair (linear law) [s]. */
double px_gran_sys_contact_time(const struct px_gran_sys *s);
/* Contact duration of law L for the reduced mass meff [kg] [s] (the
 * undamped half period, stretched by the damping; hysteretic: the mean of
 * the loading and unloading half periods). 0, inf or NaN for stiffnesses
 * out of proportion to the mass. */
double px_gran_law_contact_time(const struct px_gran_law_spec *L, double meff);
/* Memory of one particle of a system of this precision [bytes]: its
 * arrays, about 5 pairs of the neighbour list, wall lists and grid cells (an
 * estimate for refusing cases beyond the machine's memory up front). */
double px_gran_sys_particle_bytes(enum px_precision precision, int abm);

/* Advance one step. Returns PX_STATUS_NUMERIC with a diagnosis on
 * non-finite values or a particle escaping through a wall. */
enum px_status px_gran_sys_step(struct px_gran_sys *s);
/* The first particle with a non-finite position or velocity, reported as a
 * blow-up found at step `step` (time t [s]): PX_STATUS_NUMERIC naming the
 * particle; PX_STATUS_OK when every value is finite. */
enum px_status px_gran_sys_check_finite(struct px_gran_sys *s, long step, double t);
/* Rebuild the neighbour and wall lists now (also reorders). */
enum px_status px_gran_sys_rebuild(struct px_gran_sys *s);

/* Brute-force list of contacts (pairs of persistent ids, lower id first,
 * sorted) at the current positions, with overlap > 0: for tests. */
enum px_status px_gran_sys_contacts_brute(const struct px_gran_sys *s, int32_t **pairs, size_t *n);
/* Contacts in the neighbour list with overlap > 0, same format. */
enum px_status px_gran_sys_contacts_list(const struct px_gran_sys *s, int32_t **pairs, size_t *n);

/* Particle values by persistent id (PX_GRAN_P_* record). */
void px_gran_sys_get(const struct px_gran_sys *s, int32_t id, double out[8]);
/* Total kinetic energy [J] and sum of m g.h potential [J] (h along -gravity). */
double px_gran_sys_kinetic(const struct px_gran_sys *s);
double px_gran_sys_potential(const struct px_gran_sys *s);

/* Statistics: enable with spec (allocates per segment). */
enum px_status px_gran_sys_stats_enable(struct px_gran_sys *s,
                                        const struct px_gran_stats_spec *spec);
/* Flush the accumulators of contacts in progress into the statistics. */
void px_gran_sys_stats_flush(struct px_gran_sys *s);
/* The statistics as they stand, contacts in progress included, without
 * touching the system (outputs must not change the run: a flush regroups
 * the sums, so a run with more outputs, e.g. one resumed, would drift).
 * Adds the in-progress normal impulse [N s], sliding work [J], Archard
 * integral [N m] and contact time [s] per segment to the arrays given
 * (nseg each, copies of the statistics the caller owns). */
void px_gran_sys_stats_pending(const struct px_gran_sys *s, double *impulse, double *slide,
                               double *archard, double *ctime);
/* Total wall force on contour c (sum of the reactions of all its contacts,
 * i.e. the force the media exerts on the contour) [N], from the last step. */
void px_gran_sys_wall_force(const struct px_gran_sys *s, size_t c, double f[2]);

/* Particle values in the current (cell-sorted) order as doubles; any
 * pointer may be NULL. */
void px_gran_sys_export(const struct px_gran_sys *s, double *x, double *y, double *vx, double *vy,
                        double *w, double *r, double *m, double *id);
/* Contacts of each particle (pairs in contact + wall contacts) into z (n,
 * current order), from its positions x, y and radii r as px_gran_sys_export
 * gives them; returns the mean coordination number. */
double px_gran_sys_coordination(const struct px_gran_sys *s, const double *x, const double *y,
                                const double *r, double *z);

/* Checkpoint everything the next step reads, and read it back (into a
 * system created and prepared from the same case). */
struct px_checkpoint_writer;
struct px_checkpoint;
enum px_status px_gran_sys_save(const struct px_gran_sys *s, struct px_checkpoint_writer *w);
enum px_status px_gran_sys_load(struct px_gran_sys *s, struct px_checkpoint *ck);

/* Largest displacement of a contour point since the last rebuild [m]. */
double px_gran_sys_wall_drift_now(const struct px_gran_sys *s);
/* The current contour frames become the reference of the skin test. */
void px_gran_sys_set_reference_frames(struct px_gran_sys *s);
/* Contour reactions (px_gran_sys_wall_force) of the current state, without
 * touching any history. */
enum px_status px_gran_sys_wall_reactions(struct px_gran_sys *s);

/* Ranks (system_ranks.c; K = 1: nothing). This rank's work ranges. */
void px_gran_ranks_own(const struct px_gran_sys *s, int *vt0, int *vt1);
/* The ghost and record lists of the current neighbour list (made after a
 * rebuild or a load; collective: logs the decomposition). */
enum px_status px_gran_ranks_begin(struct px_gran_sys *s);
/* The lists alone (not collective; tests set s->nrank and s->rank to see
 * any rank's, and free them with px_gran_ranks_free before changing
 * nrank), and one of them: kind 0 the ghost discs sent to rank q, 1 those
 * received from q, 2 the pairs whose records go to q, 3 those whose
 * records come from q (slots or pair indices, ascending); their count. */
enum px_status px_gran_ranks_lists(struct px_gran_sys *s);
size_t px_gran_ranks_list(const struct px_gran_sys *s, int kind, int q, const int32_t **idx);
/* Collective: rank `root` (every rank when root < 0) gets the owners'
 * particle state, wall slots and contact histories (its system then reads
 * as a 1-rank run's). */
enum px_status px_gran_ranks_sync(struct px_gran_sys *s, int root);
/* Inside a step's parallel region (one thread): the ghosts' state arrays
 * (arr: narr arrays of es[k] bytes per particle) from their owners, and the
 * pair records (force, torques) of pairs whose partner another rank owns. */
enum px_status px_gran_ranks_ghosts(struct px_gran_sys *s, void *const *arr, const size_t *es,
                                    int narr);
enum px_status px_gran_ranks_records(struct px_gran_sys *s);
/* After a step's region: every rank's per-range results (largest
 * displacement, speed, non-finite flags, contour reactions, wall events),
 * so that what follows is summed over all ranges in range order. */
enum px_status px_gran_ranks_reduce(struct px_gran_sys *s, double *disp2, double *vmax2,
                                    double *nonfinite);
void px_gran_ranks_free(struct px_gran_sys *s);

/* Internal: update contour frames for time t (both precisions). */
void px_gran_sys_frames(struct px_gran_sys *s, double t);
/* Internal: process events from the thread buffers into the statistics. */
void px_gran_sys_events(struct px_gran_sys *s);
/* Internal: set a law's kernel parameters (double values, see
 * contact_kernel.h PX_GRAN_LAW_*) from a spec. */
void px_gran_law_params(const struct px_gran_law_spec *spec, int cells, double p[14]);

#endif
