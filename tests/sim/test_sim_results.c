/* Results in memory (partix/results.h) of each solver's case, run as a loop
 * of px_sim_step: every series equals the run's own CSV file (names, units,
 * rows; values to the digits the file prints), the granular segment
 * statistics equal segments_part.csv, and the state agrees with the
 * quantities the solver writes about it (vortex count; granular kinetic
 * energy and centre of mass; lattice largest displacement and von Mises
 * stress). The callback sees every step, output and checkpoint. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/results.h"
#include "partix/sim.h"
#include "px_test.h"

/* A CSV file read back: header names and rows (at most 4096 x 64). */
struct table {
  size_t ncols, nrows;
  char names[64][96];
  double *v; /* nrows * ncols */
};

static int table_read(const char *path, struct table *t) {
  FILE *f = fopen(path, "r");
  static char line[1 << 16];
  char *p, *tok;
  memset(t, 0, sizeof *t);
  if (!f || !fgets(line, sizeof line, f)) {
    if (f) fclose(f);
    return -1;
  }
  line[strcspn(line, "\n")] = '\0';
  for (tok = strtok(line, ","); tok && t->ncols < 64; tok = strtok(NULL, ","))
    snprintf(t->names[t->ncols++], sizeof t->names[0], "%s", tok);
  t->v = calloc(4096 * t->ncols, sizeof *t->v);
  while (t->v && t->nrows < 4096 && fgets(line, sizeof line, f)) {
    size_t c;
    for (c = 0, p = line; c < t->ncols; ++c) {
      t->v[t->nrows * t->ncols + c] = strtod(p, &p);
      if (*p == ',') ++p;
    }
    ++t->nrows;
  }
  fclose(f);
  return t->v ? 0 : -1;
}

/* The value as the file prints it: 10 significant digits at least. */
static int same_printed(double mem, double file) {
  if (isnan(mem) || isnan(file)) return isnan(mem) && isnan(file);
  return fabs(mem - file) <= 6e-10 * fabs(mem) + 1e-300;
}

/* Views `r` against the CSV `path`, column by column ("name [units]"). */
static void check_against_csv(const struct px_results *r, const char *path, size_t first_col) {
  struct table t;
  size_t c, i;
  PX_CHECK_MSG(table_read(path, &t) == 0, "cannot read %s", path);
  PX_CHECK_MSG(px_results_count(r) == t.ncols + first_col, "%s: %zu views, %zu columns", path,
               px_results_count(r), t.ncols);
  for (c = 0; c < t.ncols && c + first_col < px_results_count(r); ++c) {
    const struct px_view *v = px_results_view(r, c + first_col);
    char head[160];
    int bad = 0;
    snprintf(head, sizeof head, "%s [%s]", v->name, v->units);
    PX_CHECK_MSG(strcmp(head, t.names[c]) == 0, "%s: view '%s', column '%s'", path, head,
                 t.names[c]);
    PX_CHECK(v->type == PX_VIEW_F64 && v->components == 1);
    PX_CHECK_MSG(v->length == t.nrows, "%s: %s has %zu rows in memory, %zu in the file", path,
                 v->name, v->length, t.nrows);
    for (i = 0; i < v->length && i < t.nrows && !bad; ++i) {
      double mem = *(const double *)((const char *)v->data + (ptrdiff_t)i * v->stride);
      bad = !same_printed(mem, t.v[i * t.ncols + c]);
      PX_CHECK_MSG(!bad, "%s: %s row %zu: %.17g in memory, %.17g in the file", path, v->name, i,
                   mem, t.v[i * t.ncols + c]);
    }
  }
  free(t.v);
}

static struct { long steps, outputs, checkpoints; } events;

static void on_event(struct px_sim *sim, enum px_sim_event ev, void *user) {
  (void)sim;
  PX_CHECK(user == &events);
  if (ev == PX_SIM_EVENT_STEP) ++events.steps;
  if (ev == PX_SIM_EVENT_OUTPUT) ++events.outputs;
  if (ev == PX_SIM_EVENT_CHECKPOINT) ++events.checkpoints;
}

/* Run `case_file` for `steps` steps with outputs every 5 steps (log) and 10
 * (snapshots) into `dir`, as a loop of px_sim_step. */
