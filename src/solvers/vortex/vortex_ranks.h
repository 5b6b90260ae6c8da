/* The vortex solver over the ranks of one run (`mpirun -np K partix run`,
 * core/comm.h; issue 21), private to the solver.
 *
 * Every rank holds the whole wake, the sheet and the panels (replicated: a
 * checkpoint loads the same state on every rank, and `gather` has nothing
 * to bring). The sums over the wake that dominate a step are split by
 * targets, each rank summing over all sources for its share:
 *  - convective velocities by the FMM (px_nbody_set_part): every rank builds
 *    the same quadtree and runs the whole upward pass (every target needs
 *    every source cell's multipole) and the top cells of the traversal, then
 *    the downward pass and near field of the subtrees whose first vortex lies
 *    in its K-th of the tree's Morton order (a space-filling curve);
 *  - diffusive velocities and eps* (the VVD): the groups of neighbouring
 *    vortices of the vortex tree (its leaf order) whose first vortex lies in
 *    the rank's K-th of that order;
 *  - restructuring's search of each vortex's merge partner: the leaves of
 *    the vortex tree starting in the rank's K-th;
 *  - the free stream and exact-sheet correction of the convective
 *    velocities: the rank's FMM targets, before their gather;
 *  - the crossing tests of non-penetration and of the rk2 predictor: the
 *    rank's contiguous share of the wake (px_vortex_ranks_share), the
 *    crossed panels gathered as int32.
 * A target's sum does not depend on which other targets are evaluated, so
 * the result is the 1-rank result bit for bit. One px_comm_allgatherv per
 * split sum brings every target's values to every rank (in the split order,
 * which is the same on every rank: the trees are built from the same data).
 * Everything else (the sheet, the FMM's upward pass, loads, the moves,
 * absorption, the removals and merges of restructuring, and direct sums, whose symmetric pair
 * schedule adds each vortex's terms in an order a split by targets would change) runs whole on
 * every rank from identical data, so every rank takes the same decisions.
 *
 * The opencl engine (vortex_opencl.c) splits its direct sums instead into
 * K contiguous shares of the targets (px_vortex_ranks_share): the
 * convective sum and eps* with the VVD velocities, each target computed by
 * one work-item over the same source tiles whatever the share; one
 * allgatherv of the device's reals per split sum (2N convective, 3N
 * diffusive: 10 N reals per rk2 step, 5 N with euler), written back to
 * every device (px_vortex_ocl_gather).
 *
 * Per step and rank on the cpu engine, with N vortices: one allgatherv of 2N doubles per
 * convective FMM sum and one of 3N doubles per diffusive sum (2N without
 * eps*), two of each with rk2, one with euler, one of N int32 (merge
 * partners) and one of N int32 per crossing test (non-penetration, and the
 * rk2 predictor), and with n panels one of n doubles per sheet right-hand
 * side and per loads evaluation: 92 N + 24 n bytes received per step with
 * rk2 (48 N + 16 n with euler), 1/K of them sent; plus a status agreement
 * (px_comm_agree) before each gather,
 * so that a rank's failure stops all. */
#ifndef PX_VORTEX_RANKS_H
#define PX_VORTEX_RANKS_H

#include "solvers/vortex/vortex_core.h"

struct px_case;

/* Collective: after px_vortex_core_create returned st (e: its engine, NULL
 * when it failed), the ranks agree on st; then e takes the run's ranks
 * (px_context_comm(ctx)), every rank takes rank 0's factors of the panel
 * matrix, and rank 0 says at INFO how the sums are split. The factors come
 * from LAPACK, whose blocked LU rounds differently with its thread count
 * (pinned to one for OpenBLAS only: vortex_panels.c) and with the kernels
 * it picks for the node's CPU, so ranks on different nodes that factored on
 * their own could shed different sheets. (The step's solves, triangular
 * with one right-hand side, are taken to round alike everywhere.) One rank:
 * st, e takes the single rank. fmm: the engine's px_vortex_caps.fmm (0: the
 * opencl engine, whose direct sums split by contiguous shares: the log
 * says which split). */
enum px_status px_vortex_ranks_init(struct px_context *ctx, struct px_vortex_engine *e, int fmm,
                                    enum px_status st);
/* The number of ranks. */
int px_vortex_ranks_count(const struct px_vortex_engine *e);
/* A case over several ranks on an engine that cannot split its sums
 * (engine_ranks: px_vortex_caps.ranks, 0) is refused at backend.type
 * (PX_STATUS_CONFIG). Both engines split theirs today (cpu and opencl);
 * the check stays for an engine added without. */
