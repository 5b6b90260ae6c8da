/* Small user functions of one variable for the granular reports (work
 * hardening and residual stress as functions of the specific impact energy
 * E): an arithmetic expression ("120 * (1 - exp(-E / 4000))") or a table of
 * (E, value) points interpolated linearly (clamped at the ends). */
#ifndef PX_GRAN_EXPR_H
#define PX_GRAN_EXPR_H

#include <stddef.h>

#include "partix/context.h"

#define PX_GRAN_EXPR_MAX 128 /* instructions of a compiled expression */

/* A compiled expression (stack machine) or a table. */
struct px_gran_fn {
  int kind; /* 0 none, 1 expression, 2 table */
  int ncode;
  int op[PX_GRAN_EXPR_MAX];     /* opcodes */
  double arg[PX_GRAN_EXPR_MAX]; /* constants */
  size_t n;                     /* table rows */
  double *tx, *ty;              /* table (owned, ascending tx) */
};

/* Compile `text`, whose only variable is `var` ("E"). Operators + - * / ^
 * (right-associative), unary minus, parentheses, numbers (1e3), functions
 * exp log sqrt abs tanh min(a,b) max(a,b) pow(a,b). On error the message
 * says what is wrong at which character. */
enum px_status px_gran_fn_compile(struct px_context *ctx, struct px_gran_fn *f, const char *text,
                                  const char *var);
/* A table from n (x, y) pairs (copied; x strictly ascending). */
enum px_status px_gran_fn_table(struct px_context *ctx, struct px_gran_fn *f, const double *x,
                                const double *y, size_t n);
double px_gran_fn_eval(const struct px_gran_fn *f, double x);
void px_gran_fn_free(struct px_context *ctx, struct px_gran_fn *f);

#endif
