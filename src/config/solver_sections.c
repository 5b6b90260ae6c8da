/* The solver sections of the root schema: none in this file.
 *
 * This is the plug-in point for solvers (see src/config/schema.h): the solver
 * registry defines px_case_solver_sections itself, e.g. in
 * src/solvers/registry.c,
 *
 *   const struct px_schema px_case_solver_sections[] = {
 *       PX_KEY_MAP("vortex", px_vortex_case_keys, "vortex element method"),
 *       PX_KEY_END};
 *
 * and this file is deleted (a duplicate definition fails to link). */
#include "config/schema.h"

const struct px_schema px_case_solver_sections[] = {PX_KEY_END};
