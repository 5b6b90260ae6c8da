/* Single-precision instantiation of lincomb_cpu.h. */
#define PX_REAL float
#include "compute/cpu/lincomb_cpu.h"
