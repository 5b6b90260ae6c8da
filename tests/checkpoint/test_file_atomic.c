/* Atomic file replacement and directory helpers (include/partix/file.h):
 * the target changes only at commit, abort and write errors leave the old
 * file and no temporary, two writers of one target do not share a
 * temporary, stale temporaries of dead writers are swept, mkdirs and join. */
#include <errno.h>
#include <signal.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "ck_util.h"
#include "partix/partix.h"

#define DIR_ "file_tmp"

static struct px_context *ctx;

/* 1 if `path` holds exactly `text`. */
static int holds(const char *path, const char *text) {
  size_t n = 0;
  unsigned char *data = ck_slurp(path, &n);
  int same = data && n == strlen(text) && memcmp(data, text, n) == 0;
  free(data);
  return same;
}

static void test_commit_replaces_the_target_only_at_commit(void) {
  const char *path = DIR_ "/out.txt";
  struct px_file *f = NULL;
  PX_CHECK_OK(ctx, px_file_write_all(ctx, path, "old", 3));
  PX_CHECK(holds(path, "old"));
  PX_CHECK_OK(ctx, px_file_open(ctx, path, &f));
  if (!f) return;
  fputs("new content", px_file_stream(f));
  fflush(px_file_stream(f));
  PX_CHECK(holds(path, "old")); /* not yet */
  PX_CHECK(ck_count_temps(DIR_, "out.txt") == 1);
  PX_CHECK_OK(ctx, px_file_commit(f));
  PX_CHECK(holds(path, "new content"));
  PX_CHECK(ck_count_temps(DIR_, "out.txt") == 0);
  /* write_all of nothing makes an empty file */
  PX_CHECK_OK(ctx, px_file_write_all(ctx, path, NULL, 0));
  PX_CHECK(holds(path, ""));
}

static void test_abort_keeps_the_old_file_and_removes_the_temporary(void) {
  const char *path = DIR_ "/keep.txt";
  struct px_file *f = NULL;
  PX_CHECK_OK(ctx, px_file_write_all(ctx, path, "old", 3));
  PX_CHECK_OK(ctx, px_file_open(ctx, path, &f));
  fputs("discarded", px_file_stream(f));
  px_file_abort(f);
  PX_CHECK(holds(path, "old"));
  PX_CHECK(ck_count_temps(DIR_, "keep.txt") == 0);
  px_file_abort(NULL);
  /* abort of a file that never existed leaves nothing */
  PX_CHECK_OK(ctx, px_file_open(ctx, DIR_ "/never.txt", &f));
  px_file_abort(f);
  PX_CHECK(!px_file_exists(DIR_ "/never.txt"));
  PX_CHECK(ck_count_temps(DIR_, "never.txt") == 0);
}

/* In a child limited to 1000 bytes per file: both ways a write can fail must
 * give PX_STATUS_IO naming the target and leave the old file alone. */
static void child_with_small_file_limit(const char *path) {
  struct rlimit rl;
  struct px_file *f = NULL;
  char *big = calloc(1, 100000);
  rl.rlim_cur = rl.rlim_max = 1000;
  signal(SIGXFSZ, SIG_IGN);
  if (!big || setrlimit(RLIMIT_FSIZE, &rl) != 0) _exit(5);
  /* the write itself fails */
  PX_CHECK_STATUS(ctx, px_file_write_all(ctx, path, big, 100000), PX_STATUS_IO);
  PX_CHECK(ck_contains(px_context_message(ctx), path));
  PX_CHECK(ck_contains(px_context_message(ctx), strerror(EFBIG)));
  /* buffered writes that fail only when commit flushes them */
  PX_CHECK_OK(ctx, px_file_open(ctx, path, &f));
  if (f) {
    fwrite(big, 1, 2000, px_file_stream(f));
    PX_CHECK_STATUS(ctx, px_file_commit(f), PX_STATUS_IO);
    PX_CHECK(ck_contains(px_context_message(ctx), "the previous file, if any, is kept"));
  }
  free(big);
  fflush(stderr);
  _exit(px_test_failures ? 1 : 0);
}

static void test_write_errors_keep_the_old_file(void) {
  const char *path = DIR_ "/limited.txt";
  int status = 0;
  pid_t pid;
  PX_CHECK_OK(ctx, px_file_write_all(ctx, path, "old", 3));
  pid = fork();
  if (pid == 0) child_with_small_file_limit(path);
  PX_CHECK(pid > 0);
  waitpid(pid, &status, 0);
  PX_CHECK_MSG(WIFEXITED(status) && WEXITSTATUS(status) == 0, "child status %d", status);
  PX_CHECK(holds(path, "old"));
  PX_CHECK(ck_count_temps(DIR_, "limited.txt") == 0);
}

static void test_failed_rename_keeps_the_target_and_no_temporary(void) {
  /* a non-empty directory cannot be replaced by a file */
  struct px_file *f = NULL;
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, DIR_ "/adir/inside"));
  PX_CHECK_OK(ctx, px_file_open(ctx, DIR_ "/adir", &f));
  fputs("x", px_file_stream(f));
  PX_CHECK_STATUS(ctx, px_file_commit(f), PX_STATUS_IO);
  PX_CHECK(ck_contains(px_context_message(ctx), "cannot write " DIR_ "/adir"));
  PX_CHECK(ck_count_temps(DIR_, "adir") == 0);
  PX_CHECK(px_file_exists(DIR_ "/adir/inside"));
}

