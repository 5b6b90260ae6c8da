/* partix sweep, its runs (sweep.c): what to do with each run's folder (run,
 * resume, skip or refuse: px_sweep_decide), the runs started as child
 * processes and waited on (px_sweep_local, at most --jobs at a time, Ctrl-C
 * forwarded) or handed out to the ranks of an MPI sweep (px_sweep_mpi),
 * and the table and last line once they are done (px_sweep_finish). */
#include <errno.h>
#include <fcntl.h>
#include <libfyaml.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef __linux__
#include <sys/prctl.h>
#endif

#include "cli/cli.h"
#include "cli/sweep.h"
#include "partix/partix.h"

#ifdef PX_HAVE_MPI
#include <mpi.h>
#endif

/* The status in RUN/summary.json ("" when there is none). */
static void px_sweep_run_status(const char *rundir, char *buf, size_t size) {
  char path[4500];
  struct fy_document *d;
  const char *st;
  buf[0] = '\0';
  snprintf(path, sizeof path, "%s/summary.json", rundir);
  if (!px_file_exists(path)) return;
  d = fy_document_build_from_file(NULL, path);
  st = px_sweep_scalar(px_cli_json_get(d ? fy_document_root(d) : NULL, "status"));
  if (st) snprintf(buf, size, "%s", st);
  if (d) fy_document_destroy(d);
}

/* What a sweep does with a run's folder when it comes to the run. */
enum px_sweep_action {
  PX_SWEEP_ACTION_RUN,    /* no run there: run it anew */
  PX_SWEEP_ACTION_RESUME, /* an unfinished run of these settings with a checkpoint */
  PX_SWEEP_ACTION_DONE    /* finished before, or refused: run->status says which */
};

/* DIR/.NAME.fingerprint: the fingerprint run r was started with. 0 when
 * the file is missing or unreadable. */
static int px_sweep_fingerprint_read(const struct px_sweep *s, size_t r, uint64_t *out) {
  char path[4500];
  unsigned long long v = 0;
  FILE *f;
  int ok;
  snprintf(path, sizeof path, "%s/.%s.fingerprint", s->dir, s->runs[r].name);
  f = fopen(path, "r");
  if (!f) return 0;
  ok = fscanf(f, "%16llx", &v) == 1;
  fclose(f);
  *out = (uint64_t)v;
  return ok;
}

/* Decide what to do with run r's folder. A folder that holds a run
 * (summary.json or a checkpoint) is skipped or resumed only when it was
 * made with the same settings (its recorded fingerprint equals the run's):
 * otherwise the sweep's case or overrides changed since, and skipping it
 * would table old results as new ones, resuming it would drop the new
 * overrides. Such a folder is left alone (it holds the user's results) and
 * the run recorded as failed. A fresh run's fingerprint is recorded before
 * it starts, so that a run killed halfway is recognised too. */
