/* Double-precision instantiation of lincomb_cpu.h. */
#define PX_REAL double
#include "compute/cpu/lincomb_cpu.h"
