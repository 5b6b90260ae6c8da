/* The table of a sweep: every run's summary.json gathered into sweep.csv
 * and sweep.json, and sweep.png (docs/sweeps.md). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "cli/sweep.h"
#include "partix/partix.h"

/* A CSV field: quoted, with quotes doubled. */
static void px_sweep_csv_field(FILE *f, const char *s) {
  fputc('"', f);
  for (; s && *s; ++s) {
    if (*s == '"') fputc('"', f);
    fputc(*s, f);
  }
  fputc('"', f);
}

/* A JSON string. */
static void px_sweep_json_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; s && *s; ++s) {
    if (*s == '"' || *s == '\\')
      fprintf(f, "\\%c", *s);
    else if ((unsigned char)*s < 0x20)
      fprintf(f, "\\u%04x", (unsigned)(unsigned char)*s);
    else
      fputc(*s, f);
  }
  fputc('"', f);
}

int px_sweep_table_read(struct px_sweep *s, struct px_sweep_table *t) {
  size_t r, j;
  memset(t, 0, sizeof *t);
  t->doc = calloc(s->nruns, sizeof *t->doc);
  t->name = calloc(1024, sizeof *t->name);
  t->unit = calloc(1024, sizeof *t->unit);
  if (!t->doc || !t->name || !t->unit) return -1;
  for (r = 0; r < s->nruns; ++r) {
    char path[4400];
    struct fy_node *q;
    struct fy_node_pair *p;
    void *it = NULL;
    snprintf(path, sizeof path, "%s/%s/summary.json", s->dir, s->runs[r].name);
    /* a run of other settings: its quantities are not this run's */
    if (s->runs[r].foreign || !px_file_exists(path)) continue;
    t->doc[r] = fy_document_build_from_file(NULL, path);
    q = px_cli_json_get(t->doc[r] ? fy_document_root(t->doc[r]) : NULL, "quantities");
    while (q && fy_node_is_mapping(q) && (p = fy_node_mapping_iterate(q, &it)) != NULL) {
      const char *name = px_sweep_scalar(fy_node_pair_key(p));
      struct fy_node *v = fy_node_pair_value(p);
      if (!name) continue;
      for (j = 0; j < t->n && strcmp(t->name[j], name) != 0; ++j) {
      }
      if (j < t->n || t->n == 1024) continue;
      t->name[t->n] = name;
      t->unit[t->n] = px_sweep_scalar(px_cli_json_get(v, "unit"));
      ++t->n;
    }
  }
  return 0;
}

void px_sweep_table_free(struct px_sweep *s, struct px_sweep_table *t) {
  size_t r;
  for (r = 0; t->doc && r < s->nruns; ++r)
    if (t->doc[r]) fy_document_destroy(t->doc[r]);
  free(t->doc);
  free(t->name);
  free(t->unit);
}

/* The wall time a run reports (all its segments), else the sweep's figure. */
static double px_sweep_wall(const struct px_sweep_run *run, struct fy_document *d) {
  const char *w = px_sweep_scalar(px_cli_json_get(d ? fy_document_root(d) : NULL, "wall_time_s"));
  return w ? atof(w) : run->wall;
}

enum px_status px_sweep_write_csv(struct px_context *ctx, struct px_sweep *s,
                                  const struct px_sweep_table *t) {
  char path[4200], cell[1024];
  struct px_file *pf = NULL;
  FILE *f;
  size_t r, k, j;
  snprintf(path, sizeof path, "%s/sweep.csv", s->dir);
  PX_TRY(px_file_open(ctx, path, &pf));
  f = px_file_stream(pf);
  fprintf(f, "run");
  for (k = 0; k < s->nkeys; ++k) fprintf(f, ",%s", s->key[k]);
  fprintf(f, ",status,exit,wall_time [s]");
  for (j = 0; j < t->n; ++j) {
    fputc(',', f);
    snprintf(cell, sizeof cell, "%s%s%s%s", t->name[j], t->unit[j] && t->unit[j][0] ? " [" : "",
             t->unit[j] && t->unit[j][0] ? t->unit[j] : "", t->unit[j] && t->unit[j][0] ? "]" : "");
    px_sweep_csv_field(f, cell);
  }
  fprintf(f, ",error\n");
  for (r = 0; r < s->nruns; ++r) {
    const struct px_sweep_run *run = &s->runs[r];
    fprintf(f, "%s", run->name);
    for (k = 0; k < s->nkeys; ++k) {
      fputc(',', f);
      px_sweep_csv_field(f, run->value[k] ? run->value[k] : "");
    }
    fprintf(f, ",%s,%d,%.6g", run->status, run->exit, px_sweep_wall(run, t->doc[r]));
    for (j = 0; j < t->n; ++j) {
      px_cli_summary_text(px_cli_summary_value(t->doc[r], t->name[j]), cell, sizeof cell, 0, "");
      fputc(',', f);
      if (cell[0] == '[')
        px_sweep_csv_field(f, cell);
      else
        fputs(cell, f);
    }
    fputc(',', f);
    px_sweep_csv_field(f, run->error);
    fputc('\n', f);
  }
  return px_file_commit(pf);
}

