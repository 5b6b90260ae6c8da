/* The run driver with a test solver: output schedule, the last state always
 * written, checkpoints, resume bit-identical to an uninterrupted run and
 * dropping what an earlier segment wrote only because it ended there, keys
 * refused on resume, an end before the checkpoint refused, render writing
 * pictures only, run.log and summary.json, input files kept in the run
 * folder, a converged run ending early, Ctrl-C, blow-up diagnosis, check
 * mode, end time. The test replaces the solver registry at link time (its
 * definitions come before libpartix.a, so registry.o is not linked). */
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "px_test.h"
#include "solvers/solver.h"
#include "solvers/summary.h"

/* ---- the test solver: n values relaxing by y' = -k (y - sin(i)) with explicit
 * Euler; `fail_at` makes a step fail like a blow-up. */
struct decay {
  struct px_sim *sim;
  long n, fail_at, interrupt_at;
  double k, done_below;
  long input_bytes; /* size of decay.file (-1: none) */
  double *y;        /* owned */
};

/* Outputs the driver asked for in the current run. */
static struct {
  long series, snapshots, pictures, finals, renders;
  struct px_sim_output last; /* of the last output hook called */
} outputs_seen;

static volatile sig_atomic_t test_interrupt = 0;

static enum px_status decay_create(struct px_sim *sim, void **state) {
  struct px_context *ctx = px_sim_context(sim);
  const struct px_case *c = px_sim_case(sim);
  struct decay *d = px_mem_calloc(ctx, "decay", 1, sizeof *d);
  long i;
  if (!d) return PX_STATUS_NOMEM;
  *state = d;
  d->sim = sim;
  memset(&outputs_seen, 0, sizeof outputs_seen);
  PX_TRY(px_case_get_int(c, "decay.n", &d->n));
  PX_TRY(px_case_get_real(c, "decay.k", &d->k));
  PX_TRY(px_case_get_int(c, "decay.fail_at", &d->fail_at));
  PX_TRY(px_case_get_int(c, "decay.interrupt_at", &d->interrupt_at));
  PX_TRY(px_case_get_real(c, "decay.done_below", &d->done_below));
  if (px_case_has(c, "decay.bytes")) {
    double bytes = 0;
    PX_TRY(px_case_get_real(c, "decay.bytes", &bytes));
    PX_TRY(px_sim_require_memory(sim, bytes, "decay.bytes", "the test's arrays"));
  }
  d->input_bytes = -1;
  if (px_case_has(c, "decay.file")) {
    char path[1024];
    FILE *f;
    PX_TRY(px_case_input_path(c, "decay.file", path, sizeof path));
    f = fopen(path, "rb");
    if (!f) return px_case_fail((struct px_case *)c, "decay.file", "cannot open %s", path);
    fseek(f, 0, SEEK_END);
    d->input_bytes = ftell(f);
    fclose(f);
  }
  d->y = px_mem_calloc(ctx, "decay.y", (size_t)d->n, sizeof *d->y);
  if (!d->y) return PX_STATUS_NOMEM;
  for (i = 0; i < d->n; ++i) d->y[i] = cos((double)i);
  return PX_STATUS_OK;
}

static void decay_destroy(void *state) {
  struct decay *d = state;
  struct px_context *ctx = px_sim_context(d->sim);
  px_mem_free(ctx, d->y);
  px_mem_free(ctx, d);
}

static enum px_status decay_time_step(void *state, double *dt) {
  struct decay *d = state;
  *dt = 0.1 / d->k;
  return PX_STATUS_OK;
}

static enum px_status decay_step(void *state, long step, double t, double dt) {
  struct decay *d = state;
  long i;
  (void)t;
  if (step + 1 == d->fail_at)
    return px_context_fail(px_sim_context(d->sim), PX_STATUS_NUMERIC,
                           "value 3 is not finite (y = nan)");
  for (i = 0; i < d->n; ++i) d->y[i] += dt * (-d->k * (d->y[i] - sin((double)i)));
  if (step + 1 == d->interrupt_at) test_interrupt = 1;
  return PX_STATUS_OK;
}

static void decay_seen(const struct px_sim_output *o) {
  outputs_seen.last = *o;
  outputs_seen.finals += o->final;
  outputs_seen.renders += o->render;
}

static enum px_status decay_series(void *state, const struct px_sim_output *o) {
  (void)state;
  outputs_seen.series++;
  decay_seen(o);
  return PX_STATUS_OK;
}

static enum px_status decay_snapshot(void *state, const struct px_sim_output *o) {
  (void)state;
  outputs_seen.snapshots++;
  decay_seen(o);
  return PX_STATUS_OK;
}

static enum px_status decay_picture(void *state, const struct px_sim_output *o) {
  (void)state;
  outputs_seen.pictures++;
  decay_seen(o);
  return PX_STATUS_OK;
}

/* The largest |y - sin(i)| (the distance from the fixed point). */
static double decay_distance(const struct decay *d) {
  double m = 0;
  long i;
  for (i = 0; i < d->n; ++i) m = fmax(m, fabs(d->y[i] - sin((double)i)));
  return m;
}

static enum px_status decay_report(void *state, const struct px_sim_output *o,
                                   struct px_summary *sum) {
  struct decay *d = state;
  (void)o;
  px_summary_real(sum, "distance", decay_distance(d), "-", "largest |y - sin(i)|");
  px_summary_int(sum, "values", d->n, "-", "number of values");
  px_summary_real(sum, "whole", 200.0, "-", "a whole number held as a real");
  px_summary_text(sum, "note", "a \"quoted\" name", "text is escaped");
  return PX_STATUS_OK;
}

static int decay_done(const void *state) {
  const struct decay *d = state;
  return d->done_below > 0 && decay_distance(d) < d->done_below;
}

static const char *const decay_resume_keys[] = {"decay.interrupt_at", NULL};

static enum px_status decay_save(void *state, struct px_checkpoint_writer *w) {
  struct decay *d = state;
  return px_checkpoint_write(w, "y", PX_DTYPE_F64, (uint64_t)d->n, d->y);
}

static enum px_status decay_load(void *state, struct px_checkpoint *ck) {
  struct decay *d = state;
  return px_checkpoint_read(ck, "y", PX_DTYPE_F64, (uint64_t)d->n, d->y);
}

