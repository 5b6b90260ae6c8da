/* Template of the cpu fast multipole method; instantiated by fmm_cpu_f32.c
 * and fmm_cpu_f64.c (see src/kernels/px_kernel.h).
 *
 * What is computed
 * ----------------
 * The smoothed Biot–Savart sum of include/partix/nbody.h,
 *   2π (u_i, v_i) = Σ_j Γ_j (−dy, dx) / max(|d|², ε²),   d = z_i − z_j,
 * split into a near field, summed pair by pair with the smoothing (P2P), and
 * a far field of point vortices, f(z) = Σ_j Γ_j / (z − z_j), for which
 * 2π (u − i v) = f / i, i.e. 2π u = Im f and 2π v = Re f. Far-field pairs are
 * at least ε apart (below), where max(r², ε²) = r²: there the smoothed and
 * the point-vortex kernels are the same function, so the far field is exact
 * up to the truncation of the expansions.
 *
 * Expansions (Greengard & Rokhlin, J. Comput. Phys. 73 (1987) 315, sec. 2,
 * "GR87" below; the Cauchy-kernel form of fmm2d's cfmm2d), about a centre c
 * with a scale r > 0, coefficients stored scaled so that they are O(Σ|Γ|):
 *   multipole  f(z) = Σ_{k<p} ã_k r^k / (z − c)^{k+1},  ã_k = Σ_j Γ_j ((z_j − c)/r)^k   (P2M)
 *   local      f(z) = Σ_{l<p} b̃_l ((z − c)/r)^l                                     (L2P)
 * Translations (z0, δ complex; C(n, k) binomials):
 *   M2M  child (c, r_c) -> parent (c', r'), u = (c − c')/r', σ = r_c/r':
 *        ã'_k = Σ_{m<=k} C(k, m) u^{k−m} σ^m ã_m                 (exact: the moments)
 *   M2L  source (c_s, r_s) -> target (c_t, r_t), z0 = c_t − c_s,
 *        ρ_s = r_s/z0, ρ_t = r_t/z0:
 *        b̃_l += (−1)^l ρ_t^l / z0 · Σ_k C(k + l, k) ρ_s^k ã_k      (GR87, conversion
 *                                                                of a multipole into
 *                                                                a local expansion)
 *   L2L  parent (c, r) -> child (c', r'), u = (c' − c)/r, σ = r'/r:
 *        b̃'_m = σ^m Σ_{l>=m} C(l, m) u^{l−m} b̃_l                  (exact)
 *   P2L  b̃_l += −Σ_j Γ_j / s_j · (r_t/s_j)^l,  s_j = z_j − c_t
 *   M2P  f(z) = (q/r) Σ_k ã_k q^k,  q = r/(z − c)
 * M2L is written as a pre-scaling by ρ_s^k, a product with the fixed real
 * matrix C(k + l, k) and a post-scaling by (−ρ_t)^l / z0; the M2Ls of one
 * target cell are batched as columns, so the middle step is a small matrix
 * product (p × p real by p × 2m), register-blocked and vectorised.
 *
 * Tree and traversal
 * ------------------
 * Sources and targets are sorted into Morton order and get a quadtree each
 * (fmm_tree.c; one tree when the targets are the sources). Every cell has
 * the centre c of its points' bounding box and a radius R with every point
 * within R of c. For a target cell t and a source cell s at d = |c_t − c_s|
 * the multipole series of s converges at the points of t with ratio
 * a = R_s / (d − R_t) and the local series of t with b = R_t / (d − R_s)
 * (GR87 sec. 2: multipole expansion and its conversion into a local
 * expansion, with their error bounds: truncating both series at order q
 * leaves at most Σ|Γ_s| (a^q / ((1 − a)(d − R_t)) + b^q / ((1 − b)(d − R_s)))
 * of f, from the binomial double series of 1/(z − z_j)). The
 * pair is accepted (well separated) when
 *   (a)  max(a, b) <= ρ = E^(1/p)     (so that order q <= p reaches E)
 *   (b)  d − R_t − R_s >= ε (1 + 1e-6) + rounding slack,
 * and each accepted interaction uses its own order, the smallest q with
 * max(a, b)^q <= E (E: fmm.c, the requested tolerance). Compared with a
 * fixed opening angle (R_t + R_s <= θ d) this accepts pairs by their actual
 * convergence, so a small cell next to a large one is not under-resolved
 * and the expansions need no reserve for it (p = ln E / ln ρ, not ln E /
 * ln θ); measured 20-30% faster at equal error.
 * Dual-tree traversal with fixed ownership (Dehnen, J. Comput. Phys. 179
 * (2002) 27, sec. 3, "interaction phase", organised per target cell as in
 * the adaptive lists of Carrier, Greengard & Rokhlin, SIAM J. Sci. Stat.
 * Comput. 9 (1988) 669): a target cell takes the source cells its parent
 * handed down and tests each: accepted pairs become an M2L (V list), P2L
 * (X list), M2P (W list, leaves only) or P2P, whichever the cost model
 * says is cheapest; rejected pairs split the source cell if the target is
 * a leaf or the source is the larger, are summed pair by pair if both are
 * leaves, and are handed down to the target's children otherwise.
 *
 * Why no pair closer than ε reaches the far field: for a point a of t and
 * b of s, |a − b| >= |c_t − c_s| − |a − c_t| − |b − c_s| >= d − R_t − R_s
 * (triangle inequality), and (b) makes that >= ε. R is an upper bound by
 * construction (rounded up by 1e-12 relative, far above the rounding of its
 * double computation from the points), d is computed in double with the
 * slack 4 DBL_EPSILON (|c_t| + |c_s|) covering its rounding. Pairs that fail
 * (b) are never accepted, so they end in P2P with the smoothed kernel.
 *
 * Determinism: every target value is computed by one thread, in an order
 * fixed by the trees (traversal order, list order, fixed batch and chunk
 * widths); the trees are the stable sort by Morton key. Thread count and
 * schedule change who computes a cell, never the operations: results are
 * bitwise identical for any number of threads. */
