/* The solvers built into partix, by name: the one list. Each entry NAME
 * provides `px_solver_NAME` (its struct px_solver_i) and `px_solver_NAME_keys`
 * (the keys of its case section, a PX_KEY_END-terminated px_schema array). */
#include <stddef.h>
#include <threads.h>

#include "config/schema.h"

#include "solvers/solver.h"

#define PX_SOLVER_LIST(X) X(granular) X(lattice) X(vortex)

#define PX_SOLVER_DECLARE_(name)                    \
  extern const struct px_solver_i px_solver_##name; \
  extern const struct px_schema px_solver_##name##_keys[];
PX_SOLVER_LIST(PX_SOLVER_DECLARE_)

#define PX_SOLVER_ENTRY_(name) &px_solver_##name,
static const struct px_solver_i *const px_solvers[] = {PX_SOLVER_LIST(PX_SOLVER_ENTRY_) NULL};

/* The case sections of the solvers, plugged into the platform's keys: the
 * root schema of this build. The config layer knows no solver: the case
 * functions of the public API that need this build's schema are defined in
 * case_root.c, on the config layer's px_case_*_schema. (A test links its own
 * registry in place of this file: px_solver_registry and
 * px_case_root_schema.) */
#define PX_SOLVER_SECTION_(name) PX_KEY_MAP(#name, px_solver_##name##_keys, "the " #name " solver"),
static const struct px_schema px_solver_sections[] = {PX_SOLVER_LIST(PX_SOLVER_SECTION_)
                                                          PX_KEY_END};

static struct px_case_root_storage px_root_storage;
static const struct px_schema *px_root;
static once_flag px_root_once = ONCE_FLAG_INIT;

static void px_root_init(void) {
  px_root = px_case_root_schema_build(px_solver_sections, &px_root_storage);
}

const struct px_schema *px_case_root_schema(void) {
  call_once(&px_root_once, px_root_init);
  return px_root;
}

const struct px_solver_i *const *px_solver_registry(void) { return px_solvers; }
