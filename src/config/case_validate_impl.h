/* Case validation, private (case_validate.c: maps, lists, variants and the
 * entry points; case_validate_scalar.c: scalars; case_validate_msg.c: key
 * paths and messages). */
#ifndef PX_CONFIG_CASE_VALIDATE_IMPL_H
#define PX_CONFIG_CASE_VALIDATE_IMPL_H

#include <stddef.h>

#include "config/case_impl.h"

struct px_case_validator {
  struct px_case *c;
  char path[PX_CASE_PATH_MAX]; /* key path of the node being validated */
  size_t plen;
  enum px_status fatal; /* PX_STATUS_OK unless something other than the
                           case itself failed (memory, a check) */
};

/* Best "did you mean" candidate among names. */
struct px_case_suggest {
  const char *word;
  size_t wlen;
  const char *best; /* borrowed */
  size_t dist;
};

/* case_validate_msg.c: key paths and messages */
/* Append `.key` (or the key alone at the top) to the path; returns the old
 * length for px_case_path_pop. */
size_t px_case_path_key(struct px_case_validator *v, const char *key, size_t len);
/* Append `[index]` to the path; returns the old length. */
size_t px_case_path_index(struct px_case_validator *v, size_t index);
void px_case_path_pop(struct px_case_validator *v, size_t old);
/* Record an error at loc for the current path. */
void px_case_verr(struct px_case_validator *v, const struct px_case_loc *loc, const char *fmt, ...)
    PX_PRINTF(3, 4);
int px_case_verbose(const struct px_case_validator *v);
/* A node as a message shows it: "null", "a map", "a list" or the quoted text. */
const char *px_case_describe(char *buf, size_t size, const struct px_case_node *n);
void px_case_suggest_try(struct px_case_suggest *sg, const char *cand);
void px_case_suggest_init(struct px_case_suggest *sg, const char *word, size_t wlen);
const char *px_case_suggest_text(char *buf, size_t size, const struct px_case_suggest *sg);
const char *px_case_list_choices(char *buf, size_t size, const char *const *choices);
/* The key names of `keys` (and `type` when with_type) as a list. */
const char *px_case_list_keys(char *buf, size_t size, const struct px_schema *keys, int with_type);

/* case_validate_scalar.c */
int px_case_need_scalar(struct px_case_validator *v, const struct px_case_node *n,
                        const char *expected);
int px_case_check_range(struct px_case_validator *v, const struct px_case_node *n,
                        const struct px_schema *s, double x);
int px_case_parse_real(struct px_case_validator *v, const struct px_case_node *n, double *x);
struct px_case_node *px_case_val_scalar(struct px_case_validator *v, struct px_case_node *n,
                                        const struct px_schema *s);

/* case_validate.c */
struct px_case_node *px_case_val_node(struct px_case_validator *v, struct px_case_node *n,
                                      const struct px_schema *s);

#endif