enum px_status px_sweep_write_json(struct px_context *ctx, struct px_sweep *s,
                                   const struct px_sweep_table *t) {
  char path[4200], cell[1024];
  struct px_file *pf = NULL;
  FILE *f;
  size_t r, k, j;
  snprintf(path, sizeof path, "%s/sweep.json", s->dir);
  PX_TRY(px_file_open(ctx, path, &pf));
  f = px_file_stream(pf);
  fprintf(f, "{\n  \"sweep\": ");
  px_sweep_json_string(f, s->file);
  fprintf(f, ",\n  \"case\": ");
  px_sweep_json_string(f, s->base);
  fprintf(f, ",\n  \"runs\": [");
  for (r = 0; r < s->nruns; ++r) {
    const struct px_sweep_run *run = &s->runs[r];
    fprintf(f, "%s\n    {\"run\": ", r ? "," : "");
    px_sweep_json_string(f, run->name);
    fprintf(f, ", \"values\": {");
    for (k = 0; k < s->nkeys; ++k) {
      fprintf(f, "%s", k ? ", " : "");
      px_sweep_json_string(f, s->key[k]);
      fprintf(f, ": ");
      px_sweep_json_string(f, run->value[k] ? run->value[k] : "");
    }
    fprintf(f, "}, \"status\": \"%s\", \"exit\": %d, \"wall_time_s\": %.6g", run->status, run->exit,
            px_sweep_wall(run, t->doc[r]));
    if (run->error[0]) {
      fprintf(f, ", \"error\": ");
      px_sweep_json_string(f, run->error);
    }
    fprintf(f, ",\n     \"quantities\": {");
    for (j = 0; j < t->n; ++j) {
      px_cli_summary_text(px_cli_summary_value(t->doc[r], t->name[j]), cell, sizeof cell, 0, "");
      fprintf(f, "%s", j ? ", " : "");
      px_sweep_json_string(f, t->name[j]);
      fprintf(f, ": {\"value\": %s, \"unit\": ", cell[0] ? cell : "null");
      px_sweep_json_string(f, t->unit[j] ? t->unit[j] : "");
      fprintf(f, "}");
    }
    fprintf(f, "}}");
  }
  fprintf(f, "\n  ]\n}\n");
  return px_file_commit(pf);
}

/* 1 when runs r and q have the same values of every varied key but kx. */
static int px_sweep_same_others(const struct px_sweep *s, size_t r, size_t q, size_t kx) {
  size_t k;
  for (k = 0; k < s->nkeys; ++k) {
    const char *a = s->runs[r].value[k], *b = s->runs[q].value[k];
    if (k != kx && (!a != !b || (a && strcmp(a, b) != 0))) return 0;
  }
  return 1;
}

/* " [unit]" of a case key, from the last "[...]" of its doc string
 * ("frequency [Hz]": " [Hz]"), or "" when it has none. */
static const char *px_sweep_key_unit(const char *key, char *buf, size_t size) {
  const char *doc = px_case_key_doc(key), *close = doc ? strrchr(doc, ']') : NULL;
  const char *open = close;
  while (open && open > doc && *open != '[') --open;
  buf[0] = '\0';
  if (open && *open == '[' && close - open > 1)
    snprintf(buf, size, " %.*s", (int)(close - open + 1), open);
  return buf;
}

