/* Private layout of struct px_case and the node tree shared by the files of
 * src/config (never installed). */
#ifndef PX_CONFIG_CASE_IMPL_H
#define PX_CONFIG_CASE_IMPL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include "config/schema.h"
#include "partix/case.h"

/* Limits against hostile input: nesting depth of the YAML text, values in one
 * case (aliases expanded), anchors in one file. */
#define PX_CASE_MAX_DEPTH 64
#define PX_CASE_MAX_NODES 1000000
#define PX_CASE_MAX_ANCHORS 10000
/* Longest key path shown in messages [bytes]. */
#define PX_CASE_PATH_MAX 512

/* Where a node came from. */
enum px_case_origin {
  PX_CASE_ORIGIN_FILE = -1,   /* the case file (line, col valid) */
  PX_CASE_ORIGIN_BUILTIN = -2 /* a schema default (no position) */
  /* >= 0: index of the --set override */
};

struct px_case_loc {
  int origin; /* enum px_case_origin, or the override index */
  int line;   /* 1-based; 0 when unknown */
  int col;    /* 1-based; 0 when unknown */
};

enum px_case_node_kind {
  PX_CASE_NODE_NULL, /* plain empty, ~, null */
  PX_CASE_NODE_SCALAR,
  PX_CASE_NODE_MAP, /* items are the values, each with its key */
  PX_CASE_NODE_SEQ
};

struct px_case_node {
  enum px_case_node_kind kind;
  struct px_case_loc loc;     /* of the value */
  struct px_case_loc key_loc; /* of its key (map members); = loc otherwise */
  const char *key;            /* arena; map members only */
  size_t key_len;
  const char *text;            /* arena, NUL-terminated; scalars only */
  size_t len;                  /* of text (may hold NULs: rejected as strings) */
  int quoted;                  /* 1: quoted/block/!!str scalar (never null) */
  const char *file_base;       /* arena: input files whose value was rewritten
                                  by px_case_relocate_inputs: the folder the
                                  value is relative to (NULL: see
                                  px_case_input_path) */
  struct px_case_node **items; /* arena; map members or sequence items */
  size_t n, cap;

  /* Filled by validation. */
  const struct px_schema *schema;  /* the node's schema, NULL = unvalidated */
  int is_type;                     /* the implicit `type` key of a VARIANT (schema = variant) */
  int is_element;                  /* a VECTOR component (schema = vector) */
  int defaulted;                   /* value filled from the schema, not given by the user */
  int ok;                          /* MAP: its subtree validated without error */
  const struct px_schema *variant; /* VARIANT map: the chosen type schema */
  union {
    double real;
    long integer;
    int boolean;
    int index; /* ENUM choice / variant type index */
  } v;
};

/* A chunked bump allocator; everything of a case lives in it. */
struct px_case_arena_chunk;
struct px_case_arena {
  struct px_context *ctx;             /* borrowed */
  struct px_case_arena_chunk *chunks; /* owned */
  size_t nodes;                       /* nodes allocated so far */
};

void *px_case_arena_alloc(struct px_case_arena *a, size_t bytes);
char *px_case_arena_strdup(struct px_case_arena *a, const char *s, size_t len);
void px_case_arena_free(struct px_case_arena *a);
/* A zeroed node, or NULL when out of memory or past PX_CASE_MAX_NODES (then
 * *too_many is set). */
struct px_case_node *px_case_node_new(struct px_case_arena *a, enum px_case_node_kind kind);
/* Append a child; 0 on success, -1 out of memory. */
int px_case_node_append(struct px_case_arena *a, struct px_case_node *parent,
                        struct px_case_node *child);
/* Deep copy (aliases); NULL when out of memory or budget, or (*too_deep set)
 * when the copy would be more than max_depth levels deep. */
struct px_case_node *px_case_node_copy(struct px_case_arena *a, const struct px_case_node *n,
                                       size_t max_depth, int *too_deep);