static enum px_sweep_action px_sweep_decide(struct px_sweep *s, size_t r, struct px_context *ctx) {
  struct px_sweep_run *run = &s->runs[r];
  char rundir[4400], ck[4500], sum[4500], path[4500], status[32], text[32];
  uint64_t recorded = 0;
  snprintf(rundir, sizeof rundir, "%s/%s", s->dir, run->name);
  snprintf(ck, sizeof ck, "%s/checkpoint.pxc", rundir);
  snprintf(sum, sizeof sum, "%s/summary.json", rundir);
  if (px_file_exists(sum) || px_file_exists(ck)) {
    if (!px_sweep_fingerprint_read(s, r, &recorded) || recorded != run->fingerprint) {
      run->foreign = 1;
      snprintf(run->status, sizeof run->status, "failed");
      snprintf(run->error, sizeof run->error,
               "%.300s was made with other settings (the sweep's case or its overrides changed): "
               "remove it to run it again, or give the sweep another dir",
               rundir);
      return PX_SWEEP_ACTION_DONE;
    }
    px_sweep_run_status(rundir, status, sizeof status);
    if (strcmp(status, "finished") == 0) {
      snprintf(run->status, sizeof run->status, "finished");
      run->exit = 0;
      return PX_SWEEP_ACTION_DONE;
    }
    if (px_file_exists(ck)) return PX_SWEEP_ACTION_RESUME;
    /* a run that did not finish and left no checkpoint (it failed before
       its first one, or checkpoints are off): `partix run` does not take a
       folder that holds a run's record */
    snprintf(run->status, sizeof run->status, "failed");
    snprintf(run->error, sizeof run->error,
             "%.300s holds a run that did not finish (status '%s') and no checkpoint to resume "
             "from: remove it to run it again",
             rundir, status[0] ? status : "unknown");
    return PX_SWEEP_ACTION_DONE;
  }
  snprintf(path, sizeof path, "%s/.%s.fingerprint", s->dir, run->name);
  snprintf(text, sizeof text, "%016llx\n", (unsigned long long)run->fingerprint);
  if (px_file_write_all(ctx, path, text, strlen(text)) != PX_STATUS_OK) {
    snprintf(run->status, sizeof run->status, "failed");
    snprintf(run->error, sizeof run->error, "cannot start: %s", px_context_message(ctx));
    return PX_SWEEP_ACTION_DONE;
  }
  return PX_SWEEP_ACTION_RUN;
}

/* Start run r: `partix -q run BASE --out DIR --set ...`, or `resume` when its
 * folder holds a checkpoint of an unfinished run of the same settings
 * (px_sweep_decide). 0, or -1 when it is done already (finished), refused
 * or cannot start. */
static int px_sweep_start(struct px_sweep *s, size_t r, const char *self, struct px_context *ctx) {
  struct px_sweep_run *run = &s->runs[r];
  char rundir[4400], ck[4500], errpath[4500];
  const char *argv[8 + 2 * (2 * PX_SWEEP_MAX_KEYS)];
  size_t a = 0, k;
  int fd;
  pid_t parent;
  enum px_sweep_action act;
  snprintf(rundir, sizeof rundir, "%s/%s", s->dir, run->name);
  snprintf(ck, sizeof ck, "%s/checkpoint.pxc", rundir);
  snprintf(errpath, sizeof errpath, "%s/.%s.stderr", s->dir, run->name);
  act = px_sweep_decide(s, r, ctx);
  if (act == PX_SWEEP_ACTION_DONE) return -1;
  argv[a++] = self;
  argv[a++] = "-q";
  if (act == PX_SWEEP_ACTION_RESUME) {
    argv[a++] = "resume";
    argv[a++] = ck;
  } else {
    argv[a++] = "run";
    argv[a++] = s->base;
    argv[a++] = "--out";
    argv[a++] = rundir;
    for (k = 0; k < run->noverrides; ++k) {
      argv[a++] = "--set";
      argv[a++] = run->overrides[k];
    }
  }
  argv[a] = NULL;
  fflush(NULL);
  run->wall = px_time_now();
  parent = getpid();
  run->pid = fork();
  if (run->pid < 0) {
    snprintf(run->error, sizeof run->error, "cannot start: %s", strerror(errno));
    snprintf(run->status, sizeof run->status, "failed");
    return -1;
  }
  if (run->pid == 0) {
#ifdef __linux__
    /* a sweep killed outright (SIGKILL, the OOM killer) cannot forward
       Ctrl-C: the kernel sends its runs SIGINT (a checkpoint, then stop)
       instead of leaving them running, orphaned, where a rerun sweep would
       write into the same folder. The setting survives execv. If the sweep
       died before it took effect, stop here. */
    prctl(PR_SET_PDEATHSIG, SIGINT);
    if (getppid() != parent) _exit(PX_CLI_EXIT_INTERRUPTED);
#endif
    fd = open(errpath, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW, 0644);
    if (fd >= 0) dup2(fd, 2);
    fd = open("/dev/null", O_WRONLY);
    if (fd >= 0) dup2(fd, 1);
    execv(self, (char *const *)argv);
    fprintf(stderr, "cannot run %s: %s\n", self, strerror(errno));
    _exit(PX_CLI_EXIT_FAILURE);
  }
  return 0;
}

