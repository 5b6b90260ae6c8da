/* Case-file schemas: static, const tables that describe every key a case file
 * may hold (type, unit and meaning, default, range, choices), and the internal
 * loader entry points that take a schema.
 *
 * Writing a schema
 * ----------------
 * A map's keys are an array of struct px_schema terminated by PX_KEY_END,
 * written with the PX_KEY_* constructors and modifiers below:
 *
 *   static const char *const px_precisions[] = {"single", "double", "mixed", NULL};
 *   static const struct px_schema px_time_keys[] = {
 *     PX_KEY_REAL("dt", "time step [s]", PX_GT(0)),
 *     PX_KEY_INT("steps", "number of time steps", PX_GE(1)),
 *     PX_KEY_ENUM("precision", px_precisions, "floating-point precision",
 *                 PX_DEFAULT("mixed")),
 *     PX_KEY_END};
 *
 * Every constructor takes the key name, its type-specific table (if any), the
 * one-line doc string for users ("meaning [unit]"), then any modifiers:
 * PX_REQUIRED, PX_DEFAULT("yaml text"), PX_GT/PX_GE/PX_LT/PX_LE(x), PX_IN(a, b),
 * PX_LEN(min, max), PX_VALIDATE(fn), PX_WHAT("noun"), PX_INPUT_FILE, PX_FILE_NAME.
 *
 * Types
 *  BOOL    true/false/yes/no/on/off
 *  INT     integers only ("1e3" is rejected), stored as long
 *  REAL    integers or reals, never nan/inf, stored as double
 *  STRING  any scalar (no NUL characters); with PX_INPUT_FILE, the name of
 *          an input file, relative to the case file (px_case_input_path);
 *          with PX_FILE_NAME, a name that becomes part of output file names:
 *          1 to 64 of [A-Za-z0-9._-], not "." or ".."
 *  ENUM    one of `choices` (NULL-terminated), stored as the index
 *  MAP     a map whose keys are `keys`
 *  LIST    a sequence of `item` (one schema, usually a MAP or a VARIANT);
 *          length in [len_min, len_max] (len_max 0 = unbounded)
 *  VECTOR  a sequence of reals like [1.0, 0.0]; the range applies to each
 *          component; length in [len_min, len_max]
 *  VARIANT a map whose `type:` key picks one of `keys` (an array of MAP
 *          schemas written with PX_TYPE, the name being the type value); `type`
 *          is implicit (required unless PX_DEFAULT gives a type name)
 *
 * Absent keys: a default is parsed from its YAML text and validated like user
 * input; an absent MAP without default is filled in as an empty map (so its
 * own defaults appear and its required keys are reported); other absent keys
 * stay absent (px_case_has() is 0).
 *
 * Cross-key checks: `check` on a MAP (or a VARIANT type) runs after the whole
 * case validated, once per map whose subtree had no error, with the map's key
 * path ("time", "vortex.bodies[1]", "" for the root). It reads values with the
 * px_case_get_* getters and reports with px_case_fail(); all failures are
 * collected and reported together.
 *
 * Solver sections
 * ---------------
 * The root schema of `partix` is built at run time from the platform keys
 * (solver, title, backend, time, output) and the solver sections in
 * px_case_solver_sections (a PX_KEY_END-terminated array of PX_KEY_MAP
 * entries whose names are the solver names). `solver:` is an ENUM whose
 * choices are those names; only the chosen solver's section is validated,
 * filled with defaults and kept; a section of another solver is an error.
 *
 * The default, empty, table lives in src/config/solver_sections.c. To plug
 * in the solvers, define px_case_solver_sections in src/solvers/registry.c
 * and delete src/config/solver_sections.c (the linker reports a duplicate
 * definition if both exist); nothing else in src/config changes. */
#ifndef PX_CONFIG_SCHEMA_H
#define PX_CONFIG_SCHEMA_H

#include <stddef.h>
#include <stdio.h>

#include "partix/case.h"
#include "partix/context.h"
#include "partix/status.h"

enum px_schema_type {
  PX_SCHEMA_TYPE_BOOL,
  PX_SCHEMA_TYPE_INT,
  PX_SCHEMA_TYPE_REAL,
  PX_SCHEMA_TYPE_STRING,
  PX_SCHEMA_TYPE_ENUM,
  PX_SCHEMA_TYPE_MAP,
  PX_SCHEMA_TYPE_LIST,
  PX_SCHEMA_TYPE_VECTOR,
  PX_SCHEMA_TYPE_VARIANT
};

