/* cpu loops in mixed precision: double state, float contacts. */
#define PX_REAL float
#define PX_GRAN_STATE double
#define PX_GRAN_OPS px_gran_cpu_ops_mixed
#define PX_GRAN_SFX(n) px_gran_mixed_##n
#define PX_GRAN_RELPOS 1
#include "solvers/granular/cpu_loops.h"
