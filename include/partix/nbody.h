/* N-body velocity sums of 2D smoothed point vortices (the convective
 * velocity of the vortex method):
 *
 *   u(r_i) = Σ_j Γ_j / (2π) · k × (r_i − r_j) / max(|r_i − r_j|², ε²)
 *
 * over n_src sources (x, y, Γ) at n_tgt targets (x, y). The sum is pure: no
 * free stream, no self-exclusion needed (a coincident source adds exactly
 * zero since ε > 0), so sources and targets may be the same buffers.
 * Buffers hold SoA arrays of the precision's element type (single: f32,
 * double: f64) on the backend that runs the sum.
 *
 * Two entry points: px_nbody_direct (stateless, tiled O(n_src·n_tgt) sum)
 * and an evaluator object whose method is chosen at run time, so a solver
 * calls px_nbody_velocity and switches between direct summation and the
 * fast multipole method by configuration only (docs/fmm.md: accuracy,
 * speed, when each method is chosen). */
#ifndef PARTIX_NBODY_H
#define PARTIX_NBODY_H

#include <stddef.h>

#include "partix/backend.h"
#include "partix/context.h"
#include "partix/export.h"
#include "partix/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What happens to the output buffers. */
enum px_nbody_mode {
  PX_NBODY_MODE_SET = 0, /* out = sum */
  PX_NBODY_MODE_ADD = 1  /* out += sum (e.g. onto a free stream or another sum) */
};

/* How the sum is evaluated. Values are stable (case files, checkpoints). */
enum px_nbody_method {
  PX_NBODY_METHOD_DIRECT = 0, /* exact tiled pair sum, O(n_src n_tgt); every backend */
  PX_NBODY_METHOD_FMM = 1,    /* fast multipole method to a tolerance, O(n); cpu backend */
  PX_NBODY_METHOD_AUTO = 2    /* per call: direct on opencl and for small sums, else fmm */
};

PX_API const char *px_nbody_method_name(enum px_nbody_method method);
/* "direct", "fmm", "auto"; PX_STATUS_INVALID for other names. */
PX_API enum px_status px_nbody_method_parse(const char *name, enum px_nbody_method *out);

/* Direct tiled sum. eps > 0 (core radius, same length unit as x, y); n_src
 * or n_tgt may be 0 (with n_src = 0 the outputs are set to zero / left
 * unchanged). The outputs must be distinct from every input and from each
 * other. Tile width = the backend's work-group setting (0 = automatic: 128
 * on OpenCL, an L1-sized block on cpu); results do not depend on the thread
 * count, and on cpu are bitwise reproducible for a given tile width. When
 * the sources are the targets (same x and y buffers, n_src == n_tgt) the
 * cpu backend evaluates each pair once for both of its vortices (half the
 * divisions; terms summed in another order, same accuracy). */
PX_API enum px_status px_nbody_direct(struct px_backend *be, enum px_precision precision,
                                      size_t n_src, struct px_buffer *src_x,
                                      struct px_buffer *src_y, struct px_buffer *src_gamma,
                                      size_t n_tgt, struct px_buffer *tgt_x,
                                      struct px_buffer *tgt_y, double eps, enum px_nbody_mode mode,
                                      struct px_buffer *out_u, struct px_buffer *out_v);

/* A velocity evaluator: method, precision and parameters (and, for fast
 * methods, their reusable state). */
struct px_nbody;

/* FMM needs the cpu backend (PX_STATUS_UNSUPPORTED elsewhere: on a GPU the
 * direct sum is the fast path below ~1e5 vortices; use AUTO or DIRECT). */
PX_API enum px_status px_nbody_create(struct px_backend *be, enum px_nbody_method method,
                                      enum px_precision precision, double eps,
                                      struct px_nbody **out);
/* NULL-safe. */
PX_API void px_nbody_free(struct px_nbody *nb);
PX_API enum px_nbody_method px_nbody_method(const struct px_nbody *nb);
PX_API enum px_status px_nbody_set_eps(struct px_nbody *nb, double eps);

/* Accuracy of the fast method: the requested relative L2 error of the
 * velocity field, sqrt(Σ_i |u_i − u_i^exact|²) / sqrt(Σ_i |u_i^exact|²),
 * against the exact (double, direct) sum; the max error max_i |Δu_i| /
 * max_i |u_i| stays below it too. Default 1e-6. Range: 1e-12 to 0.1 in
 * double precision, 1e-5 to 0.1 in single precision (float sums carry
 * ~1e-7 rounding, growing with N; PX_STATUS_INVALID with a message
 * otherwise). The expansion order follows from it (docs/fmm.md gives the
 * rule and the measured errors); the direct sum ignores it. */
PX_API enum px_status px_nbody_set_tolerance(struct px_nbody *nb, double tolerance);
PX_API double px_nbody_tolerance(const struct px_nbody *nb);
/* Expert knob: fix the expansion order p (number of complex multipole and
 * local coefficients; 2..40 in double, 2..24 in single) instead of deriving
 * it from the tolerance; 0 returns to the tolerance. */
PX_API enum px_status px_nbody_set_order(struct px_nbody *nb, int order);
/* The order the FMM uses with the current settings. */
PX_API int px_nbody_order(const struct px_nbody *nb);
/* The method the last px_nbody_velocity call used (DIRECT or FMM: what AUTO
 * chose); the evaluator's method before the first call. */
PX_API enum px_nbody_method px_nbody_last_method(const struct px_nbody *nb);

/* Velocities at the targets by the evaluator's method (arguments as for
 * px_nbody_direct). The FMM keeps its tree and expansion memory in the
 * evaluator between calls; its results are bitwise the same for any
 * thread count. */
PX_API enum px_status px_nbody_velocity(struct px_nbody *nb, size_t n_src, struct px_buffer *src_x,
                                        struct px_buffer *src_y, struct px_buffer *src_gamma,
                                        size_t n_tgt, struct px_buffer *tgt_x,
                                        struct px_buffer *tgt_y, enum px_nbody_mode mode,
                                        struct px_buffer *out_u, struct px_buffer *out_v);

/* Reference: the same sum in plain double precision on host arrays, one
 * source after the other (no tiling, no SIMD): what the fast paths are
 * tested against. */
PX_API void px_nbody_direct_reference(size_t n_src, const double *src_x, const double *src_y,
                                      const double *src_gamma, size_t n_tgt, const double *tgt_x,
                                      const double *tgt_y, double eps, double *out_u,
                                      double *out_v);

#ifdef __cplusplus
}
#endif
#endif
