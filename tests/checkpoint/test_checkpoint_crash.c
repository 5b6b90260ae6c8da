/* Crash safety: a child rewrites a checkpoint of several MB over and over
 * (each generation distinguishable), the parent kills it with SIGKILL at 20
 * different moments; after every kill the file at the path must validate and
 * hold one complete generation, never going back in time. Temporaries left
 * by the killed writers are swept by the next writer. */
#include <signal.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>

#include "ck_util.h"
#include "partix/partix.h"

#define DIR_ "crash_tmp"
#define PATH_ DIR_ "/state.chk"
#define N ((size_t)3 << 17) /* 3 MiB of f64 + 1.5 MiB of u32 per generation */
#define ROUNDS 20

static struct px_context *ctx;
static double *a;
static uint32_t *b;

static double a_value(uint64_t g, size_t i) { return (double)g * 1e7 + (double)i; }
static uint32_t b_value(uint64_t g, size_t i) { return (uint32_t)(g * 2654435761u) ^ (uint32_t)i; }

static enum px_status write_generation(uint64_t g) {
  struct px_checkpoint_writer *w = NULL;
  enum px_status s;
  size_t i, done;
  for (i = 0; i < N; ++i) {
    a[i] = a_value(g, i);
    b[i] = b_value(g, i);
  }
  PX_TRY(px_checkpoint_writer_open(ctx, PATH_, "granular", 99, g, 0.5 * (double)g, &w));
  s = px_checkpoint_write(w, "gen", PX_DTYPE_U64, 1, &g);
  if (s == PX_STATUS_OK) s = px_checkpoint_write_begin(w, "a", PX_DTYPE_F64, N);
  for (done = 0; s == PX_STATUS_OK && done < N; done += 65536)
    s = px_checkpoint_write_chunk(w, a + done, N - done < 65536 ? N - done : 65536);
  if (s == PX_STATUS_OK) s = px_checkpoint_write_end(w);
  if (s == PX_STATUS_OK) s = px_checkpoint_write(w, "b", PX_DTYPE_U32, N, b);
  if (s == PX_STATUS_OK) s = px_checkpoint_write(w, "gen_again", PX_DTYPE_U64, 1, &g);
  if (s != PX_STATUS_OK) {
    px_checkpoint_writer_abort(w);
    return s;
  }
  return px_checkpoint_writer_commit(w);
}

/* Load PATH_ and check it holds one whole generation; returns it or -1. */
static long long load_generation(void) {
  struct px_checkpoint *ck = NULL;
  uint64_t g = 0, g2 = 1;
  size_t i, wrong = 0;
  long long result = -1;
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, PATH_, &ck));
  if (!ck) return -1;
  PX_CHECK_OK(ctx, px_checkpoint_read(ck, "gen", PX_DTYPE_U64, 1, &g));
  PX_CHECK_OK(ctx, px_checkpoint_read(ck, "gen_again", PX_DTYPE_U64, 1, &g2));
  PX_CHECK_OK(ctx, px_checkpoint_read(ck, "a", PX_DTYPE_F64, N, a));
  PX_CHECK_OK(ctx, px_checkpoint_read(ck, "b", PX_DTYPE_U32, N, b));
  for (i = 0; i < N; ++i) wrong += a[i] != a_value(g, i) || b[i] != b_value(g, i);
  PX_CHECK_MSG(g == g2 && px_checkpoint_step(ck) == g && wrong == 0,
               "mixed generations: gen %llu, gen_again %llu, step %llu, %zu wrong elements",
               (unsigned long long)g, (unsigned long long)g2,
               (unsigned long long)px_checkpoint_step(ck), wrong);
  if (g == g2 && wrong == 0) result = (long long)g;
  px_checkpoint_close(ck);
  return result;
}

static void sleep_seconds(double s) {
  struct timespec t;
  t.tv_sec = (time_t)s;
  t.tv_nsec = (long)((s - (double)t.tv_sec) * 1e9);
  while (nanosleep(&t, &t) != 0) {
  }
}