static long decay_count(const void *state) { return ((const struct decay *)state)->n; }

static const struct px_solver_i decay_solver = {
    .name = "decay",
    .summary = "test solver",
    .create = decay_create,
    .destroy = decay_destroy,
    .time_step = decay_time_step,
    .step = decay_step,
    .snapshot = decay_snapshot,
    .series = decay_series,
    .picture = decay_picture,
    .save = decay_save,
    .load = decay_load,
    .count = decay_count,
    .report = decay_report,
    .resume_keys = decay_resume_keys,
    .done = decay_done,
};

static const struct px_schema decay_keys[] = {
    PX_KEY_INT("n", "number of values", PX_DEFAULT("100"), PX_GE(1)),
    PX_KEY_REAL("k", "rate [1/s]", PX_DEFAULT("2.0"), PX_GT(0)),
    PX_KEY_INT("fail_at", "step that fails (0 = none)", PX_DEFAULT("0"), PX_GE(0)),
    PX_KEY_INT("interrupt_at", "step after which Ctrl-C is simulated", PX_DEFAULT("0"), PX_GE(0)),
    PX_KEY_REAL("done_below", "stop when max |y - sin(i)| falls below (0 = never)", PX_DEFAULT("0"),
                PX_GE(0)),
    PX_KEY_STRING("file", "an input file (its size is read)", PX_INPUT_FILE),
    PX_KEY_REAL("bytes", "memory the run says it needs [bytes]", PX_GE(0)),
    PX_KEY_END};

/* The link-time replacement of src/solvers/registry.c. */
static const struct px_schema decay_sections[] = {PX_KEY_MAP("decay", decay_keys, "test solver"),
                                                  PX_KEY_END};

const struct px_schema *px_case_root_schema(void) {
  static struct px_case_root_storage storage;
  static const struct px_schema *root;
  if (!root) root = px_case_root_schema_build(decay_sections, &storage);
  return root;
}

const struct px_solver_i *const *px_solver_registry(void) {
  static const struct px_solver_i *const list[] = {&decay_solver, NULL};
  return list;
}

/* ---- helpers */

static struct px_sim *make_sim(struct px_context *ctx, const char *dir, const char *extra,
                               enum px_sim_mode mode, enum px_status expect) {
  char text[1024];
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  enum px_status s;
  snprintf(text, sizeof text,
           "solver: decay\n"
           "time: {steps: 20}\n"
           "output: {dir: %s, every: 5, png_every: 10, log_every: 2}\n"
           "decay: {n: 64%s}\n",
           dir, extra);
  s = px_case_load_string(ctx, "decay.yaml", text, strlen(text), NULL, 0, &c);
  PX_CHECK_MSG(s == PX_STATUS_OK, "%s", px_context_message(ctx));
  if (s != PX_STATUS_OK) return NULL;
  s = px_sim_create(ctx, c, mode, &sim);
  PX_CHECK_MSG(s == expect, "got %s: %s", px_status_name(s), px_context_message(ctx));
  if (sim) px_sim_set_progress(sim, NULL, 0);
  return sim;
}

/* The driver keeps the solver state private; reading it back from the final
 * checkpoint is the honest way to compare runs. */
static void read_final(struct px_context *ctx, const char *dir, double *y, long n, long *step) {
  char path[512];
  struct px_checkpoint *ck = NULL;
  snprintf(path, sizeof path, "%s/checkpoint.pxc", dir);
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, path, &ck));
  if (!ck) return;
  PX_CHECK_OK(ctx, px_checkpoint_read(ck, "y", PX_DTYPE_F64, (uint64_t)n, y));
  *step = (long)px_checkpoint_step(ck);
  px_checkpoint_close(ck);
}

static void test_run_writes_outputs_on_schedule(struct px_context *ctx) {
  struct px_sim *sim = make_sim(ctx, "run_a", "", PX_SIM_MODE_RUN, PX_STATUS_OK);
  double y[64];
  long step = -1, i;
  if (!sim) return;
  PX_CHECK_NEAR(px_sim_dt(sim), 0.05, 0); /* from the solver: 0.1 / k */
  PX_CHECK(px_sim_step_count(sim) == 20);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  PX_CHECK(px_sim_step_index(sim) == 20);
  PX_CHECK_NEAR(px_sim_time(sim), 1.0, 1e-15);
  /* steps 0..20: series every 2, snapshots every 5, pictures every 10 */
  PX_CHECK(outputs_seen.series == 11);
  PX_CHECK(outputs_seen.snapshots == 5);
  PX_CHECK(outputs_seen.pictures == 3);
  PX_CHECK(px_file_exists("run_a/case.yaml"));
  PX_CHECK(px_file_exists("run_a/checkpoint.pxc"));
  px_sim_free(sim);
  read_final(ctx, "run_a", y, 64, &step);
  PX_CHECK(step == 20);
  /* Euler on y' = -k (y - s): y_n - s = (1 - k dt)^n (y_0 - s) */
  for (i = 0; i < 64; ++i) {
    double s = sin((double)i), expect = s + pow(1 - 2.0 * 0.05, 20) * (cos((double)i) - s);
    PX_CHECK_NEAR(y[i], expect, 1e-13);
  }
}

static void test_resume_is_bit_identical(struct px_context *ctx) {
  struct px_sim *sim;
  double ya[64], yb[64];
  long sa = 0, sb = 0;
  const char *more[] = {"time.steps=20"};
  /* reference: 20 steps uninterrupted */
  read_final(ctx, "run_a", ya, 64, &sa);
  /* 7 steps, then resume to 20 */
  {
    char text[512];
    struct px_case *c = NULL;
    snprintf(text, sizeof text,
             "solver: decay\ntime: {steps: 7}\noutput: {dir: run_b, every: 5}\ndecay: {n: 64}\n");
    PX_CHECK_OK(ctx, px_case_load_string(ctx, "b.yaml", text, strlen(text), NULL, 0, &c));
    PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    px_sim_free(sim);
  }
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_b/checkpoint.pxc", more, 1, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  PX_CHECK(px_sim_step_index(sim) == 7);
  PX_CHECK(strcmp(px_sim_output_dir(sim), "run_b") == 0);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  read_final(ctx, "run_b", yb, 64, &sb);
  PX_CHECK(sa == 20 && sb == 20);
  PX_CHECK(memcmp(ya, yb, sizeof ya) == 0);
}

