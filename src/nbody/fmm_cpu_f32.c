/* Single-precision instantiation of fmm_cpu.h. */
#define PX_REAL float
#include "nbody/fmm_cpu.h"