static struct px_sim *run_case(struct px_context *ctx, const char *case_file, const char *dir,
                               long steps) {
  char path[1024], out[256], nsteps[64];
  const char *set[] = {nsteps,
                       "output.every=10",
                       "output.log_every=5",
                       "output.png=false",
                       "output.checkpoint_every=8",
                       out};
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  snprintf(path, sizeof path, "%s/cases/%s", PX_SOURCE_DIR, case_file);
  snprintf(nsteps, sizeof nsteps, "time.steps=%ld", steps);
  snprintf(out, sizeof out, "output.dir=%s", dir);
  px_test_fresh_dir(dir);
  PX_CHECK_OK(ctx, px_case_load(ctx, path, set, sizeof set / sizeof set[0], &c));
  if (!c) return NULL;
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (!sim) return NULL;
  px_sim_set_progress(sim, NULL, 0);
  memset(&events, 0, sizeof events);
  px_sim_set_callback(sim, on_event, &events);
  while (px_sim_step_index(sim) < px_sim_step_count(sim)) {
    enum px_status s = px_sim_step(sim);
    PX_CHECK_OK(ctx, s);
    if (s != PX_STATUS_OK) break;
  }
  /* steps, outputs at 0, 5, 10, ..., and checkpoints at 8, 16, ... and the end */
  PX_CHECK(events.steps == steps);
  PX_CHECK_MSG(events.outputs == 1 + steps / 5 + (steps % 5 != 0 || steps % 10 != 0), "%ld outputs",
               events.outputs);
  PX_CHECK_MSG(events.checkpoints == (steps - 1) / 8 + 1, "%ld checkpoints", events.checkpoints);
  return sim;
}

static double at(const struct px_view *v, size_t i, size_t k) {
  return ((const double *)((const char *)v->data + (ptrdiff_t)i * v->stride))[k];
}

static void test_vortex(struct px_context *ctx) {
  struct px_sim *sim = run_case(ctx, "vortex/demo_cylinder.yaml", "results_vortex", 20);
  struct px_results *state = NULL, *loads = NULL, *seg = NULL;
  const struct px_view *x, *n;
  if (!sim) return;
  PX_CHECK(strcmp(px_sim_series_name(sim, 0), "loads") == 0);
  PX_CHECK_OK(ctx, px_sim_series(sim, "loads", &loads));
  check_against_csv(loads, "results_vortex/loads.csv", 0);
  PX_CHECK_OK(ctx, px_sim_results(sim, PX_RESULTS_STATE, &state));
  x = px_results_find(state, "x");
  n = px_results_find(loads, "vortices");
  PX_CHECK(x && n && n->length > 0 && strcmp(x->units, "m") == 0);
  /* the last row of loads.csv is the end state's */
  if (x && n) PX_CHECK_NEAR((double)x->length, at(n, n->length - 1, 0), 0);
  PX_CHECK(px_results_step(state) == 20);
  PX_CHECK_STATUS(ctx, px_sim_results(sim, PX_RESULTS_SEGMENTS, &seg), PX_STATUS_UNSUPPORTED);
  PX_CHECK(seg == NULL && strstr(px_context_message(ctx), "per-segment"));
  PX_CHECK_STATUS(ctx, px_sim_series(sim, "nothing", &seg), PX_STATUS_NOT_FOUND);
  PX_CHECK(strstr(px_context_message(ctx), "loads") != NULL);
  /* a results object outlives its run */
  px_sim_free(sim);
  PX_CHECK(x && x->length > 0 && isfinite(at(x, x->length - 1, 0)));
  px_results_free(state);
  px_results_free(loads);
}

