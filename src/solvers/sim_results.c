/* A run's results in memory (partix/results.h): results objects, the series
 * tables filled from the rows the solvers write to their CSV files, and the
 * run's callback. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "partix/csv.h"
#include "partix/memory.h"
#include "solvers/sim_impl.h"

/* A results object is plain malloc memory, not the context's: a program
 * (the Python module) may keep it after the run and its context are gone. */
struct px_results {
  long step;
  double time;
  size_t n, cap;
  struct px_view *views; /* names, units and data owned */
};

/* One series: the rows written so far, row-major, as computed. */
struct px_sim_table {
  char name[64]; /* file name without ".csv" */
  size_t ncols;
  char (*col)[96];   /* column names (the header's, without units) */
  char (*unit)[32];  /* their units */
  double *rows;      /* nrows * ncols */
  size_t nrows, cap; /* rows held, room for */
};

size_t px_view_type_size(enum px_view_type type) {
  switch (type) {
    case PX_VIEW_F64:
    case PX_VIEW_I64: return 8;
    case PX_VIEW_F32:
    case PX_VIEW_I32: return 4;
    case PX_VIEW_U8: return 1;
  }
  return 0;
}

const char *px_view_type_name(enum px_view_type type) {
  switch (type) {
    case PX_VIEW_F64: return "f64";
    case PX_VIEW_F32: return "f32";
    case PX_VIEW_I64: return "i64";
    case PX_VIEW_I32: return "i32";
    case PX_VIEW_U8: return "u8";
  }
  return "?";
}

static struct px_results *px_results_create(long step, double time) {
  struct px_results *r = calloc(1, sizeof *r);
  if (!r) return NULL;
  r->step = step;
  r->time = time;
  return r;
}

static char *px_results_strdup(const char *s) {
  size_t n = strlen(s ? s : "") + 1;
  char *d = malloc(n);
  if (d) memcpy(d, s ? s : "", n);
  return d;
}

void *px_results_add(struct px_results *r, const char *name, const char *units,
                     enum px_view_type type, size_t length, size_t components, const void *data) {
  struct px_view *v;
  size_t bytes = px_view_type_size(type) * components * length;
  void *mem;
  if (!r || !components) return NULL;
  if (r->n == r->cap) {
    size_t cap = r->cap ? 2 * r->cap : 16;
    struct px_view *nv = realloc(r->views, cap * sizeof *nv);
    if (!nv) return NULL;
    r->views = nv;
    r->cap = cap;
  }
  mem = bytes ? malloc(bytes) : calloc(1, 1);
  if (!mem) return NULL;
  if (data && bytes)
    memcpy(mem, data, bytes);
  else if (bytes)
    memset(mem, 0, bytes);
  v = &r->views[r->n];
  v->name = px_results_strdup(name);
  v->units = px_results_strdup(units);
  if (!v->name || !v->units) {
    free((void *)v->name);
    free((void *)v->units);
    free(mem);
    return NULL;
  }
  v->type = type;
  v->data = mem;
  v->length = length;
  v->components = components;
  v->stride = (ptrdiff_t)(px_view_type_size(type) * components);
  r->n++;
  return mem;
}

size_t px_results_count(const struct px_results *r) { return r ? r->n : 0; }

const struct px_view *px_results_view(const struct px_results *r, size_t i) {
  return r && i < r->n ? &r->views[i] : NULL;
}

const struct px_view *px_results_find(const struct px_results *r, const char *name) {
  size_t i;
  if (!r || !name) return NULL;
  for (i = 0; i < r->n; ++i)
    if (strcmp(r->views[i].name, name) == 0) return &r->views[i];
  return NULL;
}

long px_results_step(const struct px_results *r) { return r ? r->step : 0; }
double px_results_time(const struct px_results *r) { return r ? r->time : 0.0; }

void px_results_free(struct px_results *r) {
  size_t i;
  if (!r) return;
  for (i = 0; i < r->n; ++i) {
    free((void *)r->views[i].name);
    free((void *)r->views[i].units);
    free((void *)r->views[i].data);
  }
  free(r->views);
  free(r);
}

enum px_status px_sim_results(struct px_sim *sim, enum px_results_kind kind,
                              struct px_results **out) {
  struct px_sim_output o;
  struct px_results *r;
  enum px_status s = PX_STATUS_OK;
  if (!sim || !out) return PX_STATUS_INVALID;
  *out = NULL;
  if (!sim->solver->results)
    return px_context_fail(sim->ctx, PX_STATUS_UNSUPPORTED,
                           "the %s solver has no results in memory", sim->solver->name);
  s = px_sim_gather(sim);
  r = px_results_create(sim->step, (double)sim->step * sim->dt);
  if (s == PX_STATUS_OK && !r) s = px_context_fail(sim->ctx, PX_STATUS_NOMEM, "out of memory");
  if (s == PX_STATUS_OK && sim->rank0) {
    px_sim_output_info(sim, &o);
    s = sim->solver->results(sim->state, &o, kind, r);
    if (s == PX_STATUS_UNSUPPORTED)
      px_context_fail(sim->ctx, s, "the %s solver has no %s results", sim->solver->name,
                      kind == PX_RESULTS_SEGMENTS ? "per-segment" : "state");
  }
  s = px_comm_agree(sim->comm, sim->ctx, s, NULL);
  if (s != PX_STATUS_OK) {
    px_results_free(r);
    return s;
  }
  *out = r;
  return PX_STATUS_OK;
}

/* ---- series ------------------------------------------------------------- */