static void test_render_redraws_the_last_state(struct px_context *ctx) {
  struct px_sim *sim = NULL;
  PX_CHECK_OK(ctx, px_sim_open(ctx, "run_a/checkpoint.pxc", NULL, 0, PX_SIM_MODE_RENDER, &sim));
  if (!sim) return;
  PX_CHECK(px_sim_step_index(sim) == 20);
  PX_CHECK(outputs_seen.pictures == 0 && outputs_seen.series == 0);
  PX_CHECK_OK(ctx, px_sim_render(sim));
  PX_CHECK(outputs_seen.pictures == 1 && outputs_seen.series == 0 && outputs_seen.snapshots == 0);
  px_sim_free(sim);
}

static void test_interrupt_writes_a_checkpoint(struct px_context *ctx) {
  struct px_sim *sim = make_sim(ctx, "run_c", ", interrupt_at: 6", PX_SIM_MODE_RUN, PX_STATUS_OK);
  double y[64];
  long step = -1;
  if (!sim) return;
  px_context_set_interrupt_flag(ctx, &test_interrupt);
  PX_CHECK_STATUS(ctx, px_sim_run(sim), PX_STATUS_INTERRUPTED);
  PX_CHECK(strstr(px_context_message(ctx), "interrupted at step 6") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "partix resume run_c/checkpoint.pxc") != NULL);
  px_sim_free(sim);
  px_context_set_interrupt_flag(ctx, NULL);
  test_interrupt = 0;
  read_final(ctx, "run_c", y, 64, &step);
  PX_CHECK(step == 6);
}

static void test_blow_up_names_step_and_last_checkpoint(struct px_context *ctx) {
  struct px_sim *sim;
  char text[512];
  struct px_case *c = NULL;
  snprintf(text, sizeof text,
           "solver: decay\ntime: {steps: 20}\noutput: {dir: run_d, checkpoint_every: 5}\n"
           "decay: {n: 8, fail_at: 12}\n");
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "d.yaml", text, strlen(text), NULL, 0, &c));
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  PX_CHECK_STATUS(ctx, px_sim_run(sim), PX_STATUS_NUMERIC);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "step 12 (t = 0.6): value 3 is not finite") != NULL,
               "%s", px_context_message(ctx));
  PX_CHECK_MSG(strstr(px_context_message(ctx), "run_d/checkpoint.pxc (step 10)") != NULL, "%s",
               px_context_message(ctx));
  px_sim_free(sim);
}

static void test_check_mode_writes_nothing(struct px_context *ctx) {
  struct stat st;
  struct px_sim *sim = make_sim(ctx, "run_e", "", PX_SIM_MODE_CHECK, PX_STATUS_OK);
  PX_CHECK(sim != NULL);
  PX_CHECK(stat("run_e", &st) != 0);
  px_sim_free(sim);
}

static void test_end_time_sets_the_step_count(struct px_context *ctx) {
  char text[512];
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  snprintf(text, sizeof text,
           "solver: decay\ntime: {end: 0.52, dt: 0.02}\noutput: {dir: run_f}\ndecay: {n: 4}\n");
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "f.yaml", text, strlen(text), NULL, 0, &c));
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim));
  if (!sim) return;
  PX_CHECK_NEAR(px_sim_dt(sim), 0.02, 0); /* the case's dt wins over the solver's */
  PX_CHECK(px_sim_step_count(sim) == 26);
  px_sim_free(sim);
}

/* ---- helpers for files */

/* The whole file into buf (NUL-terminated); its length, -1 if unreadable. */
static long slurp(const char *path, char *buf, size_t size) {
  FILE *f = fopen(path, "rb");
  size_t n;
  if (!f) return -1;
  n = fread(buf, 1, size - 1, f);
  fclose(f);
  buf[n] = '\0';
  return (long)n;
}

static void write_text(const char *path, const char *text) {
  FILE *f = fopen(path, "wb");
  PX_CHECK_MSG(f != NULL, "cannot write %s", path);
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

/* A run of `steps` steps into dir with the schedule of make_sim. */
static struct px_sim *run_steps(struct px_context *ctx, const char *dir, long steps,
                                const char *extra) {
  char text[1024];
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  snprintf(text, sizeof text,
           "solver: decay\ntime: {steps: %ld}\n"
           "output: {dir: %s, every: 5, png_every: 10, log_every: 2}\ndecay: {n: 16%s}\n",
           steps, dir, extra);
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "s.yaml", text, strlen(text), NULL, 0, &c));
  if (!c) return NULL;
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (sim) px_sim_set_progress(sim, NULL, 0);
  return sim;
}

/* 23 steps (off every schedule): the last state is written by every output
 * kind, flagged final, besides the scheduled ones. */
static void test_the_last_state_is_always_written(struct px_context *ctx) {
  struct px_sim *sim = run_steps(ctx, "run_g", 23, "");
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  /* series 0, 2, .., 22 and 23; snapshots 0, 5, .., 20 and 23; pictures 0,
     10, 20 and 23 */
  PX_CHECK(outputs_seen.series == 13);
  PX_CHECK(outputs_seen.snapshots == 6);
  PX_CHECK(outputs_seen.pictures == 4);
  PX_CHECK(outputs_seen.finals == 3);
  PX_CHECK(outputs_seen.last.step == 23 && outputs_seen.last.final == 1);
  px_sim_free(sim);
}

/* A run that ended at step 7 (off the schedules) and is resumed: its
 * outputs are told to drop what the end of the first segment added (t > 6.5
 * dt for the snapshot and series schedules, the picture of step 7) and to
 * keep everything before. */
