/* The cpu lattice engine's loops in float (lattice_cpu_impl.h, lattice_cpu_fields_impl.h). */
#define PX_REAL float
#include "solvers/lattice/lattice_cpu_impl.h"
#include "solvers/lattice/lattice_cpu_fields_impl.h"
