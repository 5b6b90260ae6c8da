/* User functions of one variable: expressions (recursive descent to a stack
 * program) and tables. */
#include "solvers/granular/expr.h"

#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "partix/memory.h"

enum {
  PX_GRAN_OP_CONST,
  PX_GRAN_OP_VAR,
  PX_GRAN_OP_ADD,
  PX_GRAN_OP_SUB,
  PX_GRAN_OP_MUL,
  PX_GRAN_OP_DIV,
  PX_GRAN_OP_POW,
  PX_GRAN_OP_NEG,
  PX_GRAN_OP_EXP,
  PX_GRAN_OP_LOG,
  PX_GRAN_OP_SQRT,
  PX_GRAN_OP_ABS,
  PX_GRAN_OP_TANH,
  PX_GRAN_OP_MIN,
  PX_GRAN_OP_MAX
};

struct px_gran_parser {
  struct px_context *ctx;
  const char *text, *p, *var;
  struct px_gran_fn *f;
  int depth;
};

static enum px_status px_gran_perr(struct px_gran_parser *P, const char *what) {
  return px_context_fail(P->ctx, PX_STATUS_CONFIG, "expression \"%s\": %s at character %d", P->text,
                         what, (int)(P->p - P->text) + 1);
}

static enum px_status px_gran_emit(struct px_gran_parser *P, int op, double arg) {
  if (P->f->ncode >= PX_GRAN_EXPR_MAX) return px_gran_perr(P, "expression too long");
  P->f->op[P->f->ncode] = op;
  P->f->arg[P->f->ncode] = arg;
  ++P->f->ncode;
  return PX_STATUS_OK;
}

static void px_gran_skip(struct px_gran_parser *P) {
  while (*P->p && isspace((unsigned char)*P->p)) ++P->p;
}

static enum px_status px_gran_sum(struct px_gran_parser *P);

static enum px_status px_gran_primary(struct px_gran_parser *P) {
  px_gran_skip(P);
  if (++P->depth > 64) return px_gran_perr(P, "nested too deeply");
  if (*P->p == '(') {
    ++P->p;
    PX_TRY(px_gran_sum(P));
    px_gran_skip(P);
    if (*P->p != ')') return px_gran_perr(P, "expected ')'");
    ++P->p;
  } else if (*P->p == '-') {
    ++P->p;
    PX_TRY(px_gran_primary(P));
    PX_TRY(px_gran_emit(P, PX_GRAN_OP_NEG, 0));
  } else if (*P->p == '+') {
    ++P->p;
    PX_TRY(px_gran_primary(P));
  } else if (isdigit((unsigned char)*P->p) || *P->p == '.') {
    char *end;
    double v = strtod(P->p, &end);
    if (end == P->p) return px_gran_perr(P, "bad number");
    P->p = end;
    PX_TRY(px_gran_emit(P, PX_GRAN_OP_CONST, v));
  } else if (isalpha((unsigned char)*P->p) || *P->p == '_') {
    char name[16];
    size_t n = 0;
    while ((isalnum((unsigned char)*P->p) || *P->p == '_') && n < sizeof name - 1)
      name[n++] = *P->p++;
    name[n] = '\0';
    px_gran_skip(P);
    if (strcmp(name, P->var) == 0) {
      PX_TRY(px_gran_emit(P, PX_GRAN_OP_VAR, 0));
    } else if (strcmp(name, "pi") == 0) {
      PX_TRY(px_gran_emit(P, PX_GRAN_OP_CONST, 3.14159265358979323846));
    } else {
      static const char *const f1[] = {"exp", "log", "sqrt", "abs", "tanh"};
      static const int o1[] = {PX_GRAN_OP_EXP, PX_GRAN_OP_LOG, PX_GRAN_OP_SQRT, PX_GRAN_OP_ABS,
                               PX_GRAN_OP_TANH};
      static const char *const f2[] = {"min", "max", "pow"};
      static const int o2[] = {PX_GRAN_OP_MIN, PX_GRAN_OP_MAX, PX_GRAN_OP_POW};
      int k, nargs = 0, op = -1;
      for (k = 0; k < 5; ++k)
        if (strcmp(name, f1[k]) == 0) nargs = 1, op = o1[k];
      for (k = 0; k < 3; ++k)
        if (strcmp(name, f2[k]) == 0) nargs = 2, op = o2[k];
      if (op < 0) {
        char msg[96];
        snprintf(msg, sizeof msg, "unknown name '%s' (the variable is '%s')", name, P->var);
        return px_gran_perr(P, msg);
      }
      if (*P->p != '(') return px_gran_perr(P, "expected '(' after a function name");
      ++P->p;
      PX_TRY(px_gran_sum(P));
      if (nargs == 2) {
        px_gran_skip(P);
        if (*P->p != ',') return px_gran_perr(P, "expected ',' (this function takes 2 arguments)");
        ++P->p;
        PX_TRY(px_gran_sum(P));
      }
      px_gran_skip(P);
      if (*P->p != ')') return px_gran_perr(P, "expected ')'");
      ++P->p;
      PX_TRY(px_gran_emit(P, op, 0));
    }
  } else {
    return px_gran_perr(P, *P->p ? "unexpected character" : "unexpected end");
  }
  --P->depth;
  return PX_STATUS_OK;
}