/* A finished child: its status and, when it failed, its last message. */
static void px_sweep_done(struct px_sweep *s, size_t r, int wstatus) {
  struct px_sweep_run *run = &s->runs[r];
  char errpath[4500], line[512];
  FILE *f;
  run->wall = px_time_now() - run->wall;
  run->exit = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
  snprintf(run->status, sizeof run->status, "%s",
           run->exit == 0     ? "finished"
           : run->exit == 130 ? "interrupted"
                              : "failed");
  snprintf(errpath, sizeof errpath, "%s/.%s.stderr", s->dir, run->name);
  f = fopen(errpath, "r");
  while (f && fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = '\0';
    if (line[0] && run->exit != 0) snprintf(run->error, sizeof run->error, "%s", line);
  }
  if (f) fclose(f);
  remove(errpath);
}

#ifdef PX_HAVE_MPI
/* Run r in this process (a rank of an MPI sweep): as `partix -q run` (or
 * `resume`, as px_sweep_decide on rank 0 decided) would. Its exit status; its message
 * in err when it fails. */
static int px_sweep_run_here(struct px_sweep *s, size_t r, char *err, size_t errsize) {
  struct px_sweep_run *run = &s->runs[r];
  char rundir[4400], ck[4500], *out = NULL;
  const char *ov[2 * PX_SWEEP_MAX_KEYS + 1];
  struct px_context *ctx = NULL;
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  enum px_status st;
  size_t n = 0, k;
  int setup;
  snprintf(rundir, sizeof rundir, "%s/%s", s->dir, run->name);
  snprintf(ck, sizeof ck, "%s/checkpoint.pxc", rundir);
  err[0] = '\0';
  if (px_context_create(&ctx) != PX_STATUS_OK) {
    snprintf(err, errsize, "out of memory");
    return PX_CLI_EXIT_FAILURE;
  }
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  /* rank 0 handed it out: a checkpoint here is of these settings */
  if (px_file_exists(ck)) {
    st = px_sim_open(ctx, ck, NULL, 0, PX_SIM_MODE_RUN, &sim);
  } else {
    /* the folder as text as given: a sweep dir may hold a '#' or ': ' (as
       `--out` takes it) */
    out = px_cli_override_text("output.dir", rundir);
    for (k = 0; k < run->noverrides; ++k) ov[n++] = run->overrides[k];
    ov[n++] = out;
    st = out ? px_case_load(ctx, s->base, ov, n, &c) : PX_STATUS_NOMEM;
    free(out);
    if (st == PX_STATUS_OK) st = px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim);
  }
  setup = st != PX_STATUS_OK && st != PX_STATUS_NOMEM && st != PX_STATUS_INTERNAL;
  if (st == PX_STATUS_OK) {
    px_sim_set_progress(sim, NULL, 0);
    st = px_sim_run(sim);
  }
  if (st != PX_STATUS_OK)
    snprintf(err, errsize, "%s",
             px_context_message(ctx)[0] ? px_context_message(ctx) : px_status_message(st));
  px_sim_free(sim);
  px_context_free(ctx);
  return setup ? PX_CLI_EXIT_USAGE : px_cli_exit_code(st);
}

/* What a rank sends back for a run. */
struct px_sweep_result {
  int32_t index, exit;
  double wall; /* [s] */
  char error[512];
};

/* The next run to hand out, or -1: runs whose summary.json says finished
 * and those refused (px_sweep_decide) are recorded as such and passed
 * over. */
static int32_t px_sweep_next(struct px_sweep *s, const struct px_cli *cli, struct px_context *ctx,
                             size_t *next, size_t *finished) {
  while (*next < s->nruns) {
    const size_t r = (*next)++;
    const struct px_sweep_run *run = &s->runs[r];
    if (px_sweep_decide(s, r, ctx) != PX_SWEEP_ACTION_DONE) return (int32_t)r;
    ++*finished;
    if (cli->log_level >= PX_LOG_LEVEL_INFO || strcmp(run->status, "finished") != 0)
      printf("[%zu/%zu] %s: %s%s%s\n", *finished, s->nruns, run->name,
             strcmp(run->status, "finished") == 0 ? "finished before, skipped" : run->status,
             run->error[0] ? ": " : "", run->error);
  }
  return -1;
}