#include <float.h>
#include <omp.h>
#include <string.h>

#include "core/radix.h"
#include "kernels/biot_savart.h"
#include "nbody/fmm.h"
#include "partix/memory.h"
#include "partix/timer.h"

/* Elements of px_real in a 32-byte vector (gcc and clang use 256-bit
 * vectors with -march=native on AVX-512 Xeons unless told otherwise). */
#define PX_FMM_VW ((int)(32 / sizeof(px_real)))
/* Particles per chunk of P2M / P2L (stack arrays). */
#define PX_FMM_CHUNK 64
/* Interaction kinds in the per-cell list. */
#define PX_FMM_M2L 0u
#define PX_FMM_P2L 1u
#define PX_FMM_M2P 2u
#define PX_FMM_P2P 3u

/* Everything the passes read, for one evaluation. */
struct px_fmm_run {
  struct px_fmm *fmm;
  const struct px_fmm_tree *S, *T;
  int p;         /* order: coefficients 0..p-1 */
  size_t stride; /* px_real per cell of an expansion: re at [0, half), im at [half, 2 half) */
  size_t half;
  double rho, eps_mac; /* acceptance: convergence ratios <= rho = E^(1/p) */
  double cost_m2l, cost_exp;
  /* ln E: the order of one interaction is the smallest q with ρ^q <= E
   * (ρ its convergence ratio), at most p. */
  double lnE;
  px_real eps2;
  const px_real *sx, *sy, *sg; /* sorted sources */
  const px_real *tx, *ty;      /* sorted targets */
  px_real *U, *V;              /* 2π u, 2π v of the sorted targets */
  px_real *mp, *lc;            /* multipoles of source cells, locals of target cells */
  const px_real *Tm;           /* M2L matrix C(k + l, k), p × p */
  const px_real *B;            /* binomials C(k, m), p × p (row k) */
  const px_real *Bt;           /* its transpose */
  /* An extension (px_fmm_cpu_extend): the root of the new sources' tree,
   * the traversal's second source root (UINT32_MAX: none), and reuse = 1:
   * the sources are in Morton order and their multipoles done already. */
  uint32_t root2;
  int reuse;
};

/* Every function of the template carries the precision in its name
 * (px_fmm_p2m_f64); below they are written by their plain names. */
