/* cpu loops in single precision (state and contacts). */
#define PX_REAL float
#define PX_GRAN_STATE float
#define PX_GRAN_OPS px_gran_cpu_ops_f32
#define PX_GRAN_SFX(n) px_gran_f32_##n
#include "solvers/granular/cpu_loops.h"
