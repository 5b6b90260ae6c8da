/* Single-precision instantiation of grid_cpu.h. */
#define PX_REAL float
#include "neighbors/grid_cpu.h"