static void test_resume_drops_what_a_segment_end_added(struct px_context *ctx) {
  struct px_sim *sim = run_steps(ctx, "run_h", 7, "");
  const char *more[] = {"time.steps=20"};
  double dt;
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  dt = px_sim_dt(sim);
  px_sim_free(sim);
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_h/checkpoint.pxc", more, 1, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  memset(&outputs_seen, 0, sizeof outputs_seen);
  PX_CHECK_OK(ctx, px_sim_step(sim)); /* step 8: a series row */
  PX_CHECK(outputs_seen.series == 1 && outputs_seen.last.resumed == 1);
  PX_CHECK_NEAR(outputs_seen.last.resume_time, 7 * dt, 1e-15);
  PX_CHECK_NEAR(outputs_seen.last.keep_series, 6.5 * dt, 1e-15);
  PX_CHECK_NEAR(outputs_seen.last.keep_snapshot, 6.5 * dt, 1e-15);
  PX_CHECK(outputs_seen.last.drop_picture == 7);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  PX_CHECK(outputs_seen.last.resumed == 1 && outputs_seen.last.step == 20);
  px_sim_free(sim);
  /* resumed at step 10, on every schedule: nothing is dropped, and the rows
     at the resume time are kept however their time was rounded */
  sim = run_steps(ctx, "run_h2", 10, "");
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_h2/checkpoint.pxc", more, 1, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  memset(&outputs_seen, 0, sizeof outputs_seen);
  PX_CHECK_OK(ctx, px_sim_step(sim)); /* step 11: no output */
  PX_CHECK_OK(ctx, px_sim_step(sim)); /* step 12: a series row */
  PX_CHECK(outputs_seen.series == 1);
  PX_CHECK_NEAR(outputs_seen.last.keep_series, outputs_seen.last.resume_time + 0.5 * dt, 1e-15);
  PX_CHECK_NEAR(outputs_seen.last.keep_snapshot, outputs_seen.last.resume_time + 0.5 * dt, 1e-15);
  PX_CHECK(outputs_seen.last.drop_picture == -1);
  px_sim_free(sim);
}

/* A key that defines the stored state cannot change on resume (named, with
 * the keys that may); the same value, the solver's resume keys and the
 * platform's output/time keys may. Nothing of the run folder is touched by a
 * refused resume. */
static void test_resume_refuses_state_keys(struct px_context *ctx) {
  struct px_sim *sim = run_steps(ctx, "run_i", 6, "");
  const char *k3[] = {"time.steps=9", "decay.k=3"};
  const char *k2[] = {"time.steps=9", "decay.k=2.0", "decay.interrupt_at=0", "output.every=3",
                      "backend.threads=1"};
  const char *prec[] = {"time.steps=9", "backend.precision=single"};
  char before[8192], after[8192];
  long nb, na;
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  sim = NULL;
  nb = slurp("run_i/case.yaml", before, sizeof before);
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_i/checkpoint.pxc", k3, 2, &sim), PX_STATUS_CONFIG);
  PX_CHECK(sim == NULL);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "decay.k cannot change when a run is resumed") &&
                   strstr(px_context_message(ctx), "decay.k = 2") &&
                   strstr(px_context_message(ctx), "time.steps") &&
                   strstr(px_context_message(ctx), "decay.interrupt_at"),
               "%s", px_context_message(ctx));
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_i/checkpoint.pxc", prec, 2, &sim), PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "backend.precision cannot change") != NULL);
  na = slurp("run_i/case.yaml", after, sizeof after);
  PX_CHECK(na == nb && na > 0 && memcmp(before, after, (size_t)na) == 0);
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_i/checkpoint.pxc", k2, 5, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    PX_CHECK(px_sim_step_index(sim) == 9);
  }
  px_sim_free(sim);
}

/* An end at or before the checkpoint runs nothing: refused, with the way to
 * run further; a finished run resumed without a new end likewise. */
static void test_resume_refuses_an_end_before_the_checkpoint(struct px_context *ctx) {
  struct px_sim *sim = run_steps(ctx, "run_j", 8, "");
  const char *back[] = {"time.steps=5"};
  const char *same[] = {"time.steps=8"};
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  sim = NULL;
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_j/checkpoint.pxc", back, 1, &sim), PX_STATUS_CONFIG);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "at step 8") &&
                   strstr(px_context_message(ctx), "ends at step 5") &&
                   strstr(px_context_message(ctx), "--more N"),
               "%s", px_context_message(ctx));
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_j/checkpoint.pxc", same, 1, &sim), PX_STATUS_CONFIG);
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_j/checkpoint.pxc", NULL, 0, &sim), PX_STATUS_CONFIG);
  PX_CHECK(sim == NULL);
}

/* A run killed after its last checkpoint but before its end-of-run
 * products (summary.json not "finished") is finished by resuming it: no
 * step runs, the last outputs and the summary are written; then it is done
 * and a further resume is refused. */
static void test_resume_finishes_a_run_killed_at_its_end(struct px_context *ctx) {
  static char text[8192];
  struct px_sim *sim = run_steps(ctx, "run_p", 10, "");
  FILE *f;
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  PX_CHECK(slurp("run_p/summary.json", text, sizeof text) > 0);
  PX_CHECK(strstr(text, "\"status\": \"finished\"") != NULL);
  f = fopen("run_p/summary.json", "wb"); /* as a kill before the end would leave it */
  if (f) {
    fputs("{\"status\": \"running\"}\n", f);
    fclose(f);
  }
  sim = NULL;
  memset(&outputs_seen, 0, sizeof outputs_seen);
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_p/checkpoint.pxc", NULL, 0, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  PX_CHECK(px_sim_step_index(sim) == 10);
  px_sim_free(sim);
  PX_CHECK(slurp("run_p/summary.json", text, sizeof text) > 0);
  PX_CHECK_MSG(strstr(text, "\"status\": \"finished\"") && strstr(text, "\"step\": 10,"), "%s",
               text);
  sim = NULL;
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_p/checkpoint.pxc", NULL, 0, &sim), PX_STATUS_CONFIG);
}

/* A loop of px_sim_step (an embedding program's, or Python's) writes what
 * px_sim_run writes: the step-0 outputs before the first step, the
 * scheduled ones, and at the last step (or when the solver is done) the
 * end-of-run products; a step past the end is refused. The decay's outputs
 * are a pure function of its state, so equal counts and the same summary
 * mean the same folder. */
