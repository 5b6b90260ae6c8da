/* A full disk while writing a checkpoint (simulated with RLIMIT_FSIZE in a
 * child process, SIGXFSZ ignored so that writes fail with EFBIG): the writer
 * reports PX_STATUS_IO with a message, the previous checkpoint still loads and
 * no temporary is left, whether the failure shows in a large write or only
 * when buffered data are flushed at commit. */
#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include "ck_util.h"
#include "partix/partix.h"

#define DIR_ "disk_full_tmp"
#define PATH_ DIR_ "/run.chk"

static struct px_context *ctx;

static void write_good(void) {
  struct px_checkpoint_writer *w = NULL;
  double v[3] = {1.0, 2.0, 3.0};
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, PATH_, "granular", 1, 41, 4.1, &w));
  PX_CHECK_OK(ctx, px_checkpoint_write(w, "v", PX_DTYPE_F64, 3, v));
  PX_CHECK_OK(ctx, px_checkpoint_writer_commit(w));
}

static void check_good_is_intact(void) {
  struct px_checkpoint *ck = NULL;
  double v[3] = {0, 0, 0};
  PX_CHECK_OK(ctx, px_checkpoint_open(ctx, PATH_, &ck));
  PX_CHECK(px_checkpoint_step(ck) == 41);
  PX_CHECK_OK(ctx, px_checkpoint_read(ck, "v", PX_DTYPE_F64, 3, v));
  PX_CHECK(v[0] == 1.0 && v[1] == 2.0 && v[2] == 3.0);
  px_checkpoint_close(ck);
  PX_CHECK(ck_count_temps(DIR_, "run.chk") == 0);
}

/* In a child limited to `limit` bytes per file: write `sections` sections of
 * `count` doubles over PATH_ and expect an I/O error that names the file. */
static void child_writes_too_much(rlim_t limit, int sections, size_t count) {
  struct rlimit rl;
  struct px_checkpoint_writer *w = NULL;
  double *v = calloc(count, sizeof *v);
  enum px_status s = PX_STATUS_OK;
  int i;
  rl.rlim_cur = rl.rlim_max = limit;
  signal(SIGXFSZ, SIG_IGN);
  if (setrlimit(RLIMIT_FSIZE, &rl) != 0) _exit(5);
  PX_CHECK_OK(ctx, px_checkpoint_writer_open(ctx, PATH_, "granular", 1, 42, 4.2, &w));
  if (!w) _exit(6);
  for (i = 0; i < sections && s == PX_STATUS_OK; ++i) {
    char name[16];
    snprintf(name, sizeof name, "s%d", i);
    s = px_checkpoint_write(w, name, PX_DTYPE_F64, count, v);
  }
  if (s == PX_STATUS_OK) {
    s = px_checkpoint_writer_commit(w); /* frees w */
  } else {
    PX_CHECK(ck_contains(px_context_message(ctx), "cannot write checkpoint: "));
    /* a failed writer refuses to commit */
    PX_CHECK_STATUS(ctx, px_checkpoint_writer_commit(w), PX_STATUS_IO);
  }
  PX_CHECK_MSG(s == PX_STATUS_IO, "status %s: %s", px_status_name(s), px_context_message(ctx));
  PX_CHECK_MSG(ck_contains(px_context_message(ctx), PATH_) &&
                   ck_contains(px_context_message(ctx), strerror(EFBIG)),
               "message: %s", px_context_message(ctx));
  printf("child: %s\n", px_context_message(ctx));
  fflush(stdout);
  free(v);
  _exit(px_test_failures ? 1 : 0);
}

static void run_child(rlim_t limit, int sections, size_t count) {
  int status = 0;
  pid_t pid;
  fflush(stdout);
  pid = fork();
  if (pid == 0) child_writes_too_much(limit, sections, count);
  PX_CHECK(pid > 0);
  waitpid(pid, &status, 0);
  PX_CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "child status %d", status);
}

static void test_a_full_disk_during_a_large_write_keeps_the_old_checkpoint(void) {
  run_child(1 << 20, 1, (size_t)1 << 20); /* 8 MB section, 1 MB allowed */
  check_good_is_intact();
}

static void test_a_full_disk_at_the_final_flush_keeps_the_old_checkpoint(void) {
  /* small sections stay in the stdio buffer until commit flushes them */
  run_child(600, 10, 8);
  check_good_is_intact();
}

int main(void) {
  px_context_create(&ctx);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  ck_scratch(DIR_);
  write_good();
  check_good_is_intact();
  test_a_full_disk_during_a_large_write_keeps_the_old_checkpoint();
  test_a_full_disk_at_the_final_flush_keeps_the_old_checkpoint();
  px_context_free(ctx);
  ck_rm_rf(DIR_);
  return px_test_report("test_checkpoint_disk_full");
}
