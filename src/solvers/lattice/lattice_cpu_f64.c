/* The cpu lattice engine's loops in double (lattice_cpu_impl.h, lattice_cpu_fields_impl.h). */
#define PX_REAL double
#include "solvers/lattice/lattice_cpu_impl.h"
#include "solvers/lattice/lattice_cpu_fields_impl.h"