static void test_a_loop_of_steps_writes_what_run_writes(struct px_context *ctx) {
  static char text[8192];
  long series, snapshots, pictures, finals;
  struct px_sim *sim = run_steps(ctx, "run_r", 23, "");
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  series = outputs_seen.series, snapshots = outputs_seen.snapshots;
  pictures = outputs_seen.pictures, finals = outputs_seen.finals;
  px_sim_free(sim);
  sim = run_steps(ctx, "run_s", 23, "");
  if (!sim) return;
  while (px_sim_step_index(sim) < px_sim_step_count(sim)) PX_CHECK_OK(ctx, px_sim_step(sim));
  PX_CHECK_MSG(outputs_seen.series == series && outputs_seen.snapshots == snapshots &&
                   outputs_seen.pictures == pictures && outputs_seen.finals == finals,
               "steps: %ld series, %ld snapshots, %ld pictures, %ld final; run: %ld %ld %ld %ld",
               outputs_seen.series, outputs_seen.snapshots, outputs_seen.pictures,
               outputs_seen.finals, series, snapshots, pictures, finals);
  PX_CHECK(slurp("run_s/summary.json", text, sizeof text) > 0);
  PX_CHECK_MSG(strstr(text, "\"status\": \"finished\"") && strstr(text, "\"step\": 23,"), "%s",
               text);
  PX_CHECK_STATUS(ctx, px_sim_step(sim), PX_STATUS_INVALID);
  PX_CHECK(px_sim_step_index(sim) == 23);
  px_sim_free(sim);
  /* a solver done early (test_done_ends_a_run_early: step 69) ends the loop */
  sim = run_steps(ctx, "run_t", 500, ", done_below: 1e-3");
  if (!sim) return;
  while (px_sim_step(sim) == PX_STATUS_OK) {
  }
  PX_CHECK(px_sim_step_index(sim) == 69);
  PX_CHECK(outputs_seen.last.final == 1 && outputs_seen.last.step == 69);
  PX_CHECK(slurp("run_t/summary.json", text, sizeof text) > 0);
  PX_CHECK(strstr(text, "\"status\": \"finished\"") != NULL);
  px_sim_free(sim);
  px_context_clear(ctx);
}

/* Temporaries of a writer that no longer runs (kill -9 while writing) are
 * removed when the run folder opens again; a live writer's are kept. */
static void test_dead_writers_temporaries_are_swept(struct px_context *ctx) {
  struct px_sim *sim = NULL;
  const char *more[] = {"time.steps=8"};
  char live[64];
  FILE *f;
  sim = run_steps(ctx, "run_q", 4, "");
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  /* PID 2^22 + 1 is above Linux's default pid_max: no such process */
  f = fopen("run_q/loads.csv.tmp-4194305-3", "wb");
  if (f) fclose(f);
  f = fopen("run_q/checkpoint.pxc.tmp-4194305-0", "wb");
  if (f) fclose(f);
  snprintf(live, sizeof live, "run_q/x.csv.tmp-%ld-0", (long)getppid());
  f = fopen(live, "wb");
  if (f) fclose(f);
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_q/checkpoint.pxc", more, 1, &sim));
  px_sim_free(sim);
  PX_CHECK(!px_file_exists("run_q/loads.csv.tmp-4194305-3"));
  PX_CHECK(!px_file_exists("run_q/checkpoint.pxc.tmp-4194305-0"));
  PX_CHECK(px_file_exists(live));
  remove(live);
}

/* run.log holds the INFO lines whatever the console's level (here WARN)
 * and is appended to on resume; summary.json has the run and the solver's
 * report, escaped, and the automatic time step. */
static void test_run_log_and_summary(struct px_context *ctx) {
  static char text[65536];
  struct px_sim *sim = run_steps(ctx, "run_k", 6, "");
  const char *more[] = {"time.steps=10"};
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  PX_CHECK(px_context_log_level(ctx) == PX_LOG_LEVEL_WARN); /* restored */
  PX_CHECK(slurp("run_k/run.log", text, sizeof text) > 0);
  PX_CHECK_MSG(strstr(text, "info: partix ") && strstr(text, "run of s.yaml") &&
                   strstr(text, "info: automatic: time.dt = 0.05 s") &&
                   strstr(text, "info: 6 steps in"),
               "%s", text);
  PX_CHECK(slurp("run_k/summary.json", text, sizeof text) > 0);
  PX_CHECK_MSG(strstr(text, "\"solver\": \"decay\"") && strstr(text, "\"status\": \"finished\"") &&
                   strstr(text, "\"step\": 6,") && strstr(text, "\"time_s\": 0.3") &&
                   strstr(text, "\"time.dt\": \"0.05 s (the solver's stable step)\"") &&
                   strstr(text, "\"values\": {\"value\": 16, \"unit\": \"-\"") &&
                   strstr(text, "\"whole\": {\"value\": 200, \"unit\"") &&
                   strstr(text, "\"value\": \"a \\\"quoted\\\" name\""),
               "%s", text);
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_k/checkpoint.pxc", more, 1, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  PX_CHECK(slurp("run_k/run.log", text, sizeof text) > 0);
  PX_CHECK_MSG(strstr(text, "info: 6 steps in") && strstr(text, "resume of run_k/checkpoint.pxc") &&
                   strstr(text, "info: 4 steps in"),
               "%s", text);
  PX_CHECK(slurp("run_k/summary.json", text, sizeof text) > 0);
  PX_CHECK(strstr(text, "\"step\": 10,") != NULL);
}

/* Render draws pictures (flagged render) and changes nothing else of the
 * run folder: case.yaml, run.log and summary.json stay as they are. */
static void test_render_changes_no_record(struct px_context *ctx) {
  static char b_case[8192], a_case[8192], b_log[65536], a_log[65536], b_sum[8192], a_sum[8192];
  struct px_sim *sim = NULL;
  const char *set[] = {"output.every=1"};
  long n1 = slurp("run_k/case.yaml", b_case, sizeof b_case);
  long n2 = slurp("run_k/run.log", b_log, sizeof b_log);
  long n3 = slurp("run_k/summary.json", b_sum, sizeof b_sum);
  PX_CHECK(n1 > 0 && n2 > 0 && n3 > 0);
  memset(&outputs_seen, 0, sizeof outputs_seen);
  PX_CHECK_OK(ctx, px_sim_open(ctx, "run_k/checkpoint.pxc", set, 1, PX_SIM_MODE_RENDER, &sim));
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_render(sim));
  px_sim_free(sim);
  PX_CHECK(outputs_seen.pictures == 1 && outputs_seen.renders == 1);
  PX_CHECK(slurp("run_k/case.yaml", a_case, sizeof a_case) == n1 &&
           memcmp(a_case, b_case, (size_t)n1) == 0);
  PX_CHECK(slurp("run_k/run.log", a_log, sizeof a_log) == n2 &&
           memcmp(a_log, b_log, (size_t)n2) == 0);
  PX_CHECK(slurp("run_k/summary.json", a_sum, sizeof a_sum) == n3 &&
           memcmp(a_sum, b_sum, (size_t)n3) == 0);
}

