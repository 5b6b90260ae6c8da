/* Case files: one YAML file describes a whole run (solver, backend, time,
 * output, then the solver's section). Loading validates the file against the
 * schema of this build, fills in defaults, applies --set overrides and keeps
 * the resolved case, which solvers read with getters by key path.
 *
 * Key paths are dotted key names with list indices: "time.dt",
 * "backend.type", "vortex.bodies[1].chord", "vortex.v_inf[0]".
 *
 * Every error a user can cause reads "FILE:LINE:COL: key.path: message"
 * (1-based line and column of the offending node), or
 * "--set key.path=value: key.path: message" for a command-line override; all
 * errors found (up to 20) are reported together, one per line. */
#ifndef PARTIX_CASE_H
#define PARTIX_CASE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "partix/context.h"
#include "partix/export.h"
#include "partix/status.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_case;

/* Most errors reported by one load; the rest are counted ("... and 3 more"). */
#define PX_CASE_MAX_ERRORS 20
/* Largest case file accepted [bytes]. */
#define PX_CASE_MAX_BYTES (16u * 1024u * 1024u)

/* Load and validate the case file `path`. `overrides` (may be NULL when
 * noverrides is 0) are "key.path=value" strings, value in YAML flow syntax
 * ("time.steps=100", "backend.type=opencl", "vortex.v_inf=[1, 0]"), applied in
 * order before validation; intermediate maps are created as needed and
 * "list[N]" with N = length appends. On success *out is a case to free with
 * px_case_free. On failure *out is NULL and the status is PX_STATUS_CONFIG
 * (invalid case), PX_STATUS_IO (unreadable file) or PX_STATUS_NOMEM, with the
 * message(s) in ctx. ctx is borrowed by the case for its whole life. */
PX_API enum px_status px_case_load(struct px_context *ctx, const char *path,
                                   const char *const *overrides, size_t noverrides,
                                   struct px_case **out);
/* The same from YAML text in memory (e.g. the case stored in a checkpoint);
 * `name` stands for the file name in messages. */
PX_API enum px_status px_case_load_string(struct px_context *ctx, const char *name,
                                          const char *text, size_t len,
                                          const char *const *overrides, size_t noverrides,
                                          struct px_case **out);
/* NULL-safe. */
PX_API void px_case_free(struct px_case *c);

/* The file name given to load (owned by c). */
PX_API const char *px_case_file(const struct px_case *c);
/* The value of the top-level `solver:` key (owned by c), NULL if none. */
PX_API const char *px_case_solver(const struct px_case *c);
/* 64-bit FNV-1a hash of px_case_resolved_text: equal hashes mean equal runs. */
PX_API uint64_t px_case_hash(const struct px_case *c);
/* The resolved case as YAML: keys in schema order, defaults filled in,
 * overrides applied, no comments (owned by c, NUL-terminated). Loading it again
 * gives the same text and hash. */
PX_API const char *px_case_resolved_text(const struct px_case *c);
/* Write the resolved text to `path` atomically. */
PX_API enum px_status px_case_write_resolved(const struct px_case *c, const char *path);

/* The file named by the input-file key at `path` (a profile, a DXF
 * drawing): an absolute name as given; a relative name from the case file
 * relative to the case file's folder (for a case read from a checkpoint, the
 * checkpoint's folder); a relative name given by a --set override relative
 * to the working directory. Into buf (size bytes); PX_STATUS_INVALID if it
 * does not fit or the key is not an input file. */
PX_API enum px_status px_case_input_path(const struct px_case *c, const char *path, char *buf,
                                         size_t size);

/* Getters. A path outside the schema, or a getter of the wrong type, is
 * PX_STATUS_INVALID; an optional key without default that the case does not
 * give is PX_STATUS_NOT_FOUND (test with px_case_has); the message names the
 * path in both cases. Conversions: get_real works on INT values too;
 * get_string on STRING, ENUM and variant `type` values; get_enum on ENUM and
 * variant `type` values (index into the choices / types). */
PX_API int px_case_has(const struct px_case *c, const char *path);
PX_API enum px_status px_case_get_real(const struct px_case *c, const char *path, double *out);
PX_API enum px_status px_case_get_int(const struct px_case *c, const char *path, long *out);
PX_API enum px_status px_case_get_bool(const struct px_case *c, const char *path, int *out);
/* *out is owned by c. */
PX_API enum px_status px_case_get_string(const struct px_case *c, const char *path,
                                         const char **out);
PX_API enum px_status px_case_get_enum(const struct px_case *c, const char *path, int *out);
/* Number of items of a LIST or components of a VECTOR (0 for an absent
 * optional list). */
PX_API enum px_status px_case_count(const struct px_case *c, const char *path, size_t *out);
/* Copy a VECTOR of exactly n components into out[0..n-1]. */
PX_API enum px_status px_case_get_vector(const struct px_case *c, const char *path, double *out,
                                         size_t n);

/* Report a semantic error found by a solver at the node of `path` (or, for a
 * key the case does not give, at its nearest given parent) as
 * "FILE:LINE:COL: path: message", or "--set ...: path: message" when the value
 * came from an override. Successive calls on the same case accumulate (one
 * line each, up to PX_CASE_MAX_ERRORS) so a solver can report every problem
 * before giving up. Returns PX_STATUS_CONFIG. */
PX_API enum px_status px_case_fail(struct px_case *c, const char *path, const char *fmt, ...)
    PX_PRINTF(3, 4);

/* Print every key this build understands (type, default, range, meaning), or
 * only those of one top-level section ("backend", "vortex", ...).
 * Returns PX_STATUS_NOT_FOUND if there is no such section. */
PX_API enum px_status px_case_print_keys(FILE *out, const char *section);
/* The meaning and unit of a case key ("frequency [Hz]") as `partix keys`
 * prints it, e.g. for "granular.bodies[0].motion.frequency"; NULL when this
 * build has no such key. Static storage. */
PX_API const char *px_case_key_doc(const char *path);

#ifdef __cplusplus
}
#endif
#endif