enum px_status px_vortex_ranks_check(struct px_case *c, struct px_context *ctx, int engine_ranks,
                                     const char *backend);

/* This rank's share of runs of n sorted positions, starts[0..nrun) ascending
 * with starts[0] = 0 (the runs tile [0, n)): the runs whose start lies in
 * [n r / K, n (r + 1) / K) as [*r0, *r1), and the positions they cover as
 * [*lo, *hi). One rank: everything. */
void px_vortex_ranks_runs(const struct px_vortex_engine *e, const uint32_t *starts, size_t nrun,
                          size_t n, size_t *r0, size_t *r1, size_t *lo, size_t *hi);

/* Collective (K > 1): agree on st (a failure on any rank fails all, with
 * its message); then, when order is not NULL, for the split sum `sum` (0
 * convective, 1 diffusive: e->split_n), every rank's values
 * arr[a][order[q]], q in its [lo, hi) (the ranks' runs tile [0, n) in rank
 * order), go to every rank, into arr[a][order[q]]. Returns the agreed
 * status, or the gather's. One rank: st. */
enum px_status px_vortex_ranks_gather(struct px_vortex_engine *e, int sum, enum px_status st,
                                      const uint32_t *order, size_t n, size_t lo, size_t hi,
                                      double *const *arr, int narr);
/* The opencl engine's split (vortex_opencl.c) and the cpu engine's crossing
 * tests: this rank's share of n targets, [*lo, *hi) = [n r / K, n (r + 1) / K) (contiguous,
 * balanced by count; one rank: [0, n)). */
void px_vortex_ranks_share(const struct px_vortex_engine *e, size_t n, size_t *lo, size_t *hi);
/* Collective (K > 1): agree on st; then every rank's share (above) of narr
 * arrays of n values of es bytes, send = this rank's [narr][hi - lo] values
 * (array after array), lands in out = [narr][n] on every rank, bytes as
 * sent (device reals travel unconverted). `sum` as in px_vortex_ranks_gather.
 * Returns the agreed status, or the gather's. One rank: st, out untouched. */
enum px_status px_vortex_ranks_gather_shares(struct px_vortex_engine *e, int sum, enum px_status st,
                                             size_t n, size_t narr, size_t es, const void *send,
                                             void *out);
/* Rank 0, at the run's end: at INFO, the last split and the bytes and
 * seconds spent communicating (nothing on one rank). */
void px_vortex_ranks_report(const struct px_vortex_engine *e);

/* This rank's leaves of tree t (restructuring's partner search): those whose
 * first sorted position lies in [*a, *b) = [n r / K, n (r + 1) / K), which
 * cover the positions [*lo, *hi). One rank: every leaf, [0, n). */
void px_vortex_ranks_leaves(const struct px_vortex_engine *e, const struct px_vortex_tree *t,
                            size_t *a, size_t *b, size_t *lo, size_t *hi);
/* Collective (K > 1): agree on st; then each rank's run v[lo..hi) of n
 * values of es bytes (the ranks' runs tile [0, n) in rank order: sorted
 * positions of the partner search, crossing tests' or panels' shares) goes
 * to every rank's v. Returns the agreed status, or the gather's. One rank:
 * st. */
enum px_status px_vortex_ranks_gather_runs(struct px_vortex_engine *e, enum px_status st, size_t n,
                                           size_t lo, size_t hi, void *v, size_t es);

/* Collective (K > 1), at the step's end, after the ranks agree on st (the
 * step's status so far): the ranks' replicated wakes are the same, bit for bit (a hash of every
 * position and circulation, and the count, compared by one allreduce); else PX_STATUS_INTERNAL on
 * every rank, naming the step. The replicated blocks round alike on every rank only where the ranks
 * run the same code on the same kind of CPU (libm picks its routines by CPU); a divergence caught
 * here would otherwise surface later as a hang or a wrong answer. One rank: OK. */
enum px_status px_vortex_ranks_verify(struct px_vortex_engine *e, enum px_status st);

/* The convective sum's split (vortex_cpu.c): from now on the pair sums'
 * evaluator computes this rank's part (on, K > 1) or every target (off). */
void px_vortex_ranks_split_sums(struct px_vortex_engine *e, int on);

#endif