/* An input file named relative to the case file is read from there, copied
 * into RUN_DIR/input/ and recorded by that name, so the run resumes from
 * another place; two files of one name and different content get two names,
 * the same content one. */
static void test_input_files_are_kept_in_the_run(struct px_context *ctx) {
  static char text[8192];
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  const char *more[] = {"time.steps=6"};
  const char *other[] = {"decay.file=inputs_b/table.txt"};
  if (system("rm -rf inputs_a inputs_b run_l run_m && mkdir -p inputs_a inputs_b") != 0) return;
  write_text("inputs_a/table.txt", "1 2 3\n");
  write_text("inputs_b/table.txt", "4 5 6 7 8\n");
  write_text("inputs_a/case.yaml",
             "solver: decay\ntime: {steps: 3}\noutput: {dir: run_l}\n"
             "decay: {n: 4, file: table.txt}\n");
  PX_CHECK_OK(ctx, px_case_load(ctx, "inputs_a/case.yaml", NULL, 0, &c));
  if (!c) return;
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (!sim) return;
  px_sim_set_progress(sim, NULL, 0);
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  PX_CHECK(slurp("run_l/input/table.txt", text, sizeof text) == 6);
  PX_CHECK(slurp("run_l/case.yaml", text, sizeof text) > 0);
  PX_CHECK_MSG(strstr(text, "file: \"input/table.txt\"") != NULL, "%s", text);
  PX_CHECK(slurp("run_l/summary.json", text, sizeof text) > 0);
  PX_CHECK_MSG(strstr(text, "\"input/table.txt\": {\"bytes\": 6, \"fnv1a64\": \"") != NULL, "%s",
               text);
  /* the source is gone: the run resumes from its own copy */
  PX_CHECK(remove("inputs_a/table.txt") == 0);
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_l/checkpoint.pxc", more, 1, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
  }
  px_sim_free(sim);
  /* a --set file is relative to the working directory */
  write_text("inputs_a/table.txt", "1 2 3\n");
  c = NULL;
  sim = NULL;
  PX_CHECK_OK(ctx, px_case_load(ctx, "inputs_a/case.yaml", other, 1, &c));
  if (c) {
    char path[256];
    PX_CHECK_OK(ctx, px_case_input_path(c, "decay.file", path, sizeof path));
    PX_CHECK(strcmp(path, "inputs_b/table.txt") == 0);
    PX_CHECK(px_case_input_path(c, "decay.k", path, sizeof path) == PX_STATUS_INVALID);
    px_case_free(c);
  }
}

/* A run whose solver says it is done (max |y - sin i| below 1e-3) ends after
 * that step: |y_n - s| = 0.9^n |y_0 - s| (Euler, k dt = 0.1), and the
 * largest |cos i - sin i| over i < 16 is that of i = 14, so it ends at the
 * first n with 0.9^n * 1.4074 < 1e-3: n = 69. */
static void test_done_ends_a_run_early(struct px_context *ctx) {
  struct px_sim *sim = run_steps(ctx, "run_n", 500, ", done_below: 1e-3");
  double m = 0, n;
  long i;
  if (!sim) return;
  for (i = 0; i < 16; ++i) m = fmax(m, fabs(cos((double)i) - sin((double)i)));
  n = ceil(log(1e-3 / m) / log(0.9));
  PX_CHECK_OK(ctx, px_sim_run(sim));
  PX_CHECK_MSG(px_sim_step_index(sim) == (long)n, "ended at %ld, expected %g",
               px_sim_step_index(sim), n);
  PX_CHECK(outputs_seen.last.final == 1 && outputs_seen.last.step == (long)n);
  px_sim_free(sim);
}

/* Step counts and times a run cannot reach are refused at the key: an end
 * time that needs more than 1e12 steps (time.dt in the wrong units), a step
 * whose end time is not finite, more threads than 4 per core. */
static void test_absurd_schedules_are_refused(struct px_context *ctx) {
  const char *texts[] = {
      "solver: decay\ntime: {end: 1, dt: 1e-320}\ndecay: {n: 4}\n",
      "solver: decay\ntime: {steps: 10, dt: 1e308}\ndecay: {n: 4}\n",
      "solver: decay\ntime: {steps: 10}\nbackend: {threads: 1024}\ndecay: {n: 4}\n"};
  const char *expect[] = {"s.yaml:2:20: time.dt: time.end / time.dt = 1 / 1e-320 s = inf steps",
                          "s.yaml:2:23: time.dt: 10 steps of 1e+308 s end at t = inf s",
                          "s.yaml:3:20: backend.threads: 1024 threads on a machine with"};
  size_t i;
  for (i = 0; i < 3; ++i) {
    struct px_case *c = NULL;
    struct px_sim *sim = NULL;
    PX_CHECK_OK(ctx, px_case_load_string(ctx, "s.yaml", texts[i], strlen(texts[i]), NULL, 0, &c));
    if (!c) continue;
    if (i == 2 && sysconf(_SC_NPROCESSORS_ONLN) * 4 >= 1024) { /* a big machine */
      px_case_free(c);
      continue;
    }
    PX_CHECK_STATUS(ctx, px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim), PX_STATUS_CONFIG);
    PX_CHECK_MSG(strstr(px_context_message(ctx), expect[i]) != NULL, "%s", px_context_message(ctx));
    PX_CHECK(sim == NULL);
  }
}

/* Memory beyond the machine's is refused before anything is allocated, at
 * the key that sets the size, with both figures; a small need passes. */
