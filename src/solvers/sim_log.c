/* The run driver: run.log, the log of every message of a run. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "partix/memory.h"
#include "solvers/sim_impl.h"

void px_sim_log_append(struct px_sim *sim, const char *text, size_t n) {
  if (sim->log) {
    fwrite(text, 1, n, sim->log);
    fflush(sim->log);
    return;
  }
  if (sim->loglen + n + 1 > sim->logcap) {
    size_t cap = sim->logcap ? sim->logcap : 4096;
    char *grown;
    while (cap < sim->loglen + n + 1) cap *= 2;
    if (cap > (size_t)16 << 20) return; /* never opened: keep the first 16 MiB */
    grown = px_mem_realloc(sim->ctx, "run log", sim->logbuf, cap);
    if (!grown) return;
    sim->logbuf = grown;
    sim->logcap = cap;
  }
  memcpy(sim->logbuf + sim->loglen, text, n);
  sim->loglen += n;
}

/* One line of run.log: "2026-11-26 17:40:01 warning: message". */
void px_sim_log_line(struct px_sim *sim, enum px_log_level level, const char *message) {
  char line[2300], stamp[32];
  time_t now = time(NULL);
  struct tm tm;
  int n;
  if (localtime_r(&now, &tm))
    strftime(stamp, sizeof stamp, "%Y-%m-%d %H:%M:%S", &tm);
  else
    snprintf(stamp, sizeof stamp, "-");
  n = snprintf(line, sizeof line, "%s %s: %s\n", stamp, px_log_level_name(level), message);
  if (n < 0) return;
  if ((size_t)n >= sizeof line) n = (int)sizeof line - 1;
  px_sim_log_append(sim, line, (size_t)n);
}

/* The context's log callback while a run is open: every message at INFO or
 * the console's level goes to run.log; the console gets what it asked for. */
static void px_sim_tee(void *user, enum px_log_level level, const char *message) {
  struct px_sim *sim = user;
  if (level <= PX_LOG_LEVEL_INFO || level <= sim->console_level)
    px_sim_log_line(sim, level, message);
  if (level > sim->console_level) return;
  if (sim->log_prev_fn)
    sim->log_prev_fn(sim->log_prev_user, level, message);
  else if (level == PX_LOG_LEVEL_INFO)
    fprintf(stderr, "%s\n", message);
  else
    fprintf(stderr, "%s: %s\n", px_log_level_name(level), message);
}

void px_sim_tee_install(struct px_sim *sim) {
  px_context_get_log(sim->ctx, &sim->log_prev_fn, &sim->log_prev_user);
  sim->console_level = px_context_log_level(sim->ctx);
  if (sim->console_level < PX_LOG_LEVEL_INFO) px_context_set_log_level(sim->ctx, PX_LOG_LEVEL_INFO);
  px_context_set_log(sim->ctx, px_sim_tee, sim);
  sim->log_tee = 1;
}

void px_sim_tee_remove(struct px_sim *sim) {
  if (!sim->log_tee) return;
  px_context_set_log(sim->ctx, sim->log_prev_fn, sim->log_prev_user);
  px_context_set_log_level(sim->ctx, sim->console_level);
  sim->log_tee = 0;
}

/* Open RUN_DIR/run.log for appending (never through a symbolic link) and
 * write out what was logged before the folder existed. */
enum px_status px_sim_log_open(struct px_sim *sim) {
  char path[PX_SIM_PATH_MAX];
  int fd;
  PX_TRY(px_sim_output_path(sim, "run.log", path, sizeof path));
  fd = open(path, O_WRONLY | O_CREAT | O_APPEND | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0)
    return px_context_fail(sim->ctx, PX_STATUS_IO, "cannot open the run log %s: %s", path,
                           strerror(errno));
  sim->log = fdopen(fd, "a");
  if (!sim->log) {
    close(fd);
    return px_context_fail(sim->ctx, PX_STATUS_IO, "cannot open the run log %s", path);
  }
  if (sim->loglen) fwrite(sim->logbuf, 1, sim->loglen, sim->log);
  fflush(sim->log);
  px_mem_free(sim->ctx, sim->logbuf);
  sim->logbuf = NULL;
  sim->loglen = sim->logcap = 0;
  return PX_STATUS_OK;
}
