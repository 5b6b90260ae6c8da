/* The lattice physics (lattice_kernel.h) for host code: setup, the
 * reference engine, engine state transfers, checkpoints and tests work in
 * double, so a translation unit that includes this compiles the kernel
 * header with PX_REAL double (the cpu engine's float and double loops are
 * lattice_cpu_f32.c and lattice_cpu_f64.c, units of their own). */
#ifndef PX_LATTICE_C_H
#define PX_LATTICE_C_H

#ifndef PX_REAL
#define PX_REAL double
#endif
#include "kernels/px_kernel.h"
#if !PX_REAL_IS_DOUBLE
#error "lattice host code is double: include lattice_c.h only where PX_REAL is double"
#endif
#include "solvers/lattice/lattice_kernel.h"
/* <tgmath.h> (px_kernel.h) includes <complex.h>, whose macro I would
 * replace the model's rotational inertia m->I; lattice code uses no complex
 * numbers. */
#undef I

#endif
