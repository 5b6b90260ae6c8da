/* The solvers built into partix, by name: the one list. Each entry NAME
 * provides `px_solver_NAME` (its struct px_solver_i) and `px_solver_NAME_keys`
 * (the keys of its case section, a PX_KEY_END-terminated px_schema array). */
#include <stddef.h>

#include "solvers/solver.h"

#define PX_SOLVER_LIST(X) X(granular) X(lattice) X(vortex)

#define PX_SOLVER_DECLARE_(name)                                                \
  extern const struct px_solver_i px_solver_##name;                             \
  extern const struct px_schema px_solver_##name##_keys[];
PX_SOLVER_LIST(PX_SOLVER_DECLARE_)

#define PX_SOLVER_ENTRY_(name) &px_solver_##name,
static const struct px_solver_i *const px_solvers[] = {PX_SOLVER_LIST(PX_SOLVER_ENTRY_) NULL};

/* The case sections, plugged into the root schema (src/config/schema.h). */
#define PX_SOLVER_SECTION_(name) PX_KEY_MAP(#name, px_solver_##name##_keys, "the " #name " solver"),
const struct px_schema px_case_solver_sections[] = {PX_SOLVER_LIST(PX_SOLVER_SECTION_) PX_KEY_END};

const struct px_solver_i *const *px_solver_registry(void) { return px_solvers; }
