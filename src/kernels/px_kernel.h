/* Portability layer: physics written ONCE, compiled as C by the cpu backend
 * and as OpenCL C by the opencl backend.
 *
 * The including code defines PX_REAL (float or double) first:
 *   - OpenCL: the program is built with -DPX_REAL=float|double
 *     (px_opencl_program_real does it), one precision per program;
 *   - C: a per-precision translation unit, e.g. foo_cpu_f32.c =
 *       #define PX_REAL float
 *       + an include of foo/foo_cpu.h (the loop template)
 *     one precision per translation unit, exactly like one per program.
 *
 * So a body header (biot_savart.h, grid.h, a solver's contact force) is an
 * ordinary header with an include guard, compiled once per precision in
 * separate units; nothing in it is name-mangled. Names that must be
 * distinct across the two C instantiations (the extern loop functions) use
 * PX_SFX(name): name_f32 / name_f64.
 *
 * What this header gives body code:
 *   PX_FN                 static inline (C and OpenCL C 1.2)
 *   PX_FN_INLINE          PX_FN that the C compiler must inline (gcc, clang:
 *                         always_inline), for bodies called inside `omp simd`
 *                         loops: gcc's size heuristics refuse large ones, and
 *                         a call stops the vectorizer
 *   px_idx                index of an element of a buffer: size_t in C, uint
 *                         in OpenCL C (the host bounds buffers it launches)
 *   PX_GLOBAL, PX_LOCAL   __global/__local in OpenCL C, nothing in C
 *   px_real               PX_REAL
 *   px_real2, px_real3    float2/double2/... in OpenCL C, a small struct in C;
 *                         build with px_v2(x, y) / px_v3(x, y, z), access .x .y .z
 *   px_v2_add/sub/scale/dot/cross/perp/norm2 (and px_v3_*)
 *   PX_R(0.5)             a literal in px_real
 *   sqrt, exp, floor, fabs, ...  type-generic: <tgmath.h> in C, built-ins in
 *                         OpenCL C, so sqrt(x) is sqrtf for float x on both
 *   PX_REAL_IS_DOUBLE     0 or 1, usable in #if
 *   px_gsqrt, px_glog, px_gabs, px_gmin, px_gmax  of any real type, keeping
 *                         it (for code mixing precisions)
 *
 * Rules for body headers: pure functions of their arguments (no globals);
 * quoted includes only of other body headers in src/kernels/ (the OpenCL
 * embedder inlines every quoted include line, even inside #if blocks and
 * comments, so never write one in a comment here); arithmetic in
 * px_real with PX_R() literals (a bare 0.5 is a double and would promote
 * float code); spell out sums in the order you want (C is compiled with
 * -ffp-contract=off, OpenCL may contract a*b+c into fma, so cpu and opencl
 * results agree to rounding, not bitwise). */
#ifndef PX_KERNEL_H
#define PX_KERNEL_H

#ifndef PX_REAL
#error "define PX_REAL (float or double) before including kernels/px_kernel.h"
#endif

#define PX_CAT_(a, b) a##b
#define PX_CAT(a, b) PX_CAT_(a, b)

/* PX_REAL_IS_DOUBLE expands PX_REAL and pastes: PX_REAL_IS_DOUBLE_float -> 0. */
#define PX_REAL_IS_DOUBLE_float 0
#define PX_REAL_IS_DOUBLE_double 1
#define PX_REAL_IS_DOUBLE PX_CAT(PX_REAL_IS_DOUBLE_, PX_REAL)
#define PX_REAL_SUFFIX_float _f32
#define PX_REAL_SUFFIX_double _f64
#define PX_SFX(name) PX_CAT(name, PX_CAT(PX_REAL_SUFFIX_, PX_REAL))

#if defined(__OPENCL_VERSION__)
/* ------------------------------- OpenCL C ------------------------------- */
#if PX_REAL_IS_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#endif
#define PX_FN static inline
#define PX_FN_INLINE static inline
#define PX_GLOBAL __global
#define PX_LOCAL __local
typedef PX_REAL px_real;
typedef uint px_idx;
#define px_real2 PX_CAT(PX_REAL, 2)
#define px_real3 PX_CAT(PX_REAL, 3)
PX_FN px_real2 px_v2(px_real x, px_real y) { return (px_real2)(x, y); }
PX_FN px_real3 px_v3(px_real x, px_real y, px_real z) { return (px_real3)(x, y, z); }