/* Kind of a numeric bound. */
enum px_schema_bound {
  PX_SCHEMA_BOUND_NONE = 0,
  PX_SCHEMA_BOUND_INCL, /* >= / <= */
  PX_SCHEMA_BOUND_EXCL  /* >  / <  */
};

/* Cross-key check of a map (see above). Returns PX_STATUS_OK, or the status of
 * px_case_fail() (PX_STATUS_CONFIG) after reporting; any other status aborts
 * the load. */
typedef enum px_status (*px_schema_check_fn)(struct px_case *c, const char *path);

struct px_schema {
  const char *name; /* key name; NULL ends a key array */
  enum px_schema_type type;
  const char *doc;                         /* one line for users: meaning [unit] */
  int required;                            /* 1: the key must be given */
  enum px_schema_bound lo_bound, hi_bound; /* INT, REAL, VECTOR components */
  double lo, hi;
  const char *def;              /* default as YAML text, NULL = none */
  const char *const *choices;   /* ENUM: NULL-terminated */
  const struct px_schema *keys; /* MAP: keys; VARIANT: PX_TYPE array */
  const struct px_schema *item; /* LIST: the item schema */
  size_t len_min, len_max;      /* LIST/VECTOR length, len_max 0 = any */
  px_schema_check_fn check;     /* MAP / variant type: cross-key check */
  const char *what;             /* noun in messages ("solver", "body");
                                   NULL = "value" (ENUM) or the name */
  int file;                     /* STRING: names an input file (geometry,
                                   profile) relative to the case file */
  int file_name;                /* STRING: becomes part of output file
                                   names ([A-Za-z0-9._-]{1,64}) */
  int section;                  /* set by px_case_root_schema_build: a
                                   solver section, kept only when
                                   `solver:` names it */
};

/* Constructors. The variadic part is the doc string followed by modifiers. */
#define PX_KEY_BOOL(name_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_BOOL, .doc = __VA_ARGS__ }
#define PX_KEY_INT(name_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_INT, .doc = __VA_ARGS__ }
#define PX_KEY_REAL(name_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_REAL, .doc = __VA_ARGS__ }
#define PX_KEY_STRING(name_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_STRING, .doc = __VA_ARGS__ }
#define PX_KEY_ENUM(name_, choices_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_ENUM, .choices = (choices_), .doc = __VA_ARGS__ }
#define PX_KEY_MAP(name_, keys_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_MAP, .keys = (keys_), .doc = __VA_ARGS__ }
#define PX_KEY_LIST(name_, item_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_LIST, .item = (item_), .doc = __VA_ARGS__ }
#define PX_KEY_VECTOR(name_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_VECTOR, .doc = __VA_ARGS__ }
#define PX_KEY_VARIANT(name_, types_, ...) \
  { .name = (name_), .type = PX_SCHEMA_TYPE_VARIANT, .keys = (types_), .doc = __VA_ARGS__ }
/* One `type:` value of a VARIANT: its name is the value, keys its key set. */
#define PX_TYPE(name_, keys_, ...) PX_KEY_MAP(name_, keys_, __VA_ARGS__)
#define PX_KEY_END \
  { .name = NULL }

/* Modifiers. */
#define PX_REQUIRED .required = 1
#define PX_DEFAULT(yaml_) .def = (yaml_)
#define PX_GT(x) .lo_bound = PX_SCHEMA_BOUND_EXCL, .lo = (x)
#define PX_GE(x) .lo_bound = PX_SCHEMA_BOUND_INCL, .lo = (x)
#define PX_LT(x) .hi_bound = PX_SCHEMA_BOUND_EXCL, .hi = (x)
#define PX_LE(x) .hi_bound = PX_SCHEMA_BOUND_INCL, .hi = (x)
#define PX_IN(a, b) PX_GE(a), PX_LE(b)
#define PX_LEN(min_, max_) .len_min = (min_), .len_max = (max_)
#define PX_VALIDATE(fn_) .check = (fn_)
#define PX_WHAT(noun_) .what = (noun_)
#define PX_INPUT_FILE .file = 1
#define PX_FILE_NAME .file_name = 1

