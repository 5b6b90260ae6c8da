/* The lattice physics (lattice_kernel.h) instantiated for C: float items are
 * named lt_NAME_f, double items lt_NAME_d (static inline, no linkage). */
#ifndef PX_LATTICE_C_H
#define PX_LATTICE_C_H

#include <math.h>

/* The kernels must be inlined into the simd loops to vectorize; gcc's size
 * heuristics refuse for the link law, so force it where the compiler has
 * the attribute (any other compiler gets plain static inline). */
#if defined(__GNUC__)
#define LT_FN static inline __attribute__((always_inline))
#else
#define LT_FN static inline
#endif
#define LT_G

#define LT_R float
#define LT_(name) lt_##name##_f
#define LT_SQRT sqrtf
#include "solvers/lattice/lattice_kernel.h"
#undef LT_R
#undef LT_
#undef LT_SQRT

#define LT_R double
#define LT_(name) lt_##name##_d
#define LT_SQRT sqrt
#include "solvers/lattice/lattice_kernel.h"
#undef LT_R
#undef LT_
#undef LT_SQRT

#endif
