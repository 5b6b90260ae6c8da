/* Double-precision instantiation of direct_cpu.h. */
#define PX_REAL double
#include "nbody/direct_cpu.h"
