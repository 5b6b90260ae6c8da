/* Private part of the N-body module: per-backend kernel table and the cpu
 * loops. */
#ifndef PX_NBODY_IMPL_H
#define PX_NBODY_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "compute/backend_impl.h"
#include "nbody/fmm.h"
#include "partix/nbody.h"

/* Per-backend direct sum (see "Kernel tables" in backend_impl.h). Arguments
 * are validated by direct.c; n_tgt > 0. eps2 = ε² in double. */
/* `threads`: the OpenMP threads a cpu sum uses (the backend's, or
 * px_nbody_set_threads's); the device sums ignore it. */
struct px_nbody_ops {
  const char *backend;
  enum px_status (*direct)(struct px_backend *be, int threads, enum px_precision precision,
                           size_t n_src, struct px_buffer *sx, struct px_buffer *sy,
                           struct px_buffer *sg, size_t n_tgt, struct px_buffer *tx,
                           struct px_buffer *ty, double eps2, enum px_nbody_mode mode,
                           struct px_buffer *u, struct px_buffer *v);
  /* Fast multipole method (optional: NULL where the backend has none);
   * arguments validated, n_tgt > 0, n_src > 0. */
  enum px_status (*fmm)(struct px_backend *be, int threads, struct px_fmm *fmm,
                        enum px_precision precision, const struct px_fmm_params *prm, size_t n_src,
                        struct px_buffer *sx, struct px_buffer *sy, struct px_buffer *sg,
                        size_t n_tgt, struct px_buffer *tx, struct px_buffer *ty, double eps,
                        enum px_nbody_mode mode, struct px_buffer *u, struct px_buffer *v);
  /* An extension of the last FMM evaluation (px_nbody_velocity_extend;
   * optional): 1 done, 0 not applicable, -1 failed. */
  int (*fmm_extend)(struct px_backend *be, int threads, struct px_fmm *fmm,
                    enum px_precision precision, const struct px_fmm_params *prm, size_t n_src,
                    struct px_buffer *sx, struct px_buffer *sy, struct px_buffer *sg, size_t n_old,
                    double eps, enum px_nbody_mode mode, struct px_buffer *u, struct px_buffer *v);
};

/* Sums below this many pairs (n_src · n_tgt) take the direct sum under
 * PX_NBODY_METHOD_AUTO on the cpu (docs/fmm.md: measured crossover). */
extern const double px_nbody_auto_pairs;

/* Internal knobs for tests and benchmarks: replace the FMM parameters that
 * the tolerance rule would choose (NULL: back to the rule), and read the
 * counters and timings of the last FMM evaluation. */
void px_nbody_fmm_override(struct px_nbody *nb, const struct px_fmm_params *prm);
const struct px_fmm_stats *px_nbody_fmm_stats(const struct px_nbody *nb);

/* Split evaluations (the ranks of one run, core/comm.h): from now on, an
 * evaluation by the FMM computes only part `part` of `parts` of the targets
 * (struct px_fmm, split); parts <= 1 returns to whole sums. The direct sum
 * always computes every target. px_nbody_part_targets: 1 when the last
 * px_nbody_velocity was split, with the input indices of its targets
 * perm[lo..hi) (borrowed, valid until the next evaluation; every part gets
 * the same perm, and the parts' runs tile [0, n_tgt) in part order); 0 when
 * it wrote every target. */
void px_nbody_set_part(struct px_nbody *nb, int part, int parts);
/* The threads of nb's cpu sums from now on (a solver's thread tuner,
 * core/tuner.h: the sums give the same bits on any count); 0: the
 * backend's (the default). */
void px_nbody_set_threads(struct px_nbody *nb, int threads);
/* The sums at the first n_old of n_src sources (the targets: those sources)
 * from all n_src, where the first n_old are the sources of nb's last
 * evaluation and unchanged since (the vortex wake between the generation's
 * sum at the panels and the convective one, the newborns behind): on the
 * cpu backend with the FMM, that evaluation's tree and multipoles serve
 * again (px_fmm_cpu_extend_*); otherwise, or where that does not apply,
 * the whole sum with the sources as targets. *extended: 1 when the FMM's
 * extension ran (then only the first n_old entries of u and v are written,
 * and a split evaluation's targets, px_nbody_part_targets, are those n_old),
 * 0 when the whole sum ran (all n_src entries). Sources, mode and outputs
 * as for px_nbody_velocity. */
enum px_status px_nbody_velocity_extend(struct px_nbody *nb, size_t n_src, struct px_buffer *src_x,
                                        struct px_buffer *src_y, struct px_buffer *src_gamma,
                                        size_t n_old, enum px_nbody_mode mode,
                                        struct px_buffer *out_u, struct px_buffer *out_v,
                                        int *extended);
int px_nbody_part_targets(const struct px_nbody *nb, const uint32_t **perm, size_t *lo, size_t *hi);

extern const struct px_nbody_ops px_nbody_ops_cpu;
extern const struct px_nbody_ops px_nbody_ops_opencl; /* with the opencl backend */
/* The opencl direct sum (ops->direct, eps2 = eps^2) of the targets [t0, t1)
 * only, into u, v at the same indices (the others untouched): each target's
 * sum is the one the whole launch gives it, bit for bit (one work-item per
 * target, the same tiles of sources in the same order whatever its
 * neighbours), so shares of the targets computed apart (the vortex solver's
 * ranks) give the whole sum. Defined with the opencl backend only; no
 * argument checks (px_nbody_direct's). */
enum px_status px_nbody_cl_direct_range(struct px_backend *be, enum px_precision precision,
                                        size_t n_src, struct px_buffer *sx, struct px_buffer *sy,
                                        struct px_buffer *sg, size_t t0, size_t t1,
                                        struct px_buffer *tx, struct px_buffer *ty, double eps2,
                                        enum px_nbody_mode mode, struct px_buffer *u,
                                        struct px_buffer *v);

/* cpu tiled loops (direct_cpu.h), one instantiation per precision. `tile`:
 * sources per L1 block (0 = automatic). */
void px_nbody_direct_cpu_f32(int threads, size_t tile, size_t n_src, const float *sx,
                             const float *sy, const float *sg, size_t n_tgt, const float *tx,
                             const float *ty, float eps2, int accumulate, float *u, float *v);
void px_nbody_direct_cpu_f64(int threads, size_t tile, size_t n_src, const double *sx,
                             const double *sy, const double *sg, size_t n_tgt, const double *tx,
                             const double *ty, double eps2, int accumulate, double *u, double *v);
/* Sources = targets, each pair once; su, sv: n elements of scratch. */
void px_nbody_self_cpu_f32(int threads, size_t tile, size_t n, const float *x, const float *y,
                           const float *g, float eps2, int accumulate, float *u, float *v,
                           float *su, float *sv);
void px_nbody_self_cpu_f64(int threads, size_t tile, size_t n, const double *x, const double *y,
                           const double *g, double eps2, int accumulate, double *u, double *v,
                           double *su, double *sv);

#endif