static void test_memory_beyond_the_machine_is_refused(struct px_context *ctx) {
  const char *big = "solver: decay\ntime: {steps: 1}\ndecay: {n: 4, bytes: 1e18}\n";
  const char *small = "solver: decay\ntime: {steps: 1}\ndecay: {n: 4, bytes: 1e6}\n";
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "m.yaml", big, strlen(big), NULL, 0, &c));
  PX_CHECK_STATUS(ctx, px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim), PX_STATUS_CONFIG);
  PX_CHECK_MSG(strstr(px_context_message(ctx),
                      "m.yaml:3:22: decay.bytes: decay.bytes = 1e+18 "
                      "needs 1.0 EB for the test's arrays; this "
                      "machine has ") != NULL,
               "%s", px_context_message(ctx));
  c = NULL;
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "m.yaml", small, strlen(small), NULL, 0, &c));
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim));
  px_sim_free(sim);
  /* the context's limit, below the machine's memory, is the bound */
  px_context_set_memory_limit(ctx, (size_t)1 << 19);
  c = NULL;
  sim = NULL;
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "m.yaml", small, strlen(small), NULL, 0, &c));
  PX_CHECK_STATUS(ctx, px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim), PX_STATUS_CONFIG);
  PX_CHECK_MSG(strstr(px_context_message(ctx),
                      "decay.bytes = 1000000 needs 1.0 MB for the "
                      "test's arrays; the run's memory limit is 512 KiB") != NULL,
               "%s", px_context_message(ctx));
  px_context_set_memory_limit(ctx, 0);
}

/* Write run_o/checkpoint.pxc by hand: a valid file (CRCs right) whose header
 * may lie about the case hash or the step. */
static void forge_checkpoint(struct px_context *ctx, const char *text, uint64_t hash, uint64_t step,
                             double t, double dt) {
  struct px_checkpoint_writer *w = NULL;
  double y[16];
  long i;
  for (i = 0; i < 16; ++i) y[i] = cos((double)i);
  PX_CHECK_OK(ctx,
              px_checkpoint_writer_open(ctx, "run_o/checkpoint.pxc", "decay", hash, step, t, &w));
  if (!w) return;
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "case", PX_DTYPE_U8, strlen(text), text));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "driver.dt", PX_DTYPE_F64, 1, &dt));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "y", PX_DTYPE_F64, 16, y));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
}

/* A checkpoint with valid CRCs but hostile contents: a case that is not the
 * one its header's hash names, a step beyond any run or a time that does not
 * fit step x dt; refused as damaged, by name, before anything is built. */
static void test_forged_checkpoints_are_refused(struct px_context *ctx) {
  static char text[8192];
  struct px_sim *sim = run_steps(ctx, "run_o", 4, "");
  const char *more[] = {"time.steps=8"};
  struct px_checkpoint *ck = NULL;
  uint64_t hash = 0;
  double dt = 0;
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  dt = px_sim_dt(sim);
  px_sim_free(sim);
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, "run_o/checkpoint.pxc", &ck));
  if (!ck) return;
  hash = px_checkpoint_case_hash(ck);
  px_checkpoint_close(ck);
  PX_CHECK(slurp("run_o/case.yaml", text, sizeof text) > 0);
  /* the hash of the case text itself: the honest file resumes */
  forge_checkpoint(ctx, text, hash, 4, 4 * dt, dt);
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_o/checkpoint.pxc", more, 1, &sim));
  px_sim_free(sim);
  sim = NULL;
  forge_checkpoint(ctx, text, hash ^ 1u, 4, 4 * dt, dt);
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_o/checkpoint.pxc", more, 1, &sim), PX_STATUS_FORMAT);
  PX_CHECK(strstr(px_context_message(ctx), "does not match the case hash") != NULL);
  forge_checkpoint(ctx, text, hash, (uint64_t)1 << 63, 4 * dt, dt);
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_o/checkpoint.pxc", more, 1, &sim), PX_STATUS_FORMAT);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "damaged: step 9223372036854775808") != NULL, "%s",
               px_context_message(ctx));
  forge_checkpoint(ctx, text, hash, 4, NAN, dt);
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_o/checkpoint.pxc", more, 1, &sim), PX_STATUS_FORMAT);
  forge_checkpoint(ctx, text, hash, 4, 7 * dt, dt);
  PX_CHECK_STATUS(ctx, px_sim_open(ctx, "run_o/checkpoint.pxc", NULL, 0, PX_SIM_MODE_CHECK, &sim),
                  PX_STATUS_FORMAT);
  PX_CHECK(sim == NULL);
}

/* A run folder is its run's record (docs/running.md): a new run into a
 * folder that holds a run is refused before anything is written (what was
 * left by a run that failed before its first checkpoint may be replaced);
 * two runs cannot write one folder at once; a run resumes in its own folder
 * only; render takes picture settings only. */
