/* Private part of the 2D fast multipole method (FMM) for the smoothed
 * Biot–Savart sum of include/partix/nbody.h: the workspace an evaluator
 * keeps between calls, the quadtree, and the per-precision cpu entry points.
 * The algorithm is described in fmm_cpu.h; the choice of order, opening
 * ratio and leaf size from a requested tolerance in fmm.c. */
#ifndef PX_NBODY_FMM_H
#define PX_NBODY_FMM_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "partix/types.h"

/* Largest expansion order (number of complex coefficients) per precision:
 * 40 reaches 1e-12 with acceptance ratio 0.5 in double; in float the
 * tolerance stops at 1e-5 (order 20 by the rule, fmm.c). */
#define PX_FMM_MAX_ORDER 40
#define PX_FMM_MAX_ORDER_SINGLE 24
/* Morton keys: 31 bits per axis, so at most 31 quadtree levels below the
 * root; generations (tree depth counted in splits) <= 32. */
#define PX_FMM_KEY_LEVELS 31
#define PX_FMM_MAX_GEN 33

/* Parameters of one evaluation (fmm.c fills them from the user's knobs). */
struct px_fmm_params {
  int order;   /* p: coefficients 0..p-1 of each multipole and local expansion */
  double err;  /* truncation target of one interaction: its order q is the
                * smallest with ρ^q <= err (ρ its convergence ratio); pairs are
                * accepted when ρ <= err^(1/p), so q <= p */
  size_t leaf; /* most particles in a leaf (cells at the deepest level may hold more) */
  /* Cost model (in units of one near-field pair) that picks, for an
   * accepted pair of cells, between M2L, P2L, M2P and P2P. */
  double cost_m2l; /* per M2L: cost_m2l * p^2 */
  double cost_exp; /* per particle and term for P2L / M2P: cost_exp * p */
};

/* Counters and timings of the last evaluation (for tuning and tests). */
struct px_fmm_stats {
  size_t src_cells, tgt_cells, src_leaves, tgt_leaves;
  int src_generations, tgt_generations;
  size_t m2l, p2l, m2p, p2p_cells; /* interactions (cell pairs) */
  double p2p_pairs, m2p_targets, p2l_sources;
  double m2l_terms;                     /* Σ q² over the M2Ls (q: order of the interaction) */
  double t_tree, t_up, t_down, t_total; /* seconds */
};

/* One cell of a quadtree: what the traversal reads, in one 64-byte line.
 * Geometry (fmm_cpu.h fills it): the centre (cx, cy) of the points'
 * bounding box, rounded to the working precision (the expansion centre);
 * R, an upper bound of the distance of every point from the centre
 * (rounded up); r = max(R, eps/1000) > 0, the scale of the coefficients. */
struct px_fmm_cell {
  double cx, cy, R, r;
  uint32_t begin, end; /* points [begin, end) of the Morton order */
  uint32_t child;      /* first child (children are contiguous) */
  uint32_t nchild;     /* 0 for a leaf, else 2..4 */
  uint32_t parent;     /* UINT32_MAX for the root */
  uint32_t pad[3];
};

/* A quadtree over one point set, built from Morton keys (fmm_tree.c).
 * Cells are stored by generation (the root is generation 0; the children
 * of generation g cells form generation g+1, contiguously, in the order of
 * their parents), so generation g is cells [gen[g], gen[g+1]). A cell
 * whose points all fall into one quadrant is not split into that one child:
 * its key depth increases until a split separates them (so every inner
 * cell has 2-4 children, and tight bounding boxes do the rest). */
struct px_fmm_tree {
  size_t n;           /* points */
  size_t cap_n;       /* capacity of the per-point arrays */
  uint64_t *keys;     /* owned: Morton key per point, sorted after the build */
  uint64_t *keys_tmp; /* owned: radix-sort scratch */
  uint32_t *perm;     /* owned: perm[k] = input index of the k-th point in Morton order */
  uint32_t *perm_tmp; /* owned: radix-sort scratch */
  size_t ncells, cap_cells;
  struct px_fmm_cell *cell; /* owned */
  double *box;              /* owned: per cell, bounding box xmin, xmax, ymin, ymax */
  int ngen;                 /* generations */
  size_t gen[PX_FMM_MAX_GEN + 1];
  size_t maxleaf; /* most points in one leaf */
  /* Parallel work units (px_fmm_tree_tasks): task[0, ntop) are the top
   * cells (inner cells with more than n / (8 threads) points) in
   * generation order, done by one thread; task[ntop, ntop + nfront) the
   * roots of the remaining subtrees, largest first, each done by one
   * thread. */
  uint32_t *task; /* owned */
  size_t task_cap, ntop, nfront;
};

/* Per-thread scratch of an evaluation; grown on demand, kept between calls. */
struct px_fmm_thread {
  uint32_t *stack;
  size_t stack_cap;
  uint32_t *pass[2]; /* cells handed down to the children, per generation parity */
  size_t pass_cap[2], pass_len[2];
  uint32_t *list; /* interaction list of the current cell: (kind | order << 8, cell) */
  size_t list_cap;
  uint32_t *sorted; /* its M2Ls sorted by order: (cell, order) */
  size_t sorted_cap;
  void *buf; /* gathered near-field sources, M2L staging */
  size_t buf_cap;
  int failed; /* an allocation failed in a parallel region */
  size_t m2l, p2l, m2p, p2p_cells;
  double p2p_pairs, m2p_targets, p2l_sources, m2l_terms;
  char pad[64]; /* keeps neighbouring threads' counters off one cache line */
};

