/* A run's summary (internal): the quantities a user reports, as the driver
 * writes them to RUN_DIR/summary.json and `partix summary` prints them.
 *
 * The driver fills in the run (solver, version, case hash, steps, wall time,
 * backend, automatic settings); a solver's summary hook adds its quantities
 * with the px_summary_* calls below. Each quantity has a name (snake_case;
 * dots group them, e.g. "part.impacts"), a value, a unit ("-" for
 * dimensionless numbers and counts, "" where none applies, e.g. a name) and
 * one line saying what it is. In summary.json a quantity reads
 *   "cx_mean": {"value": 1.33, "unit": "-", "about": "time-averaged drag ..."}
 * under "quantities", in the order added. A non-finite real is written as
 * null. Allocation failures are remembered and reported by the driver, so
 * hooks need not check every call. */
#ifndef PX_SOLVERS_SUMMARY_H
#define PX_SOLVERS_SUMMARY_H

#include <stddef.h>
#include <stdio.h>

#include "partix/context.h"
#include "partix/status.h"

struct px_summary;

enum px_status px_summary_create(struct px_context *ctx, struct px_summary **out);
/* NULL-safe. */
void px_summary_free(struct px_summary *s);
/* Forget every quantity (keeps the allocations). */
void px_summary_clear(struct px_summary *s);

/* Add a quantity (strings are copied). A name added twice keeps the last. */
void px_summary_real(struct px_summary *s, const char *name, double value, const char *unit,
                     const char *about);
void px_summary_int(struct px_summary *s, const char *name, long value, const char *unit,
                    const char *about);
void px_summary_bool(struct px_summary *s, const char *name, int value, const char *about);
void px_summary_text(struct px_summary *s, const char *name, const char *value, const char *about);
/* n components (e.g. a position [x, y, z]). */
void px_summary_vector(struct px_summary *s, const char *name, size_t n, const double *v,
                       const char *unit, const char *about);

/* PX_STATUS_OK, or PX_STATUS_NOMEM if an addition failed. */
enum px_status px_summary_status(const struct px_summary *s);
/* The quantities as the body of a JSON object ("name": {...}, ...), each
 * line indented by `indent` spaces, into a px_mem buffer owned by the caller
 * (*text, *len). */
enum px_status px_summary_json(const struct px_summary *s, int indent, char **text, size_t *len);

/* JSON literals written to f: a string (escaped), a real (shortest form
 * that reads back exactly; null if not finite). */
void px_summary_fput_string(FILE *f, const char *s);
void px_summary_fput_real(FILE *f, double x);

#endif
