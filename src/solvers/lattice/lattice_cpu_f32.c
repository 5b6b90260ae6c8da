/* The cpu lattice engine's loops in float (lattice_cpu_impl.h). */
#define PX_REAL float
#include "solvers/lattice/lattice_cpu_impl.h"