static void test_a_run_folder_holds_one_run(struct px_context *ctx) {
  static char b_case[8192], a_case[8192], b_sum[8192], a_sum[8192], b_ck[1 << 16], a_ck[1 << 16];
  struct px_sim *sim = make_sim(ctx, "run_u", "", PX_SIM_MODE_RUN, PX_STATUS_OK), *two = NULL;
  const char *elsewhere[] = {"time.steps=30", "output.dir=run_u_copy"};
  const char *same[] = {"time.steps=22", "output.dir=run_u"};
  const char *state[] = {"decay.k=3"}, *dir[] = {"output.dir=run_u_copy"};
  long n1, n2, n3;
  if (!sim) return;
  /* a second run into the folder while the first is open (and holds its
     lock): refused, whoever started first */
  two = make_sim(ctx, "run_u", "", PX_SIM_MODE_RUN, PX_STATUS_CONFIG);
  PX_CHECK(two == NULL);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "run_u is being written by another partix"), "%s",
               px_context_message(ctx));
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  n1 = slurp("run_u/case.yaml", b_case, sizeof b_case);
  n2 = slurp("run_u/summary.json", b_sum, sizeof b_sum);
  n3 = slurp("run_u/checkpoint.pxc", b_ck, sizeof b_ck);
  PX_CHECK(n1 > 0 && n2 > 0 && n3 > 0);
  /* finished: a new run there is refused, naming the folder and the ways on */
  sim = make_sim(ctx, "run_u", ", k: 3", PX_SIM_MODE_RUN, PX_STATUS_CONFIG);
  PX_CHECK(sim == NULL);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "output.dir") &&
                   strstr(px_context_message(ctx), "run_u holds a run already") &&
                   strstr(px_context_message(ctx), "finished") &&
                   strstr(px_context_message(ctx), "partix resume run_u/checkpoint.pxc"),
               "%s", px_context_message(ctx));
  PX_CHECK(slurp("run_u/case.yaml", a_case, sizeof a_case) == n1 &&
           memcmp(a_case, b_case, (size_t)n1) == 0);
  PX_CHECK(slurp("run_u/summary.json", a_sum, sizeof a_sum) == n2 &&
           memcmp(a_sum, b_sum, (size_t)n2) == 0);
  PX_CHECK(slurp("run_u/checkpoint.pxc", a_ck, sizeof a_ck) == n3 &&
           memcmp(a_ck, b_ck, (size_t)n3) == 0);
  /* resumed into another folder: refused (that folder would hold the last
     part of the run only); into its own, named: runs */
  PX_CHECK_STATUS(ctx, px_sim_resume(ctx, "run_u/checkpoint.pxc", elsewhere, 2, &sim),
                  PX_STATUS_CONFIG);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "resumes in its own folder run_u") &&
                   strstr(px_context_message(ctx), "cp -a run_u run_u_copy"),
               "%s", px_context_message(ctx));
  PX_CHECK(!px_file_exists("run_u_copy"));
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "run_u/checkpoint.pxc", same, 2, &sim));
  if (sim) {
    /* while it holds the folder, a render of it is refused */
    PX_CHECK_OK(ctx, px_sim_open(ctx, "run_u/checkpoint.pxc", NULL, 0, PX_SIM_MODE_RENDER, &two));
    if (two) {
      PX_CHECK_STATUS(ctx, px_sim_render(two), PX_STATUS_CONFIG);
      PX_CHECK(strstr(px_context_message(ctx), "another partix process is writing") != NULL);
      px_sim_free(two);
      two = NULL;
    }
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    PX_CHECK(px_sim_step_index(sim) == 22);
  }
  px_sim_free(sim);
  sim = NULL;
  /* render: a state key or another folder is refused */
  PX_CHECK_STATUS(ctx, px_sim_open(ctx, "run_u/checkpoint.pxc", state, 1, PX_SIM_MODE_RENDER, &sim),
                  PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "render draws the state stored") != NULL);
  PX_CHECK_STATUS(ctx, px_sim_open(ctx, "run_u/checkpoint.pxc", dir, 1, PX_SIM_MODE_RENDER, &sim),
                  PX_STATUS_CONFIG);
  PX_CHECK(strstr(px_context_message(ctx), "output.dir cannot change") != NULL);
  PX_CHECK(sim == NULL && !px_file_exists("run_u_copy"));
  /* a run that failed before its first checkpoint left outputs and a
     run.log, the record of what happened: a new run there is refused too,
     without pointing to a checkpoint it does not have */
  sim = make_sim(ctx, "run_v", ", fail_at: 3", PX_SIM_MODE_RUN, PX_STATUS_OK);
  if (sim) PX_CHECK(px_sim_run(sim) != PX_STATUS_OK);
  px_sim_free(sim);
  PX_CHECK(!px_file_exists("run_v/checkpoint.pxc") && px_file_exists("run_v/summary.json"));
  sim = make_sim(ctx, "run_v", "", PX_SIM_MODE_RUN, PX_STATUS_CONFIG);
  PX_CHECK(sim == NULL);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "run_v holds a run already (summary.json: failed") &&
                   strstr(px_context_message(ctx), "partix resume") == NULL,
               "%s", px_context_message(ctx));
  /* one killed before its first checkpoint left case.yaml and run.log only */
  if (system("rm -f run_v/summary.json") != 0) return;
  sim = make_sim(ctx, "run_v", "", PX_SIM_MODE_RUN, PX_STATUS_CONFIG);
  PX_CHECK(sim == NULL && strstr(px_context_message(ctx), "stopped before its first checkpoint"));
  /* an empty folder, or one holding the user's own files, is taken */
  if (system("rm -rf run_v && mkdir run_v && echo notes > run_v/notes.txt") != 0) return;
  sim = make_sim(ctx, "run_v", "", PX_SIM_MODE_RUN, PX_STATUS_OK);
  if (sim) PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  PX_CHECK(px_file_exists("run_v/notes.txt") && px_file_exists("run_v/summary.json"));
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  /* start from nothing: stale outputs of an earlier run must not make a check pass */
  if (system("rm -rf run_a run_b run_c run_d run_e run_f run_g run_h run_h2 run_i run_j "
             "run_k run_l run_m run_n run_o run_p run_q run_r run_s run_t run_u run_u_copy "
             "run_v") != 0)
    return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  test_run_writes_outputs_on_schedule(ctx);
  test_resume_is_bit_identical(ctx);
  test_render_redraws_the_last_state(ctx);
  test_interrupt_writes_a_checkpoint(ctx);
  test_blow_up_names_step_and_last_checkpoint(ctx);
  test_check_mode_writes_nothing(ctx);
  test_end_time_sets_the_step_count(ctx);
  test_the_last_state_is_always_written(ctx);
  test_resume_drops_what_a_segment_end_added(ctx);
  test_resume_refuses_state_keys(ctx);
  test_resume_refuses_an_end_before_the_checkpoint(ctx);
  test_run_log_and_summary(ctx);
  test_render_changes_no_record(ctx);
  test_input_files_are_kept_in_the_run(ctx);
  test_done_ends_a_run_early(ctx);
  test_absurd_schedules_are_refused(ctx);
  test_forged_checkpoints_are_refused(ctx);
  test_memory_beyond_the_machine_is_refused(ctx);
  test_resume_finishes_a_run_killed_at_its_end(ctx);
  test_dead_writers_temporaries_are_swept(ctx);
  test_a_loop_of_steps_writes_what_run_writes(ctx);
  test_a_run_folder_holds_one_run(ctx);
  px_context_free(ctx);
  return px_test_report("test_sim_driver");
}