#define px_fmm_keys PX_SFX(px_fmm_keys)
#define px_fmm_round PX_SFX(px_fmm_round)
#define px_fmm_geo_leaf PX_SFX(px_fmm_geo_leaf)
#define px_fmm_geo_parent PX_SFX(px_fmm_geo_parent)
#define px_fmm_p2m PX_SFX(px_fmm_p2m)
#define px_fmm_powers PX_SFX(px_fmm_powers)
#define px_fmm_powers_real PX_SFX(px_fmm_powers_real)
#define px_fmm_powers_padded PX_SFX(px_fmm_powers_padded)
#define px_fmm_hsum8 PX_SFX(px_fmm_hsum8)
#define px_fmm_translate PX_SFX(px_fmm_translate)
#define px_fmm_p8 PX_SFX(px_fmm_p8)
#define px_fmm_kept_same PX_SFX(px_fmm_kept_same)
#define px_fmm_m2m PX_SFX(px_fmm_m2m)
#define px_fmm_l2l PX_SFX(px_fmm_l2l)
#define px_fmm_p2l PX_SFX(px_fmm_p2l)
#define px_fmm_l2p PX_SFX(px_fmm_l2p)
#define px_fmm_m2p PX_SFX(px_fmm_m2p)
#define px_fmm_m2l_scratch PX_SFX(px_fmm_m2l_scratch)
#define px_fmm_gemm PX_SFX(px_fmm_gemm)
#define px_fmm_m2l_block PX_SFX(px_fmm_m2l_block)
#define px_fmm_p2p PX_SFX(px_fmm_p2p)
#define px_fmm_push PX_SFX(px_fmm_push)
#define px_fmm_list_add PX_SFX(px_fmm_list_add)
#define px_fmm_pass_add PX_SFX(px_fmm_pass_add)
#define px_fmm_order PX_SFX(px_fmm_order)
#define px_fmm_far PX_SFX(px_fmm_far)
#define px_fmm_target PX_SFX(px_fmm_target)
#define px_fmm_up_cell PX_SFX(px_fmm_up_cell)
#define px_fmm_up_tree PX_SFX(px_fmm_up_tree)
#define px_fmm_down_tree PX_SFX(px_fmm_down_tree)
#define px_fmm_split PX_SFX(px_fmm_split)
#define px_fmm_own PX_SFX(px_fmm_own)
#define px_fmm_prepare PX_SFX(px_fmm_prepare)
#define px_fmm_storage PX_SFX(px_fmm_storage)
#define px_fmm_tables PX_SFX(px_fmm_tables)
#define px_fmm_evaluate PX_SFX(px_fmm_evaluate)
#define px_fmm_collect PX_SFX(px_fmm_collect)
#define px_fmm_cpu PX_SFX(px_fmm_cpu)
#define px_fmm_run_init PX_SFX(px_fmm_run_init)
#define px_fmm_cpu_extend PX_SFX(px_fmm_cpu_extend)

/* keys, geometry, the operators of a cell or a pair of cells */
#include "nbody/fmm_cpu_ops.h"
/* interaction lists, traversal, upward and downward passes */
#include "nbody/fmm_cpu_passes.h"

/* ------------------------------- entry --------------------------------- */

/* This part's subtrees of the downward pass (struct px_fmm, split): those
 * whose first point lies in its share of the Morton order. The subtree
 * roots partition the points into runs of the Morton order, so the part's
 * targets are the run [split_lo, split_hi). */
static void px_fmm_split(struct px_fmm *fmm, const struct px_fmm_tree *T) {
  const size_t lo = T->n * (size_t)fmm->part / (size_t)fmm->parts;
  const size_t hi = T->n * ((size_t)fmm->part + 1) / (size_t)fmm->parts;
  size_t q, a = T->n, b = T->n;
  for (q = 0; q < T->nfront; ++q) {
    const struct px_fmm_cell *c = T->cell + T->task[T->ntop + q];
    if (c->begin >= lo && c->begin < a) a = c->begin;
    if (c->begin >= hi && c->begin < b) b = c->begin;
  }
  fmm->split = 1;
  fmm->split_lo = a < b ? a : 0;
  fmm->split_hi = a < b ? b : 0;
}