static enum px_status px_sim_table_row(void *user, size_t ncols, const double *values) {
  struct px_sim_table *t = user;
  if (ncols != t->ncols) return PX_STATUS_INTERNAL;
  if (t->nrows == t->cap) {
    size_t cap = t->cap ? 2 * t->cap : 64;
    double *rows = realloc(t->rows, cap * t->ncols * sizeof *rows);
    if (!rows) return PX_STATUS_NOMEM;
    t->rows = rows;
    t->cap = cap;
  }
  memcpy(t->rows + t->nrows * t->ncols, values, t->ncols * sizeof *values);
  t->nrows++;
  return PX_STATUS_OK;
}

/* "Cl [1]" -> "Cl" and "1"; a name without "[...]" has units "". */
static void px_sim_split_column(const char *header, char *name, size_t nsize, char *unit,
                                size_t usize) {
  const char *open = strrchr(header, '[');
  size_t len = open ? (size_t)(open - header) : strlen(header);
  while (len > 0 && header[len - 1] == ' ') --len;
  snprintf(name, nsize, "%.*s", (int)len, header);
  unit[0] = '\0';
  if (open) {
    const char *close = strchr(open, ']');
    size_t ul = close ? (size_t)(close - open - 1) : strlen(open + 1);
    snprintf(unit, usize, "%.*s", (int)ul, open + 1);
  }
}

enum px_status px_sim_series_tap(struct px_sim *sim, const char *name, size_t ncols,
                                 const char *const *names, struct px_csv *csv) {
  struct px_sim_table *t = NULL, **list;
  char base[64];
  const char *dot = strrchr(name, '.');
  size_t i;
  snprintf(base, sizeof base, "%.*s", (int)(dot ? (size_t)(dot - name) : strlen(name)), name);
  for (i = 0; i < sim->ntables; ++i)
    if (strcmp(sim->tables[i]->name, base) == 0) t = sim->tables[i];
  if (t && t->ncols != ncols)
    return px_context_fail(sim->ctx, PX_STATUS_INTERNAL, "series %s reopened with %zu columns",
                           base, ncols);
  if (!t) {
    list = px_mem_realloc(sim->ctx, "sim.tables", sim->tables, (sim->ntables + 1) * sizeof *list);
    if (!list) return PX_STATUS_NOMEM;
    sim->tables = list;
    t = calloc(1, sizeof *t);
    if (t) t->col = calloc(ncols ? ncols : 1, sizeof *t->col);
    if (t) t->unit = calloc(ncols ? ncols : 1, sizeof *t->unit);
    if (!t || !t->col || !t->unit) {
      if (t) free(t->col), free(t->unit);
      free(t);
      return px_context_fail(sim->ctx, PX_STATUS_NOMEM, "out of memory (series %s)", base);
    }
    snprintf(t->name, sizeof t->name, "%s", base);
    t->ncols = ncols;
    for (i = 0; i < ncols; ++i)
      px_sim_split_column(names[i], t->col[i], sizeof t->col[i], t->unit[i], sizeof t->unit[i]);
    sim->tables[sim->ntables++] = t;
  }
  px_csv_set_tap(csv, px_sim_table_row, t);
  return PX_STATUS_OK;
}

void px_sim_tables_free(struct px_sim *sim) {
  size_t i;
  for (i = 0; i < sim->ntables; ++i) {
    free(sim->tables[i]->col);
    free(sim->tables[i]->unit);
    free(sim->tables[i]->rows);
    free(sim->tables[i]);
  }
  px_mem_free(sim->ctx, sim->tables);
  sim->tables = NULL;
  sim->ntables = 0;
}

const char *px_sim_series_name(const struct px_sim *sim, size_t i) {
  return sim && i < sim->ntables ? sim->tables[i]->name : NULL;
}

enum px_status px_sim_series(struct px_sim *sim, const char *name, struct px_results **out) {
  const struct px_sim_table *t = NULL;
  struct px_results *r;
  size_t i, c;
  if (!sim || !name || !out) return PX_STATUS_INVALID;
  *out = NULL;
  for (i = 0; i < sim->ntables; ++i)
    if (strcmp(sim->tables[i]->name, name) == 0) t = sim->tables[i];
  if (!t && sim->rank0) {
    char have[512] = "";
    size_t len = 0;
    for (i = 0; i < sim->ntables && len < sizeof have; ++i)
      len += (size_t)snprintf(have + len, sizeof have - len, "%s%s", i ? ", " : "",
                              sim->tables[i]->name);
    return px_context_fail(
        sim->ctx, PX_STATUS_NOT_FOUND, "the run has written no series '%s' (%s%s)", name,
        sim->ntables ? "it has " : "none yet: output.csv off, or no row due", have);
  }
  r = px_results_create(sim->step, (double)sim->step * sim->dt);
  if (!r) return px_context_fail(sim->ctx, PX_STATUS_NOMEM, "out of memory");
  for (c = 0; t && c < t->ncols; ++c) {
    double *col = px_results_add(r, t->col[c], t->unit[c], PX_VIEW_F64, t->nrows, 1, NULL);
    if (!col) {
      px_results_free(r);
      return px_context_fail(sim->ctx, PX_STATUS_NOMEM, "out of memory (series %s)", name);
    }
    for (i = 0; i < t->nrows; ++i) col[i] = t->rows[i * t->ncols + c];
  }
  *out = r;
  return PX_STATUS_OK;
}

/* ---- callback ----------------------------------------------------------- */

void px_sim_set_callback(struct px_sim *sim, px_sim_callback fn, void *user) {
  if (!sim) return;
  sim->callback = fn;
  sim->callback_user = user;
}

void px_sim_notify(struct px_sim *sim, enum px_sim_event event) {
  if (sim->callback) sim->callback(sim, event, sim->callback_user);
}
