/* Double-precision instantiation of grid_cpu.h. */
#define PX_REAL double
#include "neighbors/grid_cpu.h"
