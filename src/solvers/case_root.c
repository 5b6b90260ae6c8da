/* The case functions of the public API (partix/case.h) that need this
 * build's root schema (registry.c): the config layer's px_case_*_schema
 * functions with the schema of the solvers built in. */
#include <stdio.h>

#include "config/schema.h"
#include "partix/case.h"
#include "solvers/solver.h"

enum px_status px_case_load(struct px_context *ctx, const char *path, const char *const *overrides,
                            size_t noverrides, struct px_case **out) {
  return px_case_load_schema(ctx, px_case_root_schema(), path, overrides, noverrides, out);
}

enum px_status px_case_load_string(struct px_context *ctx, const char *name, const char *text,
                                   size_t len, const char *const *overrides, size_t noverrides,
                                   struct px_case **out) {
  return px_case_load_string_schema(ctx, px_case_root_schema(), name, text, len, overrides,
                                    noverrides, out);
}

enum px_status px_case_print_keys(FILE *out, const char *section) {
  return px_case_print_schema(px_case_root_schema(), section, out);
}

const char *px_case_key_doc(const char *path) {
  return px_schema_key_doc(px_case_root_schema(), path);
}
