/* cpu loops in double precision (state and contacts). */
#define PX_REAL double
#define PX_GRAN_STATE double
#define PX_GRAN_OPS px_gran_cpu_ops_f64
#define PX_GRAN_SFX(n) px_gran_f64_##n
#include "solvers/granular/cpu_loops.h"