/* The run's parameters (R cleared; trees S and T) and the thread states. */
static enum px_status px_fmm_run_init(struct px_fmm_run *R, struct px_fmm *fmm,
                                      const struct px_fmm_params *prm, const struct px_fmm_args *a,
                                      const struct px_fmm_tree *S, const struct px_fmm_tree *T) {
  memset(&fmm->stats, 0, sizeof fmm->stats);
  fmm->split = 0;
  fmm->self = a->self;
  fmm->kept_ns = 0; /* whatever happens next, the kept state is gone */
  memset(R, 0, sizeof *R);
  R->fmm = fmm;
  R->S = S;
  R->T = T;
  R->p = prm->order;
  R->half = (size_t)(R->p + PX_FMM_VW - 1) / (size_t)PX_FMM_VW * (size_t)PX_FMM_VW;
  R->stride = 2 * R->half;
  R->rho = exp(log(prm->err) / (double)R->p);
  R->eps_mac = a->eps * (1.0 + 1e-6);
  R->eps2 = (px_real)(a->eps * a->eps);
  R->cost_m2l = prm->cost_m2l;
  R->cost_exp = prm->cost_exp;
  R->lnE = log(prm->err);
  R->root2 = UINT32_MAX;
  return px_fmm_threads(fmm, a->threads);
}

/* The run's parameters, the thread states and both trees. */
static enum px_status px_fmm_prepare(struct px_fmm_run *R, struct px_fmm *fmm,
                                     const struct px_fmm_params *prm, const struct px_fmm_args *a) {
  struct px_context *ctx = fmm->ctx;
  const int threads = a->threads;
  const size_t ns = a->n_src, nt = a->n_tgt;
  struct px_fmm_tree *S = &fmm->src, *T = a->self ? &fmm->src : &fmm->tgt;
  /* a split evaluation cuts the target tree into subtrees for threads x
   * parts (who computes a cell never changes what is computed) */
  const int split_threads = fmm->parts > 1 ? threads * fmm->parts : threads;
  PX_TRY(px_fmm_run_init(R, fmm, prm, a, S, T));

  /* trees */
  PX_TRY(px_fmm_tree_reserve(ctx, S, ns));
  px_fmm_keys(threads, ns, a->sx, a->sy, S->keys);
  PX_TRY(px_fmm_tree_build(ctx, S, threads, ns, prm->leaf));
  if (!a->self) {
    PX_TRY(px_fmm_tree_reserve(ctx, T, nt));
    px_fmm_keys(threads, nt, a->tx, a->ty, T->keys);
    PX_TRY(px_fmm_tree_build(ctx, T, threads, nt, prm->leaf));
    PX_TRY(px_fmm_tree_tasks(ctx, T, split_threads));
  }
  PX_TRY(px_fmm_tree_tasks(ctx, S, a->self ? split_threads : threads));
  if (fmm->parts > 1) px_fmm_split(fmm, T);
  return PX_STATUS_OK;
}

/* Memory of one evaluation: the sorted points and velocities (nsp sources,
 * ntp targets, padded), expansions, tables and cell lists. */