/* The first member of a map named `key`, or NULL. */
struct px_case_node *px_case_node_member(const struct px_case_node *map, const char *key,
                                         size_t len);

/* One reported error. */
struct px_case_error {
  struct px_case_loc loc;
  char *text; /* arena: "path: message" (without location) */
};

/* Collected errors of one load (or of px_case_fail calls after it). */
struct px_case_errors {
  struct px_case_error list[PX_CASE_MAX_ERRORS];
  size_t n;     /* stored */
  size_t total; /* found, including those not stored */
  int nomem;    /* an allocation failed while loading */
  int fatal;    /* a failure other than CONFIG (e.g. check returned NOMEM) */
};

struct px_case {
  struct px_context *ctx;         /* borrowed */
  const struct px_schema *schema; /* borrowed (static) */
  char *file;                     /* arena: the name used in messages */
  char **overrides;               /* arena: copies of the --set strings */
  size_t noverrides;
  struct px_case_arena arena; /* owns every node and string below */
  struct px_case_node *root;  /* the resolved tree (schema order) */
  char *resolved;             /* px_mem: the resolved YAML text */
  size_t resolved_len;
  uint64_t hash;
  const char *solver;           /* arena or NULL */
  int loading;                  /* 1 while validation runs (checks) */
  struct px_case_errors errors; /* load errors, then px_case_fail ones */
};

/* Parse YAML text into a tree in c's arena. Syntax errors are added to c's
 * errors with `origin` (file or override index). *out may be NULL (empty
 * document). Returns 0 on success, -1 on a syntax/limit error (reported),
 * -2 when out of memory. */
int px_case_yaml_parse(struct px_case *c, const char *text, size_t len, int origin,
                       struct px_case_node **out);

/* Record an error at `loc` for `path` (may be empty). */
void px_case_error_add(struct px_case *c, const struct px_case_loc *loc, const char *path,
                       const char *fmt, ...) PX_PRINTF(4, 5);
void px_case_error_vadd(struct px_case *c, const struct px_case_loc *loc, const char *path,
                        const char *fmt, va_list ap);
/* Format an error list as the context message (one per line) and return
 * PX_STATUS_CONFIG. */
enum px_status px_case_errors_commit(struct px_case *c);

/* Describe a scalar for messages: 'text' truncated and escaped, into buf. */
const char *px_case_quote(char *buf, size_t size, const char *text, size_t len);

/* Key path parsing shared by overrides and getters: "a.b[2].c". */
struct px_case_seg {
  const char *name; /* key, or NULL for an index */
  size_t len;
  size_t index;
};
/* Returns the number of segments, or 0 if `path` is malformed (or has more
 * than `max` segments). An empty path has no segments and is malformed. */
size_t px_case_path_parse(const char *path, size_t plen, struct px_case_seg *segs, size_t max);

/* Validation of a parsed tree against c->schema (case_validate.c): fills in
 * defaults, builds the resolved tree in c->root and runs the checks. Errors go
 * to c->errors. Returns PX_STATUS_OK (errors may have been reported) or a
 * fatal status (NOMEM, INTERNAL). */
enum px_status px_case_validate(struct px_case *c, struct px_case_node *raw);
/* Validate one default text against its key schema (schema self-check). */
enum px_status px_case_validate_default(struct px_case *c, const struct px_schema *key,
                                        const char *path);

/* Resolved text (case_emit.c). */
enum px_status px_case_emit(struct px_case *c);
/* A value's flow text ("[1, 0]") into a px_mem buffer owned by the caller. */
enum px_status px_case_emit_flow(struct px_context *ctx, const struct px_case_node *n, char **text);
/* FNV-1a hash of the resolved text into c->hash (case_load.c). */
void px_case_rehash(struct px_case *c);
/* The node at `path`, or NULL if the case does not hold it (case_get.c). */
struct px_case_node *px_case_lookup(const struct px_case *c, const char *path);

#endif