/* An MPI sweep: rank 0 hands the runs out one at a time to the other ranks
 * as they become free (each runs one run at a time, in its own process:
 * backend.threads sets its threads) and records what they send back; it
 * runs none itself. Returns on every rank; *failed counts the runs that did
 * not finish (rank 0). */
void px_sweep_mpi(struct px_sweep *s, const struct px_cli *cli, struct px_context *ctx, int rank,
                  int size, int *failed) {
  struct px_sweep_result res;
  size_t next = 0, finished = 0, r;
  int32_t index;
  int active = 0, w;
  if (rank != 0) {
    for (;;) {
      MPI_Recv(&index, 1, MPI_INT32_T, 0, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (index < 0) return;
      memset(&res, 0, sizeof res);
      res.index = index;
      res.wall = px_time_now();
      res.exit = px_sweep_run_here(s, (size_t)index, res.error, sizeof res.error);
      res.wall = px_time_now() - res.wall;
      MPI_Send(&res, (int)sizeof res, MPI_BYTE, 0, 2, MPI_COMM_WORLD);
    }
  }
  for (w = 1; w < size; ++w) {
    index = px_sweep_next(s, cli, ctx, &next, &finished);
    MPI_Send(&index, 1, MPI_INT32_T, w, 1, MPI_COMM_WORLD);
    if (index >= 0) ++active;
  }
  while (active) {
    MPI_Status st;
    struct px_sweep_run *run;
    MPI_Recv(&res, (int)sizeof res, MPI_BYTE, MPI_ANY_SOURCE, 2, MPI_COMM_WORLD, &st);
    --active;
    run = &s->runs[res.index];
    run->exit = res.exit;
    run->wall = res.wall;
    snprintf(run->error, sizeof run->error, "%s", res.error);
    snprintf(run->status, sizeof run->status, "%s",
             res.exit == 0     ? "finished"
             : res.exit == 130 ? "interrupted"
                               : "failed");
    ++finished;
    if (cli->log_level >= PX_LOG_LEVEL_INFO || res.exit != 0)
      printf("[%zu/%zu] %s: %s in %.1f s on rank %d%s%s\n", finished, s->nruns, run->name,
             run->status, run->wall, st.MPI_SOURCE, run->error[0] ? ": " : "", run->error);
    fflush(stdout);
    index = px_sweep_next(s, cli, ctx, &next, &finished);
    MPI_Send(&index, 1, MPI_INT32_T, st.MPI_SOURCE, 1, MPI_COMM_WORLD);
    if (index >= 0) ++active;
  }
  for (r = 0; r < s->nruns; ++r)
    if (strcmp(s->runs[r].status, "finished") != 0) ++*failed;
}
#endif

/* Set by SIGINT / SIGTERM during a local sweep. */
static volatile sig_atomic_t px_sweep_stop;
static void px_sweep_on_signal(int sig) {
  (void)sig;
  px_sweep_stop = 1;
}

/* A local sweep: at most `jobs` child processes at a time. The number of
 * runs that did not finish. */
static int px_sweep_local(struct px_sweep *s, const struct px_cli *cli, struct px_context *ctx,
                          long jobs, const char *self) {
  size_t r, next = 0, finished = 0;
  int running = 0, failed = 0, forwarded = 0;
  struct sigaction sa;
  /* Ctrl-C or SIGTERM: start no more runs, let the running ones write their
     checkpoints and stop (they get the signal too: forwarded when it came
     to the sweep alone), then write the table of what there is */
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = px_sweep_on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
  while (finished < s->nruns) {
    if (px_sweep_stop && !forwarded) {
      for (r = 0; r < s->nruns; ++r)
        if (s->runs[r].pid > 0) kill(s->runs[r].pid, SIGINT);
      forwarded = 1;
    }
    if (px_sweep_stop && !running) break;
    while (running < jobs && next < s->nruns && !px_sweep_stop) {
      r = next++;
      if (px_sweep_start(s, r, self, ctx) == 0) {
        ++running;
      } else {
        ++finished;
        if (cli->log_level >= PX_LOG_LEVEL_INFO || strcmp(s->runs[r].status, "finished") != 0)
          printf("[%zu/%zu] %s: %s%s%s\n", finished, s->nruns, s->runs[r].name,
                 strcmp(s->runs[r].status, "finished") == 0 ? "finished before, skipped"
                                                            : s->runs[r].status,
                 s->runs[r].error[0] ? ": " : "", s->runs[r].error);
      }
    }
    if (!running) continue;
    {
      int wstatus = 0;
      const pid_t pid = waitpid(-1, &wstatus, 0);
      if (pid < 0) {
        if (errno == EINTR) continue;
        break;
      }
      for (r = 0; r < s->nruns && s->runs[r].pid != pid; ++r) {
      }
      if (r == s->nruns) continue;
      s->runs[r].pid = 0;
      --running;
      ++finished;
      px_sweep_done(s, r, wstatus);
      if (cli->log_level >= PX_LOG_LEVEL_INFO || s->runs[r].exit != 0)
        printf("[%zu/%zu] %s: %s in %.1f s%s%s\n", finished, s->nruns, s->runs[r].name,
               s->runs[r].status, s->runs[r].wall, s->runs[r].error[0] ? ": " : "",
               s->runs[r].error);
      fflush(stdout);
    }
  }
  for (r = 0; r < s->nruns; ++r)
    if (strcmp(s->runs[r].status, "finished") != 0) ++failed;
  return failed;
}

/* sweep.csv, sweep.json (and sweep.png) of what the runs left, and the
 * last line; the sweep's exit status. */
int px_sweep_finish(struct px_sweep *s, struct px_context *ctx, int failed) {
  struct px_sweep_table t;
  int code;
  memset(&t, 0, sizeof t);
  if (px_sweep_table_read(s, &t) != 0 || px_sweep_write_csv(ctx, s, &t) != PX_STATUS_OK ||
      px_sweep_write_json(ctx, s, &t) != PX_STATUS_OK ||
      (s->plot_x && px_sweep_plot(ctx, s, &t) != PX_STATUS_OK)) {
    fprintf(stderr, "partix sweep: %s\n", px_context_message(ctx));
    code = PX_CLI_EXIT_FAILURE;
  } else if (px_sweep_stop) {
    printf(
        "interrupted: %d of %zu runs not finished (%s/sweep.csv); run the same command "
        "again to continue\n",
        failed, s->nruns, s->dir);
    code = PX_CLI_EXIT_INTERRUPTED;
  } else {
    printf("%zu runs, %d not finished: %s/sweep.csv%s%s\n", s->nruns, failed, s->dir,
           s->plotted ? ", sweep.png" : "", failed ? " (errors in its last column)" : "");
    code = failed ? PX_CLI_EXIT_FAILURE : PX_CLI_EXIT_OK;
  }
  px_sweep_table_free(s, &t);
  return code;
}

int px_sweep_execute(struct px_sweep *s, struct px_cli *cli, struct px_context *ctx, long jobs) {
  char self[4096];
  const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
  if (len <= 0) {
    fprintf(stderr, "partix: cannot find the partix program (/proc/self/exe)\n");
    return PX_CLI_EXIT_FAILURE;
  }
  self[len] = '\0';
  if (px_file_mkdirs(ctx, s->dir) != PX_STATUS_OK) {
    fprintf(stderr, "partix: %s\n", px_context_message(ctx));
    return PX_CLI_EXIT_FAILURE;
  }
  return px_sweep_finish(s, ctx, px_sweep_local(s, cli, ctx, jobs, self));
}

int px_sweep_interrupted(void) { return px_sweep_stop != 0; }