static enum px_status px_fmm_storage(struct px_fmm_run *R, struct px_fmm *fmm,
                                     const struct px_fmm_args *a, size_t nsp, size_t ntp) {
  struct px_context *ctx = fmm->ctx;
  const struct px_fmm_tree *S = R->S, *T = R->T;
  px_real *pts;
  size_t need, ncell;

  /* sorted points and velocities */
  need = (3 * nsp + (a->self ? 0 : 2 * ntp) + 2 * ntp) * sizeof(px_real);
  if (px_fmm_reserve(ctx, "fmm points", &fmm->points, &fmm->points_cap, need))
    return PX_STATUS_NOMEM;
  pts = fmm->points;
  R->sx = pts;
  R->sy = pts + nsp;
  R->sg = pts + 2 * nsp;
  R->tx = a->self ? R->sx : pts + 3 * nsp;
  R->ty = a->self ? R->sy : pts + 3 * nsp + ntp;
  R->U = pts + 3 * nsp + (a->self ? 0 : 2 * ntp);
  R->V = R->U + ntp;

  /* expansions and tables */
  if (px_fmm_reserve(ctx, "fmm multipoles", &fmm->mpole, &fmm->mpole_cap,
                     S->ncells * R->stride * sizeof(px_real)) ||
      px_fmm_reserve(ctx, "fmm locals", &fmm->local, &fmm->local_cap,
                     T->ncells * R->stride * sizeof(px_real)) ||
      px_fmm_reserve(ctx, "fmm tables", &fmm->tables, &fmm->tables_cap,
                     (size_t)R->p * (size_t)(R->p + 2 * px_fmm_p8(R->p)) * sizeof(px_real)))
    return PX_STATUS_NOMEM;
  ncell = T->ncells;
  if (ncell > fmm->cell_cap) {
    size_t c1 = fmm->cell_cap, c2 = fmm->cell_cap * 3 * sizeof(uint32_t);
    if (px_fmm_reserve(ctx, "fmm cell flags", (void **)&fmm->has_local, &c1, ncell) ||
        px_fmm_reserve(ctx, "fmm cell lists", (void **)&fmm->pass_info, &c2,
                       3 * ncell * sizeof(uint32_t)))
      return PX_STATUS_NOMEM;
    fmm->cell_cap = c1 < c2 / (3 * sizeof(uint32_t)) ? c1 : c2 / (3 * sizeof(uint32_t));
  }
  R->mp = fmm->mpole;
  R->lc = fmm->local;
  return PX_STATUS_OK;
}

/* The M2L matrix C(k + l, k), p × p, and the binomials C(k, m) with their
 * transpose, p rows of px_fmm_p8(p) each (zero-padded: M2M and L2L run over
 * whole vectors), into fmm->tables. */
static void px_fmm_tables(struct px_fmm_run *R, struct px_fmm *fmm) {
  /* Pascal's triangle in double: exact while C(n, k) < 2^53 (n <= 56,
   * i.e. p <= 29), rounded to 1e-16 relative beyond; then cast */
  const size_t p = (size_t)R->p, p8 = (size_t)px_fmm_p8(R->p);
  px_real *Tm = fmm->tables, *Bm = Tm + p * p, *Bt = Bm + p * p8;
  double row[2 * PX_FMM_MAX_ORDER + 1];
  size_t n, k, l;
  row[0] = 1.0;
  for (k = 0; k < 2 * p * p8; ++k) Bm[k] = PX_R(0.0);
  for (n = 0; n + 2 <= 2 * p; ++n) {
    /* row n: C(n, 0..n) */
    if (n > 0) {
      row[n] = 1.0;
      for (k = n - 1; k > 0; --k) row[k] += row[k - 1];
    }
    for (k = 0; k <= n; ++k) {
      l = n - k; /* C(k + l, k) with k + l = n */
      if (k < p && l < p) Tm[l * p + k] = (px_real)row[k];
      if (n < p) {
        Bm[n * p8 + k] = (px_real)row[k];
        Bt[k * p8 + n] = (px_real)row[k];
      }
    }
  }
  R->Tm = Tm;
  R->B = Bm;
  R->Bt = Bt;
}

/* Subtree q of the downward pass is this part's (px_fmm_split). */
static int px_fmm_own(const struct px_fmm *fmm, const struct px_fmm_tree *T, size_t q) {
  const uint32_t b = T->cell[T->task[T->ntop + q]].begin;
  return !fmm->split || (b >= fmm->split_lo && b < fmm->split_hi);
}

/* The passes, in one parallel region: sort the points, the upward pass,
 * the traversal with the downward pass, and the velocities back in input
 * order; *t2 is the time the upward pass ended. */
