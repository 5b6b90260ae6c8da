/* Double-precision instantiation of fmm_cpu.h. */
#define PX_REAL double
#include "nbody/fmm_cpu.h"
