/* Portable prelude of the granular kernel headers (C and OpenCL C).
 *
 * PX_REAL        arithmetic type of contact forces (float | double)
 * PX_GRAN_STATE  type of the integrated state: positions, velocities,
 *                forces and integrator history (defaults to PX_REAL; the
 *                `mixed` precision uses double state with float contacts)
 * PX_FN          qualifier of kernel-header functions
 *
 * In C the including translation unit defines PX_REAL (and optionally
 * PX_GRAN_STATE) before including a *_kernel.h header, once per precision:
 * the functions are `static inline`, so each instantiation lives in its own
 * translation unit (cpu_f32.c, cpu_f64.c, cpu_mixed.c). In OpenCL C the
 * program is built with -DPX_REAL=float|double.
 *
 * Kept apart from src/kernels/px_kernel.h so the granular physics compiles on
 * its own; the names agree with that header (PX_FN, PX_REAL). */
#ifndef PX_GRAN_REAL_H
#define PX_GRAN_REAL_H

#ifndef PX_REAL
#define PX_REAL double
#endif
#ifndef PX_GRAN_STATE
#define PX_GRAN_STATE PX_REAL
#endif

#ifndef PX_FN
#define PX_FN static inline
#endif

#if defined(__OPENCL_VERSION__) || defined(__OPENCL_C_VERSION__)
#define PX_GRAN_OPENCL 1
#define PX_GLOBAL __global
#define px_gran_sqrt(x) sqrt(x)
#define px_gran_log(x) log(x)
#define px_gran_fabs(x) fabs(x)
#define px_gran_fmin(a, b) fmin(a, b)
#define px_gran_fmax(a, b) fmax(a, b)
#else
#include <math.h>
#define PX_GLOBAL
/* Type-generic (C11 _Generic): float arguments call sqrtf. */
#define px_gran_sqrt(x) _Generic((x), float : sqrtf, default : sqrt)(x)
#define px_gran_log(x) _Generic((x), float : logf, default : log)(x)
#define px_gran_fabs(x) ((x) < 0 ? -(x) : (x))
#define px_gran_fmin(a, b) ((a) < (b) ? (a) : (b))
#define px_gran_fmax(a, b) ((a) > (b) ? (a) : (b))
#endif

#endif
