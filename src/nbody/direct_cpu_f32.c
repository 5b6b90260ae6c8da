/* Single-precision instantiation of direct_cpu.h. */
#define PX_REAL float
#include "nbody/direct_cpu.h"
