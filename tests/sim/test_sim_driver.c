/* The run driver with a test solver: output schedule, checkpoints, resume
 * bit-identical to an uninterrupted run, Ctrl-C, blow-up diagnosis, check
 * mode, end time. The test replaces the solver registry at link time (its
 * definitions come before libpartix.a, so registry.o is not linked). */
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>

#include "px_test.h"
#include "solvers/solver.h"

/* ---- the test solver: n values relaxing by y' = -k (y - sin(i)) with explicit
 * Euler; `fail_at` makes a step fail like a blow-up. */
struct decay {
  struct px_sim *sim;
  long n, fail_at, interrupt_at;
  double k;
  double *y; /* owned */
};

/* Outputs the driver asked for in the current run. */
static struct {
  long series, snapshots, pictures;
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

static enum px_status decay_series(void *state, const struct px_sim_output *o) {
  (void)state;
  (void)o;
  outputs_seen.series++;
  return PX_STATUS_OK;
}

static enum px_status decay_snapshot(void *state, const struct px_sim_output *o) {
  (void)state;
  (void)o;
  outputs_seen.snapshots++;
  return PX_STATUS_OK;
}

static enum px_status decay_picture(void *state, const struct px_sim_output *o) {
  (void)state;
  (void)o;
  outputs_seen.pictures++;
  return PX_STATUS_OK;
}

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
};

static const struct px_schema decay_keys[] = {
    PX_KEY_INT("n", "number of values", PX_DEFAULT("100"), PX_GE(1)),
    PX_KEY_REAL("k", "rate [1/s]", PX_DEFAULT("2.0"), PX_GT(0)),
    PX_KEY_INT("fail_at", "step that fails (0 = none)", PX_DEFAULT("0"), PX_GE(0)),
    PX_KEY_INT("interrupt_at", "step after which Ctrl-C is simulated", PX_DEFAULT("0"), PX_GE(0)),
    PX_KEY_END};

/* The link-time replacement of src/solvers/registry.c. */
const struct px_schema px_case_solver_sections[] = {
    PX_KEY_MAP("decay", decay_keys, "test solver"), PX_KEY_END};

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

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  /* start from nothing: stale outputs of an earlier run must not make a check pass */
  if (system("rm -rf run_a run_b run_c run_d run_e run_f") != 0) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  test_run_writes_outputs_on_schedule(ctx);
  test_resume_is_bit_identical(ctx);
  test_render_redraws_the_last_state(ctx);
  test_interrupt_writes_a_checkpoint(ctx);
  test_blow_up_names_step_and_last_checkpoint(ctx);
  test_check_mode_writes_nothing(ctx);
  test_end_time_sets_the_step_count(ctx);
  px_context_free(ctx);
  return px_test_report("test_sim_driver");
}