/* sweep.png: plot.y against plot.x, one series per combination of the
 * other varied keys; runs without a finite value are left out. */
enum px_status px_sweep_plot(struct px_context *ctx, struct px_sweep *s,
                             const struct px_sweep_table *t) {
  struct px_plot *pl = NULL;
  double *x = malloc(s->nruns * sizeof *x), *y = malloc(s->nruns * sizeof *y);
  unsigned char *done = calloc(s->nruns, 1);
  char path[4200], label[512], unit[64] = "", u[64];
  size_t r, q, k, kx = 0, n, nseries = 0;
  enum px_status st = PX_STATUS_OK;
  if (!x || !y || !done) st = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  for (k = 0; k < s->nkeys; ++k)
    if (strcmp(s->key[k], s->plot_x) == 0) kx = k;
  for (k = 0; k < t->n; ++k)
    if (strcmp(t->name[k], s->plot_y) == 0 && t->unit[k])
      snprintf(unit, sizeof unit, "%s", t->unit[k]);
  if (st == PX_STATUS_OK) st = px_plot_create(ctx, 1000, 640, &pl);
  if (st == PX_STATUS_OK) {
    char ylabel[256];
    snprintf(ylabel, sizeof ylabel, "%s%s%s%s", s->plot_y, unit[0] ? " [" : "", unit,
             unit[0] ? "]" : "");
    char xlabel[512];
    snprintf(xlabel, sizeof xlabel, "%s%s", s->plot_x, px_sweep_key_unit(s->plot_x, u, sizeof u));
    /* the sweep file's name, not the path it was given by */
    const char *slash = strrchr(s->file, '/');
    px_plot_set_title(pl, slash ? slash + 1 : s->file);
    px_plot_set_labels(pl, xlabel, ylabel);
    /* a sweep has a few values per key: show where the runs are */
    px_plot_set_markers(pl, 1);
  }
  for (r = 0; r < s->nruns && st == PX_STATUS_OK; ++r) {
    if (done[r]) continue;
    /* the runs sharing run r's values of the other keys */
    n = 0;
    label[0] = '\0';
    for (k = 0; k < s->nkeys; ++k)
      if (k != kx)
        snprintf(label + strlen(label), sizeof label - strlen(label), "%s%s = %s%s",
                 label[0] ? ", " : "", s->key[k], s->runs[r].value[k] ? s->runs[r].value[k] : "-",
                 px_sweep_key_unit(s->key[k], u, sizeof u));
    for (q = r; q < s->nruns; ++q) {
      struct fy_node *v = px_cli_summary_value(t->doc[q], s->plot_y);
      const char *vy, *vx = s->runs[q].value[kx];
      char *end = NULL;
      if (!px_sweep_same_others(s, r, q, kx)) continue;
      done[q] = 1;
      vy = px_sweep_scalar(v);
      if (!vx || !vy) continue;
      x[n] = strtod(vx, &end);
      if (!end || *end) continue;
      y[n] = strtod(vy, &end);
      if (!end || *end || !isfinite(x[n]) || !isfinite(y[n])) continue;
      ++n;
    }
    if (n) {
      st = px_plot_add_series(pl, label[0] ? label : s->plot_y, n, x, y);
      ++nseries;
    }
  }
  if (st == PX_STATUS_OK && nseries) {
    snprintf(path, sizeof path, "%s/sweep.png", s->dir);
    st = px_plot_write_png(pl, path);
    s->plotted = st == PX_STATUS_OK;
  } else if (st == PX_STATUS_OK) {
    snprintf(path, sizeof path, "%s/sweep.png", s->dir);
    fprintf(stderr,
            "partix sweep: plot: no finished run reports %s against a numeric %s, so "
            "no sweep.png is drawn%s; the runs report:",
            s->plot_y, s->plot_x,
            px_file_exists(path) ? " (the one there is an earlier sweep's)" : "");
    for (k = 0; k < t->n; ++k) fprintf(stderr, "%s %s", k ? "," : "", t->name[k]);
    fprintf(stderr, "%s\n", t->n ? "" : " nothing (no run finished)");
  }
  px_plot_free(pl);
  free(x);
  free(y);
  free(done);
  return st;
}