static void test_open_in_a_missing_directory_names_the_target(void) {
  struct px_file *f = NULL;
  PX_CHECK_STATUS(ctx, px_file_open(ctx, DIR_ "/missing/x.txt", &f), PX_STATUS_IO);
  PX_CHECK(f == NULL);
  PX_CHECK(ck_contains(px_context_message(ctx), "cannot write " DIR_ "/missing/x.txt"));
  PX_CHECK(ck_contains(px_context_message(ctx), strerror(ENOENT)));
}

/* Two writers of one target in one process used to share "path.tmp-PID":
 * the second truncated the first's data. Each must commit its own content. */
static void test_two_writers_of_one_target_do_not_share_a_temporary(void) {
  const char *path = DIR_ "/shared.txt";
  struct px_file *f1 = NULL, *f2 = NULL;
  PX_CHECK_OK(ctx, px_file_open(ctx, path, &f1));
  PX_CHECK_OK(ctx, px_file_open(ctx, path, &f2));
  if (!f1 || !f2) return;
  PX_CHECK(ck_count_temps(DIR_, "shared.txt") == 2);
  fputs("first writer, longer text", px_file_stream(f1));
  fflush(px_file_stream(f1));
  fputs("second", px_file_stream(f2));
  PX_CHECK_OK(ctx, px_file_commit(f2));
  PX_CHECK(holds(path, "second"));
  PX_CHECK_OK(ctx, px_file_commit(f1));
  PX_CHECK(holds(path, "first writer, longer text"));
  PX_CHECK(ck_count_temps(DIR_, "shared.txt") == 0);
}

static void touch(const char *path) { ck_spit(path, "t", 1); }

static void test_stale_temporaries_of_dead_writers_are_removed(void) {
  char name[256];
  int status = 0;
  long dead, self = (long)getpid(), parent = (long)getppid();
  pid_t pid = fork();
  if (pid == 0) _exit(0);
  waitpid(pid, &status, 0);
  dead = (long)pid; /* reaped: no such process any more */
  PX_CHECK_OK(ctx, px_file_write_all(ctx, DIR_ "/state.chk", "x", 1));
#define MAKE_(fmt, value)                             \
  do {                                                \
    snprintf(name, sizeof name, DIR_ "/" fmt, value); \
    touch(name);                                      \
  } while (0)
  MAKE_("state.chk.tmp-%ld", dead);     /* removed */
  MAKE_("state.chk.tmp-%ld-3", dead);   /* removed */
  MAKE_("state.chk.tmp-%ld-0", self);   /* ours: kept */
  MAKE_("state.chk.tmp-%ld", parent);   /* alive: kept */
  MAKE_("state.chk.tmp-%ld-x", dead);   /* not a temporary name: kept */
  MAKE_("state.chk.tmp-%s", "abc");     /* kept */
  MAKE_("other.chk.tmp-%ld", dead);     /* another target: kept */
  MAKE_("state.chk.old.tmp-%ld", dead); /* another target: kept */
#undef MAKE_
  PX_CHECK(ck_count_temps(DIR_, "state.chk") == 6);
  PX_CHECK(px_file_remove_stale(ctx, DIR_ "/state.chk") == 2);
  PX_CHECK(ck_count_temps(DIR_, "state.chk") == 4);
  snprintf(name, sizeof name, DIR_ "/state.chk.tmp-%ld", dead);
  PX_CHECK(!px_file_exists(name));
  snprintf(name, sizeof name, DIR_ "/state.chk.tmp-%ld-0", self);
  PX_CHECK(px_file_exists(name));
  snprintf(name, sizeof name, DIR_ "/other.chk.tmp-%ld", dead);
  PX_CHECK(px_file_exists(name));
  PX_CHECK(holds(DIR_ "/state.chk", "x"));
  /* nothing to do, and paths without a directory part */
  PX_CHECK(px_file_remove_stale(ctx, DIR_ "/state.chk") == 0);
  PX_CHECK(px_file_remove_stale(ctx, "no-such-file-here.chk") == 0);
  PX_CHECK(px_file_remove_stale(ctx, DIR_ "/nodir/x") == 0);
}

static int is_dir(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

static void test_mkdirs_creates_nested_directories(void) {
  char abs_path[4096];
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, DIR_ "/m/a/b/c"));
  PX_CHECK(is_dir(DIR_ "/m/a") && is_dir(DIR_ "/m/a/b") && is_dir(DIR_ "/m/a/b/c"));
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, DIR_ "/m/a/b/c")); /* exists: fine */
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, DIR_ "/m/x//y/")); /* doubled and trailing slash */
  PX_CHECK(is_dir(DIR_ "/m/x/y"));
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, ""));
  PX_CHECK(getcwd(abs_path, sizeof abs_path - 64) != NULL);
  strcat(abs_path, "/" DIR_ "/m/abs/olute");
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, abs_path));
  PX_CHECK(is_dir(DIR_ "/m/abs/olute"));
  /* a file in the way */
  touch(DIR_ "/m/file");
  PX_CHECK_STATUS(ctx, px_file_mkdirs(ctx, DIR_ "/m/file/sub"), PX_STATUS_IO);
  PX_CHECK(ck_contains(px_context_message(ctx), DIR_ "/m/file exists and is not a directory"));
  PX_CHECK_STATUS(ctx, px_file_mkdirs(ctx, NULL), PX_STATUS_INVALID);
}