/* The workspace of an FMM evaluator (owned by struct px_nbody). */
struct px_fmm {
  struct px_context *ctx; /* borrowed */
  struct px_fmm_tree src, tgt;
  int nthreads;
  struct px_fmm_thread *thr; /* owned: nthreads entries */
  void *points;              /* owned: sorted coordinates, strengths, velocities */
  size_t points_cap;
  void *mpole, *local; /* owned: expansions per source / target cell */
  size_t mpole_cap, local_cap;
  uint8_t *has_local;  /* owned: per target cell, 1 if its local expansion is nonzero */
  uint32_t *pass_info; /* owned: per target cell, thread, offset, count of its hand-down list */
  size_t cell_cap;
  void *tables; /* owned: binomial tables in the working precision */
  size_t tables_cap;
  struct px_fmm_stats stats;
  /* A split evaluation (the ranks of one run, each evaluating a share of the
   * targets from all sources): with parts > 1 (px_nbody_set_part), every
   * part builds the same trees and runs the whole upward pass and the top
   * cells of the traversal (every target needs every source cell's
   * multipole), then only the subtrees of the downward pass (downward
   * translations, near field, evaluation at the points) whose first point
   * in Morton order lies in [n part / parts, n (part + 1) / parts). Those
   * subtrees' targets are the points split_lo..split_hi - 1 of the target
   * tree's Morton order (tgt.perm, or src.perm when the targets are the
   * sources); only their velocities are written. A target's value does not
   * depend on which other targets are evaluated, so the parts together
   * give the unsplit result bit for bit. parts <= 1: the whole sum. */
  int part, parts;
  int split; /* the last evaluation was split (0: every target written) */
  int self;  /* the last evaluation's targets were its sources (one tree) */
  size_t split_lo, split_hi;
  /* What an extension (px_fmm_cpu_extend_*) of the last whole evaluation
   * needs to know of it: its source count (0: nothing kept; any other
   * evaluation clears it), parameters, core radius and working precision.
   * Its source tree (src), sorted sources (the head of points) and
   * multipoles stay as it left them. */
  size_t kept_ns;
  struct px_fmm_params kept_prm;
  double kept_eps;
  size_t kept_real;
};

/* Arguments of one evaluation (host arrays of the precision's type). */
struct px_fmm_args {
  int threads;
  size_t n_src, n_tgt;
  const void *sx, *sy, *sg, *tx, *ty; /* borrowed */
  int self;                           /* targets are the sources (same arrays) */
  double eps;                         /* core radius */
  int accumulate;
  void *u, *v; /* borrowed outputs */
};

void px_fmm_init(struct px_fmm *fmm, struct px_context *ctx);
void px_fmm_release(struct px_fmm *fmm);

/* Grow *ptr (a px_mem block of *cap bytes) to at least `need` bytes with
 * 50% headroom; content kept. Returns 0, or -1 when out of memory (the
 * context holds the message). Thread-safe. */
int px_fmm_reserve(struct px_context *ctx, const char *label, void **ptr, size_t *cap, size_t need);

/* Size the tree's per-point arrays for n points. */
enum px_status px_fmm_tree_reserve(struct px_context *ctx, struct px_fmm_tree *t, size_t n);
/* Sort t->keys[0..n) (perm = identity on entry is set here) and build the
 * cells: leaves of at most `leaf` points (more only at the deepest key
 * level). Deterministic: the result is the stable sort by key and does not
 * depend on the thread count. */
enum px_status px_fmm_tree_build(struct px_context *ctx, struct px_fmm_tree *t, int threads,
                                 size_t n, size_t leaf);
/* Fill t->task, t->ntop, t->nfront for `threads` threads. */
enum px_status px_fmm_tree_tasks(struct px_context *ctx, struct px_fmm_tree *t, int threads);
/* Room for `need` cells in t (cell and box arrays; content kept). */
enum px_status px_fmm_tree_cells(struct px_context *ctx, struct px_fmm_tree *t, size_t need);
/* Set up the per-thread scratch for `threads` threads. */
enum px_status px_fmm_threads(struct px_fmm *fmm, int threads);

/* Full evaluation on the cpu, per precision (fmm_cpu.h). */
enum px_status px_fmm_cpu_f32(struct px_fmm *fmm, const struct px_fmm_params *prm,
                              const struct px_fmm_args *a);
enum px_status px_fmm_cpu_f64(struct px_fmm *fmm, const struct px_fmm_params *prm,
                              const struct px_fmm_args *a);

/* The sums at the first n_old of the a->n_src sources from all of them,
 * where those n_old are the sources of the last whole evaluation, unchanged
 * since (checked): that evaluation's tree and multipoles serve again, the
 * other sources get a tree of their own whose root the traversal visits
 * beside the kept one, and the downward pass runs over the kept tree (its
 * points the targets). a: the sources; a->n_tgt = n_old; a->self = 1; u, v
 * hold n_old entries. The result is the sum to the tolerance, though not
 * bit for bit the sum that one tree over all sources gives; the same on
 * any number of threads and parts. Returns 1 when done, 0 when it does not
 * apply (no whole evaluation kept, other parameters, sources that changed:
 * nothing written; the caller evaluates the whole sum), -1 on failure (the
 * context holds the error). */
int px_fmm_cpu_extend_f32(struct px_fmm *fmm, const struct px_fmm_params *prm,
                          const struct px_fmm_args *a, size_t n_old);
int px_fmm_cpu_extend_f64(struct px_fmm *fmm, const struct px_fmm_params *prm,
                          const struct px_fmm_args *a, size_t n_old);

/* Parameters for a requested relative L2 error `tolerance` (order 0) or a
 * fixed order p (then err = 0.5^p); documented in fmm.c and docs/fmm.md. */
void px_fmm_params_for(enum px_precision precision, double tolerance, int order,
                       struct px_fmm_params *out);

#endif