static void test_a_killed_writer_never_leaves_a_torn_checkpoint(void) {
  double t0, t_write;
  long long last;
  int round, advanced = 0, killed_mid_write = 0, temps;
  PX_CHECK_OK(ctx, write_generation(0));
  t0 = px_time_now();
  PX_CHECK_OK(ctx, write_generation(1));
  t_write = px_time_now() - t0;
  last = load_generation();
  PX_CHECK(last == 1);
  printf("one generation (%.1f MB) written in %.1f ms\n", (double)N * (sizeof *a + sizeof *b) / 1e6,
         1e3 * t_write);
  /* ROUNDS kills from early in the first write to the middle of the third;
   * if the machine's pace changed so much that no kill fell inside a write,
   * or none after a commit, up to 10 more rounds aim at what is missing. */
  for (round = 0; round < ROUNDS || (round < ROUNDS + 10 && (!advanced || !killed_mid_write));
       ++round) {
    double delay = t_write * 2.5 * (round + 1) / ROUNDS;
    uint64_t first = 1000 * (uint64_t)(round + 1);
    int status = 0, extra = round - ROUNDS;
    long long g;
    pid_t pid;
    if (extra >= 0)
      delay = !advanced ? t_write * (double)(2 << (extra < 5 ? extra : 5)) : 0.1 * t_write;
    pid = fork();
    if (pid == 0) {
      uint64_t gen;
      for (gen = first;; ++gen)
        if (write_generation(gen) != PX_STATUS_OK) _exit(3);
    }
    PX_CHECK(pid > 0);
    if (pid <= 0) return;
    sleep_seconds(delay);
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    PX_CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL,
                 "round %d: the writer ended by itself (status %d)", round, status);
    temps = ck_count_temps(DIR_, "state.chk");
    PX_CHECK_MSG(temps <= 1, "round %d: %d temporaries", round, temps);
    if (temps > 0) ++killed_mid_write;
    g = load_generation();
    /* the previous generation, or a newer one that this child wrote */
    PX_CHECK_MSG(g == last || (g >= (long long)first && g < (long long)first + 1000),
                 "round %d: generation %lld after %lld", round, g, last);
    if (g != last) ++advanced;
    if (g >= 0) last = g;
  }
  printf("%d of %d kills left a temporary behind; %d rounds committed a generation\n",
         killed_mid_write, round, advanced);
  /* both outcomes must have happened, or the test did not test anything */
  PX_CHECK(advanced >= 1);
  PX_CHECK(killed_mid_write >= 1);

  /* A writer killed right after its first section leaves its temporary;
   * the next writer removes it (and the killed children's before, which is
   * why at most one was ever found above). */
  {
    struct px_checkpoint_writer *w = NULL;
    int status = 0;
    pid_t pid = fork();
    if (pid == 0) {
      uint64_t g = 7;
      if (px_checkpoint_writer_open(ctx, PATH_, "granular", 99, 7, 7.0, &w) == PX_STATUS_OK &&
          px_checkpoint_write(w, "gen", PX_DTYPE_U64, 1, &g) == PX_STATUS_OK)
        raise(SIGKILL);
      _exit(4);
    }
    PX_CHECK(pid > 0);
    waitpid(pid, &status, 0);
    PX_CHECK(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
    PX_CHECK(ck_count_temps(DIR_, "state.chk") >= 1);
    PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, PATH_, "granular", 99, 5, 5.0, &w));
    PX_CHECK(ck_count_temps(DIR_, "state.chk") == 1); /* its own */
    px_checkpoint_writer_abort(w);
  }
  PX_CHECK(ck_count_temps(DIR_, "state.chk") == 0);
  PX_CHECK(load_generation() == last);
}

int main(void) {
  px_context_create(&ctx);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  ck_scratch(DIR_);
  a = malloc(N * sizeof *a);
  b = malloc(N * sizeof *b);
  test_a_killed_writer_never_leaves_a_torn_checkpoint();
  free(a);
  free(b);
  px_context_free(ctx);
  ck_rm_rf(DIR_);
  return px_test_report("test_checkpoint_crash");
}