static void px_fmm_evaluate(const struct px_fmm_run *R, struct px_fmm *fmm,
                            const struct px_fmm_args *a, size_t nsp, size_t ntp, double *t2) {
  const int threads = a->threads;
  const size_t ns = a->n_src, nt = a->n_tgt;
  const struct px_fmm_tree *S = R->S, *T = R->T;
  px_real *pts = fmm->points;
  int k;
  for (k = 0; k < fmm->nthreads; ++k) {
    struct px_fmm_thread *th = fmm->thr + k;
    th->failed = 0;
    th->m2l = th->p2l = th->m2p = th->p2p_cells = 0;
    th->p2p_pairs = th->m2p_targets = th->p2l_sources = th->m2l_terms = 0.0;
    th->pass_len[0] = th->pass_len[1] = 0;
  }
  /* One parallel region, few barriers (the machine may be shared: a
   * barrier waits for a preempted thread). Subtrees below the top cells
   * are tasks taken dynamically, largest first; the top cells are done by
   * one thread. Who does a cell never changes what is computed. */
  {
    const double rmin = 1e-3 * a->eps;
    const int self = a->self;
    const px_real *sx = a->sx, *sy = a->sy, *sg = a->sg, *tx = a->tx, *ty = a->ty;
    px_real *ox = pts, *oy = pts + nsp, *og = pts + 2 * nsp;
    px_real *otx = pts + 3 * nsp, *oty = pts + 3 * nsp + ntp, *u = a->u, *v = a->v;
    const px_real *U = R->U, *V = R->V;
    const uint32_t *sp = S->perm, *tp = T->perm;
    const int acc = a->accumulate;
    const size_t q0 = fmm->split ? fmm->split_lo : 0, q1 = fmm->split ? fmm->split_hi : nt;
#pragma omp parallel num_threads(threads)
    {
      const int tid = omp_get_thread_num();
      struct px_fmm_thread *th = fmm->thr + tid;
      size_t j;
      int bad = 0;
      /* sources and targets into Morton order, and the upward pass (not
       * in an extension, R->reuse: done) */
      if (!R->reuse) {
#pragma omp for schedule(static) nowait
        for (size_t q = 0; q < ns; ++q) {
          ox[q] = sx[sp[q]];
          oy[q] = sy[sp[q]];
          og[q] = sg[sp[q]];
        }
        if (!self) {
#pragma omp for schedule(static) nowait
          for (size_t q = 0; q < nt; ++q) {
            otx[q] = tx[tp[q]];
            oty[q] = ty[tp[q]];
          }
        }
#pragma omp barrier
#pragma omp for schedule(dynamic, 1)
        for (size_t q = 0; q < S->nfront + (self ? 0 : T->nfront); ++q) {
          if (q < S->nfront)
            px_fmm_up_tree(R, S, R->sx, R->sy, 1, rmin, S->task[S->ntop + q]);
          else
            px_fmm_up_tree(R, T, R->tx, R->ty, 0, rmin, T->task[T->ntop + q - S->nfront]);
        }
      }
#pragma omp single
      {
        for (j = S->ntop; j-- > 0 && !R->reuse;)
          px_fmm_up_cell(R, S, R->sx, R->sy, 1, rmin, S->task[j]);
        if (!self)
          for (j = T->ntop; j-- > 0;) px_fmm_up_cell(R, T, R->tx, R->ty, 0, rmin, T->task[j]);
        *t2 = px_time_now();
        for (j = 0; j < T->ntop && !th->failed; ++j) px_fmm_target(R, th, tid, 0, T->task[j]);
      }
#pragma omp for schedule(dynamic, 1)
      for (size_t q = 0; q < T->nfront; ++q)
        if (!th->failed && px_fmm_own(fmm, T, q))
          px_fmm_down_tree(R, th, tid, T->task[T->ntop + q]);
      /* back to the input order, with the 1/(2π), unless a thread failed */
      for (int w = 0; w < fmm->nthreads; ++w) bad |= fmm->thr[w].failed;
      if (!bad) {
#pragma omp for schedule(static)
        for (size_t q = q0; q < q1; ++q) {
          const size_t o = tp[q];
          u[o] = (acc ? u[o] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * U[q];
          v[o] = (acc ? v[o] : PX_R(0.0)) + PX_BIOT_SAVART_SCALE * V[q];
        }
      }
    }
  }
}

/* The threads' counts into fmm->stats; 1 if a thread failed. */
static int px_fmm_collect(struct px_fmm *fmm) {
  int k, failed = 0;
  for (k = 0; k < fmm->nthreads; ++k) {
    const struct px_fmm_thread *th = fmm->thr + k;
    failed |= th->failed;
    fmm->stats.m2l += th->m2l;
    fmm->stats.p2l += th->p2l;
    fmm->stats.m2p += th->m2p;
    fmm->stats.p2p_cells += th->p2p_cells;
    fmm->stats.p2p_pairs += th->p2p_pairs;
    fmm->stats.m2p_targets += th->m2p_targets;
    fmm->stats.p2l_sources += th->p2l_sources;
    fmm->stats.m2l_terms += th->m2l_terms;
  }
  return failed;
}

enum px_status px_fmm_cpu(struct px_fmm *fmm, const struct px_fmm_params *prm,
                          const struct px_fmm_args *a) {
  struct px_context *ctx = fmm->ctx;
  struct px_fmm_run R;
  const size_t ns = a->n_src, nt = a->n_tgt;
  const size_t pad = 64 / sizeof(px_real);
  const size_t nsp = (ns + pad - 1) / pad * pad, ntp = (nt + pad - 1) / pad * pad;
  const double t0 = px_time_now();
  double t1, t2;
  const struct px_fmm_tree *S, *T;
  size_t i;
  PX_TRY(px_fmm_prepare(&R, fmm, prm, a));
  PX_TRY(px_fmm_storage(&R, fmm, a, nsp, ntp));
  px_fmm_tables(&R, fmm);
  t1 = px_time_now();
  t2 = t1;
  px_fmm_evaluate(&R, fmm, a, nsp, ntp, &t2);
  if (px_fmm_collect(fmm))
    return px_context_status(ctx) != PX_STATUS_OK ? px_context_status(ctx) : PX_STATUS_NOMEM;

  S = R.S;
  T = R.T;
  fmm->stats.src_cells = S->ncells;
  fmm->stats.tgt_cells = T->ncells;
  fmm->stats.src_generations = S->ngen;
  fmm->stats.tgt_generations = T->ngen;
  for (i = 0; i < S->ncells; ++i) fmm->stats.src_leaves += S->cell[i].nchild == 0;
  for (i = 0; i < T->ncells; ++i) fmm->stats.tgt_leaves += T->cell[i].nchild == 0;
  fmm->stats.t_tree = t1 - t0;
  fmm->stats.t_up = t2 - t1;
  fmm->stats.t_total = px_time_now() - t0;
  fmm->stats.t_down = fmm->stats.t_total - fmm->stats.t_up - fmm->stats.t_tree;
  /* what px_fmm_cpu_extend may build on */
  fmm->kept_ns = ns;
  fmm->kept_prm = *prm;
  fmm->kept_eps = a->eps;
  fmm->kept_real = sizeof(px_real);
  return PX_STATUS_OK;
}

/* The kept evaluation's parameters are prm, a->eps and this precision. */
static int px_fmm_kept_same(const struct px_fmm *fmm, const struct px_fmm_params *prm,
                            const struct px_fmm_args *a) {
  const struct px_fmm_params *k = &fmm->kept_prm;
  return fmm->kept_real == sizeof(px_real) && k->order == prm->order && k->err == prm->err &&
         k->leaf == prm->leaf && k->cost_m2l == prm->cost_m2l && k->cost_exp == prm->cost_exp &&
         fmm->kept_eps == a->eps;
}

/* fmm.h. The kept tree S stays the targets' (a view T of its first nc0
 * cells); the new sources' tree is built in fmm->tgt and its cells appended
 * to S's (indices and point ranges shifted), so that the traversal and the
 * near field read both through S; the sorted sources become the kept ones
 * followed by the new ones in their Morton order. */
int px_fmm_cpu_extend(struct px_fmm *fmm, const struct px_fmm_params *prm,
                      const struct px_fmm_args *a, size_t n_old) {
  struct px_context *ctx = fmm->ctx;
  struct px_fmm_tree *S = &fmm->src, *N = &fmm->tgt, Tv;
  struct px_fmm_run R;
  struct px_fmm_args b = *a;
  const int threads = a->threads;
  const int split_threads = fmm->parts > 1 ? threads * fmm->parts : threads;
  const size_t ns = a->n_src, nn = ns - n_old, pad = 64 / sizeof(px_real);
  const size_t nsp0 = (n_old + pad - 1) / pad * pad, nsp = (ns + pad - 1) / pad * pad;
  const px_real *sx = a->sx, *sy = a->sy, *sg = a->sg;
  const double t0 = px_time_now();
  size_t nc0, ncn = 0, q;
  px_real *pts;
  unsigned same = 1u;
  if (n_old == 0 || n_old > ns || fmm->kept_ns != n_old || !px_fmm_kept_same(fmm, prm, a)) {
    fmm->kept_ns = 0;
    return 0;
  }
  /* the kept sources are these: their sorted copies against the input */
  {
    const px_real *ox = fmm->points, *oy = ox + nsp0, *og = oy + nsp0;
    const uint32_t *sp = S->perm;
#pragma omp parallel for num_threads(threads) reduction(& : same) if (n_old >= PX_FMM_KEYS_PARALLEL)
    for (q = 0; q < n_old; ++q)
      same &= (unsigned)(ox[q] == sx[sp[q]] && oy[q] == sy[sp[q]] && og[q] == sg[sp[q]]);
  }
  if (!same) {
    fmm->kept_ns = 0;
    return 0;
  }
  b.n_tgt = n_old;
  b.self = 1;
  b.tx = sx;
  b.ty = sy;
  if (px_fmm_run_init(&R, fmm, prm, &b, S, S) != PX_STATUS_OK) return -1;
  /* the targets' tasks over the kept cells, before any is appended */
  if (px_fmm_tree_tasks(ctx, S, split_threads) != PX_STATUS_OK) return -1;
  nc0 = S->ncells;
  if (nn > 0) {
    if (px_fmm_tree_reserve(ctx, N, nn) != PX_STATUS_OK) return -1;
    px_fmm_keys(threads, nn, sx + n_old, sy + n_old, N->keys);
    if (px_fmm_tree_build(ctx, N, threads, nn, prm->leaf) != PX_STATUS_OK ||
        px_fmm_tree_cells(ctx, S, nc0 + N->ncells) != PX_STATUS_OK)
      return -1;
    ncn = N->ncells;
    for (q = 0; q < ncn; ++q) {
      struct px_fmm_cell *c = S->cell + nc0 + q;
      *c = N->cell[q];
      c->begin += (uint32_t)n_old;
      c->end += (uint32_t)n_old;
      if (c->nchild) c->child += (uint32_t)nc0;
      c->parent = q ? c->parent + (uint32_t)nc0 : UINT32_MAX;
    }
    S->ncells = nc0 + ncn;
    R.root2 = (uint32_t)nc0;
  }
  Tv = *S;
  Tv.ncells = nc0;
  R.S = S;
  R.T = &Tv;
  R.reuse = 1;
  /* storage for nsp sources (its head, the kept sorted sources at stride
   * nsp0, kept by the reallocation), n_old targets, all cells' multipoles */
  if (px_fmm_storage(&R, fmm, &b, nsp, nsp0) != PX_STATUS_OK) return -1;
  px_fmm_tables(&R, fmm);
  pts = fmm->points;
  /* g, then y, to the new stride (g first: y's new place may overlap g's
   * old one); then the new sources behind the kept ones */
  memmove(pts + 2 * nsp, pts + 2 * nsp0, n_old * sizeof *pts);
  memmove(pts + nsp, pts + nsp0, n_old * sizeof *pts);
  for (q = 0; q < nn; ++q) {
    const size_t j = n_old + N->perm[q];
    pts[n_old + q] = sx[j];
    pts[nsp + n_old + q] = sy[j];
    pts[2 * nsp + n_old + q] = sg[j];
  }
  if (nn > 0) px_fmm_up_tree(&R, S, R.sx, R.sy, 1, 1e-3 * a->eps, nc0);
  if (fmm->parts > 1) px_fmm_split(fmm, &Tv);
  {
    const double t1 = px_time_now();
    double t2 = t1;
    px_fmm_evaluate(&R, fmm, &b, nsp, nsp0, &t2);
    if (px_fmm_collect(fmm)) return -1;
    fmm->stats.src_cells = S->ncells;
    fmm->stats.tgt_cells = nc0;
    fmm->stats.t_tree = t1 - t0;
    fmm->stats.t_total = px_time_now() - t0;
    fmm->stats.t_down = fmm->stats.t_total - fmm->stats.t_tree;
  }
  return 1;
}