static enum px_status px_gran_power(struct px_gran_parser *P) {
  PX_TRY(px_gran_primary(P));
  px_gran_skip(P);
  if (*P->p == '^') {
    ++P->p;
    PX_TRY(px_gran_power(P)); /* right-associative */
    PX_TRY(px_gran_emit(P, PX_GRAN_OP_POW, 0));
  }
  return PX_STATUS_OK;
}

static enum px_status px_gran_product(struct px_gran_parser *P) {
  PX_TRY(px_gran_power(P));
  for (;;) {
    char c;
    px_gran_skip(P);
    c = *P->p;
    if (c != '*' && c != '/') return PX_STATUS_OK;
    ++P->p;
    PX_TRY(px_gran_power(P));
    PX_TRY(px_gran_emit(P, c == '*' ? PX_GRAN_OP_MUL : PX_GRAN_OP_DIV, 0));
  }
}

static enum px_status px_gran_sum(struct px_gran_parser *P) {
  PX_TRY(px_gran_product(P));
  for (;;) {
    char c;
    px_gran_skip(P);
    c = *P->p;
    if (c != '+' && c != '-') return PX_STATUS_OK;
    ++P->p;
    PX_TRY(px_gran_product(P));
    PX_TRY(px_gran_emit(P, c == '+' ? PX_GRAN_OP_ADD : PX_GRAN_OP_SUB, 0));
  }
}

enum px_status px_gran_fn_compile(struct px_context *ctx, struct px_gran_fn *f, const char *text,
                                  const char *var) {
  struct px_gran_parser P;
  memset(f, 0, sizeof *f);
  P.ctx = ctx;
  P.text = text;
  P.p = text;
  P.var = var;
  P.f = f;
  P.depth = 0;
  PX_TRY(px_gran_sum(&P));
  px_gran_skip(&P);
  if (*P.p) return px_gran_perr(&P, "unexpected text after the expression");
  f->kind = 1;
  return PX_STATUS_OK;
}

enum px_status px_gran_fn_table(struct px_context *ctx, struct px_gran_fn *f, const double *x,
                                const double *y, size_t n) {
  size_t k;
  memset(f, 0, sizeof *f);
  if (n < 1) return px_context_fail(ctx, PX_STATUS_CONFIG, "a table needs at least one row");
  for (k = 1; k < n; ++k)
    if (!(x[k] > x[k - 1]))
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "table rows must have ascending first values (row %zu: %g after %g)",
                             k + 1, x[k], x[k - 1]);
  f->tx = px_mem_alloc(ctx, "granular table", n * sizeof(double));
  f->ty = px_mem_alloc(ctx, "granular table", n * sizeof(double));
  if (!f->tx || !f->ty) return PX_STATUS_NOMEM;
  memcpy(f->tx, x, n * sizeof(double));
  memcpy(f->ty, y, n * sizeof(double));
  f->n = n;
  f->kind = 2;
  return PX_STATUS_OK;
}

double px_gran_fn_eval(const struct px_gran_fn *f, double x) {
  if (f->kind == 1) {
    double st[PX_GRAN_EXPR_MAX];
    int sp = 0, k;
    for (k = 0; k < f->ncode; ++k) {
      const int op = f->op[k];
      double a, b;
      switch (op) {
        case PX_GRAN_OP_CONST: st[sp++] = f->arg[k]; break;
        case PX_GRAN_OP_VAR: st[sp++] = x; break;
        case PX_GRAN_OP_NEG: st[sp - 1] = -st[sp - 1]; break;
        case PX_GRAN_OP_EXP: st[sp - 1] = exp(st[sp - 1]); break;
        case PX_GRAN_OP_LOG: st[sp - 1] = log(st[sp - 1]); break;
        case PX_GRAN_OP_SQRT: st[sp - 1] = sqrt(st[sp - 1]); break;
        case PX_GRAN_OP_ABS: st[sp - 1] = fabs(st[sp - 1]); break;
        case PX_GRAN_OP_TANH: st[sp - 1] = tanh(st[sp - 1]); break;
        default:
          b = st[--sp];
          a = st[sp - 1];
          switch (op) {
            case PX_GRAN_OP_ADD: a = a + b; break;
            case PX_GRAN_OP_SUB: a = a - b; break;
            case PX_GRAN_OP_MUL: a = a * b; break;
            case PX_GRAN_OP_DIV: a = a / b; break;
            case PX_GRAN_OP_POW: a = pow(a, b); break;
            case PX_GRAN_OP_MIN: a = a < b ? a : b; break;
            case PX_GRAN_OP_MAX: a = a > b ? a : b; break;
            default: break;
          }
          st[sp - 1] = a;
      }
    }
    return sp ? st[0] : 0;
  }
  if (f->kind == 2) {
    size_t lo = 0, hi = f->n - 1;
    if (x <= f->tx[0]) return f->ty[0];
    if (x >= f->tx[f->n - 1]) return f->ty[f->n - 1];
    while (hi - lo > 1) {
      const size_t mid = (lo + hi) / 2;
      if (f->tx[mid] <= x)
        lo = mid;
      else
        hi = mid;
    }
    return f->ty[lo] + (x - f->tx[lo]) / (f->tx[hi] - f->tx[lo]) * (f->ty[hi] - f->ty[lo]);
  }
  return 0;
}

void px_gran_fn_free(struct px_context *ctx, struct px_gran_fn *f) {
  if (!f) return;
  px_mem_free(ctx, f->tx);
  px_mem_free(ctx, f->ty);
  f->tx = f->ty = NULL;
  f->kind = 0;
}