/* The key `solver:` at the root: its value selects the solver section. */
#define PX_CASE_SOLVER_KEY "solver"
/* Most solver sections a root schema can hold. */
#define PX_CASE_MAX_SECTIONS 16

/* Storage of a built root schema (platform keys + sections + solver choices). */
struct px_case_root_storage {
  struct px_schema keys[8 + PX_CASE_MAX_SECTIONS];
  const char *choices[PX_CASE_MAX_SECTIONS + 1];
  struct px_schema root;
};

/* Build the root schema from the platform keys and `sections` (a PX_KEY_END
 * terminated array of PX_KEY_MAP entries) into `st`. Returns &st->root, or
 * NULL if there are more than PX_CASE_MAX_SECTIONS sections. */
const struct px_schema *px_case_root_schema_build(const struct px_schema *sections,
                                                  struct px_case_root_storage *st);

/* Load and validate a case file against `root` (a MAP schema). overrides are
 * "key.path=value" strings applied before validation. On failure *out is
 * NULL, the status is PX_STATUS_CONFIG (or IO / NOMEM) and the context holds
 * every error found, one per line, as "FILE:LINE:COL: key.path: message". */
enum px_status px_case_load_schema(struct px_context *ctx, const struct px_schema *root,
                                   const char *path, const char *const *overrides,
                                   size_t noverrides, struct px_case **out);
/* The same from text in memory; `name` stands for the file in messages. */
enum px_status px_case_load_string_schema(struct px_context *ctx, const struct px_schema *root,
                                          const char *name, const char *text, size_t len,
                                          const char *const *overrides, size_t noverrides,
                                          struct px_case **out);

/* Print every key of `root` with type, default,
 * range and doc; `section` (NULL = all) restricts it to one top-level key.
 * Returns PX_STATUS_NOT_FOUND if there is no such top-level key. */
enum px_status px_case_print_schema(const struct px_schema *root, const char *section, FILE *out);
/* The doc string ("meaning [unit]") of the key at path, e.g.
 * "granular.bodies[0].motion.frequency" (list indices in any form, a
 * variant's keys of any type); NULL when no key has that path. */
const char *px_schema_key_doc(const struct px_schema *root, const char *path);

/* Check that a schema is well formed: key names are [A-Za-z0-9_-]+ and unique
 * per map, no key is both required and defaulted, every default parses and
 * satisfies its own type and range, ranges are ordered, enums have choices,
 * lists have an item, variants have types. Returns PX_STATUS_INTERNAL with the
 * first problem in ctx. Used by tests for every schema in the tree. */
enum px_status px_case_schema_check(struct px_context *ctx, const struct px_schema *root);

/* Join a map path and a key for getters in checks: "time" + "dt" -> "time.dt",
 * "" + "solver" -> "solver". Returns buf (truncated if it does not fit). */
const char *px_case_path_join(char *buf, size_t size, const char *path, const char *key);

/* ---- Run records (used by the run driver) ------------------------------ */

/* The value at `path` in the flow syntax of the resolved text ("0.005",
 * "[1, 0]", "{type: box, ...}") into a px_mem buffer owned by the caller;
 * *text = NULL (and PX_STATUS_OK) when the case does not hold the key. */
enum px_status px_case_value_text(const struct px_case *c, const char *path, char **text);

/* Called for each input file of a case (every PX_INPUT_FILE value): `key` is
 * its key path, `source` the file it names (px_case_input_path). Writes the
 * value the case should record instead into newvalue (NUL-terminated, at most
 * size bytes), or leaves newvalue empty to keep the value. */
typedef enum px_status (*px_case_input_fn)(void *user, const char *key, const char *source,
                                           char *newvalue, size_t size);
/* Visit every input file of c in key order; the values written by fn, names
 * relative to the folder `base`, replace the old ones (px_case_input_path
 * resolves them against `base` from then on), and the resolved text and hash
 * are made again. */
enum px_status px_case_relocate_inputs(struct px_case *c, const char *base, px_case_input_fn fn,
                                       void *user);

/* Optimal-string-alignment (restricted Damerau-Levenshtein) distance of a and
 * b, ASCII case-insensitive; strings longer than 64 bytes count as far apart. */
size_t px_case_edit_distance(const char *a, size_t alen, const char *b, size_t blen);

#endif
