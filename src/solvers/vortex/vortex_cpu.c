/* CPU instantiations of the vortex kernels for float and double. */
#include <math.h>
#include <stddef.h>

#include "solvers/vortex/vortex_cpu.h"

#define VX_REAL float
#define VX_K(name) name##_f
#define VX_M(fn) fn##f
#include "solvers/vortex/vortex_kernel.h"
#include "solvers/vortex/vortex_direct_tmpl.h"
#undef VX_REAL
#undef VX_K
#undef VX_M

#define VX_REAL double
#define VX_K(name) name##_d
#define VX_M(fn) fn
#include "solvers/vortex/vortex_kernel.h"
#include "solvers/vortex/vortex_direct_tmpl.h"
#undef VX_REAL
#undef VX_K
#undef VX_M