static void test_join_and_exists(void) {
  char buf[16];
  PX_CHECK_OK(ctx, px_file_join(ctx, buf, sizeof buf, "dir", "name"));
  PX_CHECK(strcmp(buf, "dir/name") == 0);
  PX_CHECK_OK(ctx, px_file_join(ctx, buf, sizeof buf, "dir/", "name"));
  PX_CHECK(strcmp(buf, "dir/name") == 0);
  PX_CHECK_OK(ctx, px_file_join(ctx, buf, sizeof buf, "", "name"));
  PX_CHECK(strcmp(buf, "name") == 0);
  PX_CHECK_OK(ctx, px_file_join(ctx, buf, sizeof buf, ".", "name"));
  PX_CHECK(strcmp(buf, "name") == 0);
  PX_CHECK_OK(ctx, px_file_join(ctx, buf, sizeof buf, NULL, "name"));
  PX_CHECK(strcmp(buf, "name") == 0);
  PX_CHECK_OK(ctx, px_file_join(ctx, buf, sizeof buf, "/", "x"));
  PX_CHECK(strcmp(buf, "/x") == 0);
  /* 15 characters fit in 16 bytes, 16 do not */
  PX_CHECK_OK(ctx, px_file_join(ctx, buf, sizeof buf, "abcdefg", "hijklmn"));
  PX_CHECK(strcmp(buf, "abcdefg/hijklmn") == 0);
  PX_CHECK_STATUS(ctx, px_file_join(ctx, buf, sizeof buf, "abcdefg", "hijklmno"),
                  PX_STATUS_INVALID);
  PX_CHECK(ck_contains(px_context_message(ctx), "path too long"));
  PX_CHECK_STATUS(ctx, px_file_join(ctx, buf, sizeof buf, "d", NULL), PX_STATUS_INVALID);
  PX_CHECK(px_file_exists(DIR_));
  PX_CHECK(!px_file_exists(DIR_ "/nothing"));
  PX_CHECK(!px_file_exists(NULL));
}

/* Symbolic links planted where the writer's temporaries go (this process's
 * next 50 predictable names) and at the target itself: nothing is written
 * through them; the victim file keeps its content, the planted names are
 * skipped, the target becomes a regular file holding the new data. */
static void test_planted_links_are_never_followed(void) {
  const char *path = DIR_ "/planted.txt", *victim = DIR_ "/victim.txt";
  char name[512];
  struct stat st;
  long k, pid = (long)getpid();
  PX_CHECK_OK(ctx, px_file_write_all(ctx, victim, "precious", 8));
  for (k = 0; k < 2000; ++k) { /* the sequence so far is small; cover well past it */
    snprintf(name, sizeof name, "%s.tmp-%ld-%ld", path, pid, k);
    PX_CHECK(symlink("victim.txt", name) == 0);
  }
  PX_CHECK(symlink("victim.txt", path) == 0);
  PX_CHECK_STATUS(ctx, px_file_write_all(ctx, path, "new data", 8), PX_STATUS_IO);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "names before it are taken") != NULL, "%s",
               px_context_message(ctx));
  PX_CHECK(holds(victim, "precious"));
  /* with a few names left free the write succeeds, still without following */
  for (k = 1000; k < 2000; ++k) {
    snprintf(name, sizeof name, "%s.tmp-%ld-%ld", path, pid, k);
    remove(name);
  }
  PX_CHECK_OK(ctx, px_file_write_all(ctx, path, "new data", 8));
  PX_CHECK(holds(victim, "precious"));
  PX_CHECK(lstat(path, &st) == 0 && S_ISREG(st.st_mode));
  PX_CHECK(holds(path, "new data"));
  for (k = 0; k < 1000; ++k) {
    snprintf(name, sizeof name, "%s.tmp-%ld-%ld", path, pid, k);
    remove(name);
  }
}

int main(void) {
  px_context_create(&ctx);
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  ck_scratch(DIR_);
  test_commit_replaces_the_target_only_at_commit();
  test_abort_keeps_the_old_file_and_removes_the_temporary();
  test_write_errors_keep_the_old_file();
  test_failed_rename_keeps_the_target_and_no_temporary();
  test_open_in_a_missing_directory_names_the_target();
  test_two_writers_of_one_target_do_not_share_a_temporary();
  test_stale_temporaries_of_dead_writers_are_removed();
  test_mkdirs_creates_nested_directories();
  test_join_and_exists();
  test_planted_links_are_never_followed();
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  ck_rm_rf(DIR_);
  return px_test_report("test_file_atomic");
}