#else
/* ---------------------------------- C ---------------------------------- */
#include <math.h>
#include <stddef.h>
#include <tgmath.h>
#define PX_FN static inline
#if defined(__GNUC__)
#define PX_FN_INLINE static inline __attribute__((always_inline))
#else
#define PX_FN_INLINE static inline
#endif
#define PX_GLOBAL
#define PX_LOCAL
typedef PX_REAL px_real;
typedef size_t px_idx;
/* Tagged per precision, so the float and double layouts never share a tag. */
struct PX_CAT(px_real2_, PX_REAL) {
  px_real x, y;
};
struct PX_CAT(px_real3_, PX_REAL) {
  px_real x, y, z;
};
#define px_real2 struct PX_CAT(px_real2_, PX_REAL)
#define px_real3 struct PX_CAT(px_real3_, PX_REAL)
PX_FN px_real2 px_v2(px_real x, px_real y) {
  px_real2 r;
  r.x = x;
  r.y = y;
  return r;
}
PX_FN px_real3 px_v3(px_real x, px_real y, px_real z) {
  px_real3 r;
  r.x = x;
  r.y = y;
  r.z = z;
  return r;
}
#endif

/* Type-generic helpers for code that mixes precisions (a float contact law
 * in a double state: granular's `mixed`): they keep their argument's type.
 * px_gsqrt, px_glog: sqrt, log of a float or a double (sqrtf for a float in
 * C, as in OpenCL C); px_gabs, px_gmin, px_gmax: |x|, min, max (ternaries in
 * C, the built-ins in OpenCL C). */
#if defined(__OPENCL_VERSION__)
#define px_gsqrt(x) sqrt(x)
#define px_glog(x) log(x)
#define px_gabs(x) fabs(x)
#define px_gmin(a, b) fmin(a, b)
#define px_gmax(a, b) fmax(a, b)
#else
#define px_gsqrt(x) _Generic((x), float : sqrtf, default : sqrt)(x)
#define px_glog(x) _Generic((x), float : logf, default : log)(x)
#define px_gabs(x) ((x) < 0 ? -(x) : (x))
#define px_gmin(a, b) ((a) < (b) ? (a) : (b))
#define px_gmax(a, b) ((a) > (b) ? (a) : (b))
#endif

/* ------------------------ common to both languages ----------------------- */
#define PX_R(literal) ((px_real)(literal))
#define PX_PI PX_R(3.14159265358979323846)
/* unit roundoff of px_real (FLT_EPSILON, DBL_EPSILON: spelled out, OpenCL C has
 * no float.h on every platform) */
#define PX_REAL_EPS (PX_REAL_IS_DOUBLE ? PX_R(2.220446049250313e-16) : PX_R(1.1920929e-7))

PX_FN px_real px_maxr(px_real a, px_real b) { return a > b ? a : b; }
PX_FN px_real px_minr(px_real a, px_real b) { return a < b ? a : b; }
PX_FN int px_clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

PX_FN px_real2 px_v2_add(px_real2 a, px_real2 b) { return px_v2(a.x + b.x, a.y + b.y); }
PX_FN px_real2 px_v2_sub(px_real2 a, px_real2 b) { return px_v2(a.x - b.x, a.y - b.y); }
PX_FN px_real2 px_v2_scale(px_real2 a, px_real s) { return px_v2(a.x * s, a.y * s); }
PX_FN px_real px_v2_dot(px_real2 a, px_real2 b) { return a.x * b.x + a.y * b.y; }
/* z-component of a × b (a, b in the plane). */
PX_FN px_real px_v2_cross(px_real2 a, px_real2 b) { return a.x * b.y - a.y * b.x; }
/* k × a: a turned by +90° about the z axis. */
PX_FN px_real2 px_v2_perp(px_real2 a) { return px_v2(-a.y, a.x); }
PX_FN px_real px_v2_norm2(px_real2 a) { return a.x * a.x + a.y * a.y; }

PX_FN px_real3 px_v3_add(px_real3 a, px_real3 b) { return px_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
PX_FN px_real3 px_v3_sub(px_real3 a, px_real3 b) { return px_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
PX_FN px_real3 px_v3_scale(px_real3 a, px_real s) { return px_v3(a.x * s, a.y * s, a.z * s); }
PX_FN px_real px_v3_dot(px_real3 a, px_real3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
PX_FN px_real3 px_v3_cross(px_real3 a, px_real3 b) {
  return px_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
PX_FN px_real px_v3_norm2(px_real3 a) { return a.x * a.x + a.y * a.y + a.z * a.z; }

#endif