static void test_granular(struct px_context *ctx) {
  struct px_sim *sim = run_case(ctx, "granular/small_box.yaml", "results_granular", 20);
  struct px_results *state = NULL, *media = NULL, *seg = NULL, *hist = NULL;
  const struct px_view *m, *x, *y, *vx, *vy, *w, *rad, *ek, *cx, *cy;
  double e = 0, mass = 0, mx = 0, my = 0;
  size_t i, last;
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_series(sim, "media", &media));
  check_against_csv(media, "results_granular/media.csv", 0);
  PX_CHECK_OK(ctx, px_sim_series(sim, "speed_histogram", &hist));
  check_against_csv(hist, "results_granular/speed_histogram.csv", 0);
  PX_CHECK_OK(ctx, px_sim_results(sim, PX_RESULTS_SEGMENTS, &seg));
  PX_CHECK(seg && strcmp(px_results_view(seg, 0)->name, "contour") == 0);
  check_against_csv(seg, "results_granular/segments_part.csv", 1);
  PX_CHECK_OK(ctx, px_sim_results(sim, PX_RESULTS_STATE, &state));
  m = px_results_find(state, "mass");
  x = px_results_find(state, "x");
  y = px_results_find(state, "y");
  vx = px_results_find(state, "vx");
  vy = px_results_find(state, "vy");
  w = px_results_find(state, "spin");
  rad = px_results_find(state, "radius");
  ek = px_results_find(media, "kinetic");
  cx = px_results_find(media, "com_x");
  cy = px_results_find(media, "com_y");
  PX_CHECK(m && x && y && vx && vy && w && rad && ek && cx && cy);
  if (!(m && x && y && vx && vy && w && rad && ek && cx && cy)) return;
  PX_CHECK(x->length == m->length && x->length > 0);
  for (i = 0; i < x->length; ++i) {
    e += 0.5 * at(m, i, 0) * (at(vx, i, 0) * at(vx, i, 0) + at(vy, i, 0) * at(vy, i, 0));
    mass += at(m, i, 0);
    mx += at(m, i, 0) * at(x, i, 0);
    my += at(m, i, 0) * at(y, i, 0);
    PX_CHECK(at(rad, i, 0) > 0);
  }
  /* media.csv's last row is the end state's (sums in another order) */
  last = ek->length - 1;
  PX_CHECK_REL(e, at(ek, last, 0), 1e-12);
  PX_CHECK_REL(mx / mass, at(cx, last, 0), 1e-12);
  PX_CHECK_REL(my / mass, at(cy, last, 0), 1e-12);
  px_results_free(state);
  px_results_free(media);
  px_results_free(hist);
  px_results_free(seg);
  px_sim_free(sim);
}

static void test_lattice(struct px_context *ctx) {
  struct px_sim *sim = run_case(ctx, "lattice/cantilever.yaml", "results_lattice", 20);
  struct px_results *state = NULL, *probes = NULL;
  const struct px_view *u, *vm, *umax, *vmmax, *br;
  double big_u = 0, big_vm = 0;
  size_t i;
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_series(sim, "probes", &probes));
  check_against_csv(probes, "results_lattice/probes.csv", 0);
  PX_CHECK_OK(ctx, px_sim_results(sim, PX_RESULTS_STATE, &state));
  u = px_results_find(state, "displacement");
  vm = px_results_find(state, "von_mises");
  br = px_results_find(state, "broken_links");
  umax = px_results_find(probes, "max_displacement");
  vmmax = px_results_find(probes, "max_von_mises");
  PX_CHECK(u && vm && br && umax && vmmax);
  if (!(u && vm && br && umax && vmmax)) return;
  PX_CHECK(u->components == 3 && u->stride == 24 && br->type == PX_VIEW_U8);
  PX_CHECK(px_results_find(state, "stress")->components == 6);
  PX_CHECK(u->length == vm->length && u->length > 0);
  for (i = 0; i < u->length; ++i) {
    double a = hypot(hypot(at(u, i, 0), at(u, i, 1)), at(u, i, 2));
    if (a > big_u) big_u = a;
    if (at(vm, i, 0) > big_vm) big_vm = at(vm, i, 0);
  }
  PX_CHECK(big_u > 0);
  PX_CHECK_REL(big_u, at(umax, umax->length - 1, 0), 1e-12);
  PX_CHECK_REL(big_vm, at(vmmax, vmmax->length - 1, 0), 1e-12);
  px_results_free(state);
  px_results_free(probes);
  px_sim_free(sim);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return EXIT_FAILURE;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  test_vortex(ctx);
  test_granular(ctx);
  test_lattice(ctx);
  px_context_free(ctx);
  return px_test_report("test_sim_results");
}
