/* The run driver: one time loop for every solver. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/ioutil.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "partix/progress.h"
#include "partix/timer.h"
#include "partix/version.h"
#include "solvers/solver.h"
#include "solvers/summary.h"

#define PX_SIM_PATH_MAX 4096
/* Most steps a run may take (time.steps' schema range). */
#define PX_SIM_MAX_STEPS 1e12
/* Most CPU threads per logical core: more only slows a run. */
#define PX_SIM_THREADS_PER_CORE 4

struct px_sim {
  struct px_context *ctx;           /* borrowed */
  struct px_case *c;                /* owned */
  const struct px_solver_i *solver; /* static */
  void *state;                      /* owned through solver->destroy */
  struct px_backend *be;            /* owned */
  enum px_precision precision;
  enum px_sim_mode mode;
  long step;   /* steps done */
  long nsteps; /* steps to reach */
  double dt;   /* [s] */
  char outdir[PX_SIM_PATH_MAX];
  char ckpath[PX_SIM_PATH_MAX];
  long every, png_every, log_every, ck_every;
  int vtk, csv, png;
  FILE *progress_out; /* borrowed */
  int progress_tty;
  int resumed;
  double resume_time;
  double keep_series, keep_snapshot; /* see struct px_sim_output */
  long drop_picture;
  long last_checkpoint;      /* step of the last checkpoint written, -1 none */
  struct px_timeset *timers; /* owned */
  int t_step, t_output, t_checkpoint;
  char **autos; /* px_mem, owned: "key\tvalue" of each automatic setting */
  size_t nauto;
  char **inputs; /* px_mem, owned: "name\tbytes\thash" of each input file */
  size_t ninput;
  /* run.log: every log message at INFO or more detailed (whatever the console
     shows), buffered until the run folder is opened */
  FILE *log;    /* owned; NULL before the folder is opened */
  char *logbuf; /* px_mem, owned: lines waiting for the file */
  size_t loglen, logcap;
  int log_tee;           /* 1 while the tee below is installed */
  px_log_fn log_prev_fn; /* the context's log callback before the tee */
  void *log_prev_user;
  enum px_log_level console_level; /* the context's level before the tee */
  double wall_start;               /* px_time_now() when this process started the run */
  double wall_before;              /* wall time of earlier segments (resumed runs) [s] */
  char title[256];
};

const char *const *px_sim_solver_names(void) {
  static const char *names[32];
  const struct px_solver_i *const *reg = px_solver_registry();
  size_t i;
  for (i = 0; reg[i] && i < 31; ++i) names[i] = reg[i]->name;
  names[i] = NULL;
  return names;
}

const char *px_sim_solver_summary(const char *name) {
  const struct px_solver_i *s = px_solver_find(name);
  return s ? s->summary : NULL;
}

const struct px_solver_i *px_solver_find(const char *name) {
  const struct px_solver_i *const *reg = px_solver_registry();
  size_t i;
  if (!name) return NULL;
  for (i = 0; reg[i]; ++i)
    if (strcmp(reg[i]->name, name) == 0) return reg[i];
  return NULL;
}

static enum px_status px_sim_get_long(struct px_sim *sim, const char *path, long *out) {
  return px_case_get_int(sim->c, path, out);
}

static enum px_status px_sim_get_flag(struct px_sim *sim, const char *path, int *out) {
  return px_case_get_bool(sim->c, path, out);
}

/* ---- run.log ------------------------------------------------------------ */

static void px_sim_log_append(struct px_sim *sim, const char *text, size_t n) {
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
static void px_sim_log_line(struct px_sim *sim, enum px_log_level level, const char *message) {
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

static void px_sim_tee_install(struct px_sim *sim) {
  px_context_get_log(sim->ctx, &sim->log_prev_fn, &sim->log_prev_user);
  sim->console_level = px_context_log_level(sim->ctx);
  if (sim->console_level < PX_LOG_LEVEL_INFO) px_context_set_log_level(sim->ctx, PX_LOG_LEVEL_INFO);
  px_context_set_log(sim->ctx, px_sim_tee, sim);
  sim->log_tee = 1;
}

static void px_sim_tee_remove(struct px_sim *sim) {
  if (!sim->log_tee) return;
  px_context_set_log(sim->ctx, sim->log_prev_fn, sim->log_prev_user);
  px_context_set_log_level(sim->ctx, sim->console_level);
  sim->log_tee = 0;
}

/* Open RUN_DIR/run.log for appending (never through a symbolic link) and
 * write out what was logged before the folder existed. */
static enum px_status px_sim_log_open(struct px_sim *sim) {
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

/* ---- input files -------------------------------------------------------- */

/* 64-bit FNV-1a of a buffer (names an input file's content in summary.json). */
static uint64_t px_sim_fnv(const char *data, size_t len) {
  uint64_t h = 14695981039346656037u;
  size_t i;
  for (i = 0; i < len; ++i) {
    h ^= (unsigned char)data[i];
    h *= 1099511628211u;
  }
  return h;
}

/* The index of the input record named `name` ("input/x.dat"), or ninput. */
static size_t px_sim_find_input(const struct px_sim *sim, const char *name) {
  size_t i, n = strlen(name);
  for (i = 0; i < sim->ninput; ++i)
    if (strncmp(sim->inputs[i], name, n) == 0 && sim->inputs[i][n] == '\t') break;
  return i;
}

/* Copy an input file of the case into RUN_DIR/input/ and record its new
 * name (px_case_input_fn): the run folder then holds everything its case
 * reads, and `partix resume`, `render` and `check RUN_DIR/case.yaml` work
 * from any directory and after the folder is moved. The record (summary.json
 * "inputs") is "name\tbytes\thash" of the content. */
static enum px_status px_sim_copy_input(void *user, const char *key, const char *source,
                                        char *newvalue, size_t size) {
  struct px_sim *sim = user;
  const char *base = strrchr(source, '/'), *dot;
  char name[512], dest[PX_SIM_PATH_MAX], dir[PX_SIM_PATH_MAX], stem[400], rec[700];
  struct stat sa, sb;
  char *data = NULL, *entry, **grown;
  size_t len = 0;
  uint64_t hash;
  int k, same;
  enum px_status st;
  base = base ? base + 1 : source;
  if (!base[0] || strcmp(base, ".") == 0 || strcmp(base, "..") == 0)
    return px_case_fail(sim->c, key, "'%s' is not a file name", source);
  st = px_ioutil_read_file(sim->ctx, source, &data, &len);
  if (st != PX_STATUS_OK) return px_context_prefix(sim->ctx, "%s", key);
  hash = px_sim_fnv(data, len);
  dot = strrchr(base, '.');
  if (!dot || dot == base) dot = base + strlen(base);
  snprintf(stem, sizeof stem, "%.*s", (int)(dot - base), base);
  /* input/NAME, or input/NAME-2.EXT when another file took NAME; the same
     content keeps the name it got */
  for (k = 1;; ++k) {
    size_t at;
    if (k == 1)
      snprintf(name, sizeof name, "input/%s", base);
    else
      snprintf(name, sizeof name, "input/%s-%d%s", stem, k, dot);
    snprintf(rec, sizeof rec, "%s\t%zu\t%016llx", name, len, (unsigned long long)hash);
    at = px_sim_find_input(sim, name);
    if (at == sim->ninput) break;
    if (strcmp(sim->inputs[at], rec) == 0) {
      px_mem_free(sim->ctx, data);
      snprintf(newvalue, size, "%s", name);
      return PX_STATUS_OK;
    }
  }
  st = px_file_join(sim->ctx, dir, sizeof dir, sim->outdir, "input");
  if (st == PX_STATUS_OK) st = px_file_join(sim->ctx, dest, sizeof dest, sim->outdir, name);
  same = st == PX_STATUS_OK && stat(source, &sa) == 0 && stat(dest, &sb) == 0 &&
         sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
  if (st == PX_STATUS_OK && !same) {
    /* not the run's own copy (as when a run resumes in its folder) */
    st = px_file_mkdirs(sim->ctx, dir);
    if (st == PX_STATUS_OK) st = px_file_write_all(sim->ctx, dest, data, len);
    if (st == PX_STATUS_OK)
      px_log(sim->ctx, PX_LOG_LEVEL_DEBUG, "%s: %s kept in the run folder as %s", key, source,
             name);
  }
  px_mem_free(sim->ctx, data);
  if (st != PX_STATUS_OK) return px_context_prefix(sim->ctx, "%s: copying %s", key, source);
  snprintf(newvalue, size, "%s", name);
  entry = px_ioutil_strdup(sim->ctx, "input record", rec);
  grown = px_mem_realloc(sim->ctx, "input records", sim->inputs, (sim->ninput + 1) * sizeof *grown);
  if (grown) sim->inputs = grown;
  if (!entry || !grown) {
    px_mem_free(sim->ctx, entry);
    return PX_STATUS_NOMEM;
  }
  sim->inputs[sim->ninput++] = entry;
  return PX_STATUS_OK;
}

/* ---- building a run ----------------------------------------------------- */

/* Backend, precision and output settings from the case; the output folder
 * is `outdir` when given (a resumed run continues next to its checkpoint). */
static enum px_status px_sim_configure(struct px_sim *sim, const char *outdir) {
  const char *type = NULL, *prec = NULL, *dir = NULL;
  long device = 0, threads = 0, workgroup = 0;
  PX_TRY(px_case_get_string(sim->c, "backend.type", &type));
  PX_TRY(px_sim_get_long(sim, "backend.device", &device));
  PX_TRY(px_sim_get_long(sim, "backend.threads", &threads));
  PX_TRY(px_sim_get_long(sim, "backend.workgroup", &workgroup));
  PX_TRY(px_case_get_string(sim->c, "backend.precision", &prec));
  if (px_precision_parse(prec, &sim->precision) != PX_STATUS_OK)
    return px_case_fail(sim->c, "backend.precision", "unknown precision '%s'", prec);
  {
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    if (cores > 0 && threads > PX_SIM_THREADS_PER_CORE * cores)
      return px_case_fail(sim->c, "backend.threads",
                          "%ld threads on a machine with %ld logical cores: more than %d per core "
                          "only slows a run down (0 = one per core)",
                          threads, cores, PX_SIM_THREADS_PER_CORE);
  }
  if (px_backend_create(sim->ctx, type, (int)device, (int)threads, &sim->be) != PX_STATUS_OK) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(sim->ctx));
    return px_case_fail(sim->c, "backend.type", "cannot start the %s backend: %s", type, msg);
  }
  PX_TRY(px_backend_set_workgroup(sim->be, (size_t)workgroup));
  if (px_backend_require(sim->be, sim->precision) != PX_STATUS_OK) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(sim->ctx));
    return px_case_fail(sim->c, "backend.precision", "%s", msg);
  }

  PX_TRY(px_case_get_string(sim->c, "output.dir", &dir));
  if (outdir) dir = outdir;
  if (strlen(dir) >= sizeof sim->outdir - 32)
    return px_case_fail(sim->c, "output.dir", "path too long");
  snprintf(sim->outdir, sizeof sim->outdir, "%s", dir);
  PX_TRY(px_file_join(sim->ctx, sim->ckpath, sizeof sim->ckpath, sim->outdir, "checkpoint.pxc"));
  PX_TRY(px_sim_get_long(sim, "output.every", &sim->every));
  PX_TRY(px_sim_get_long(sim, "output.png_every", &sim->png_every));
  if (sim->png_every == 0) sim->png_every = sim->every;
  PX_TRY(px_sim_get_long(sim, "output.log_every", &sim->log_every));
  PX_TRY(px_sim_get_long(sim, "output.checkpoint_every", &sim->ck_every));
  PX_TRY(px_sim_get_flag(sim, "output.vtk", &sim->vtk));
  PX_TRY(px_sim_get_flag(sim, "output.csv", &sim->csv));
  PX_TRY(px_sim_get_flag(sim, "output.png", &sim->png));
  if (px_case_has(sim->c, "title")) {
    const char *title = NULL;
    PX_TRY(px_case_get_string(sim->c, "title", &title));
    snprintf(sim->title, sizeof sim->title, "%s", title);
  }
  return PX_STATUS_OK;
}

/* dt from the case or the solver, and the number of steps. */
static enum px_status px_sim_schedule(struct px_sim *sim) {
  if (px_case_has(sim->c, "time.dt")) {
    PX_TRY(px_case_get_real(sim->c, "time.dt", &sim->dt));
  } else if (sim->solver->time_step) {
    PX_TRY(sim->solver->time_step(sim->state, &sim->dt));
    if (sim->dt > 0 && isfinite(sim->dt))
      px_sim_note_auto(sim, "time.dt", "%.9g s (the solver's stable step)", sim->dt);
  } else {
    return px_case_fail(sim->c, "time",
                        "missing required key 'dt' (time step [s]): the %s solver "
                        "does not choose one automatically",
                        sim->solver->name);
  }
  if (!(sim->dt > 0) || !isfinite(sim->dt))
    return px_context_fail(sim->ctx, PX_STATUS_INTERNAL, "invalid time step %g", sim->dt);
  if (px_case_has(sim->c, "time.steps")) {
    PX_TRY(px_case_get_int(sim->c, "time.steps", &sim->nsteps));
  } else {
    double end = 0, n;
    PX_TRY(px_case_get_real(sim->c, "time.end", &end));
    /* the last step may overshoot `end` by less than one dt */
    n = ceil(end / sim->dt - 1e-9);
    if (!(n <= PX_SIM_MAX_STEPS))
      return px_case_fail(sim->c, px_case_has(sim->c, "time.dt") ? "time.dt" : "time.end",
                          "time.end / time.dt = %.3g / %.3g s = %.3g steps, more than a run may "
                          "take (%.0e): check the units of time.dt",
                          end, sim->dt, n, PX_SIM_MAX_STEPS);
    sim->nsteps = n < 1 ? 1 : (long)n;
  }
  if (!isfinite((double)sim->nsteps * sim->dt))
    return px_case_fail(sim->c, "time.dt", "%ld steps of %.3g s end at t = %g s: not a finite time",
                        sim->nsteps, sim->dt, (double)sim->nsteps * sim->dt);
  return PX_STATUS_OK;
}

/* Everything of a run that writes nothing: backend, solver, schedule. In
 * RUN mode the log tee is installed first, so that what the solver logs
 * while it builds the problem reaches run.log once the folder is open. */
static enum px_status px_sim_build(struct px_context *ctx, struct px_case *c, enum px_sim_mode mode,
                                   const char *outdir, struct px_sim **out) {
  struct px_sim *sim;
  const char *solver_name = px_case_solver(c);
  *out = NULL;
  sim = px_mem_calloc(ctx, "sim", 1, sizeof *sim);
  if (!sim) {
    px_case_free(c);
    return PX_STATUS_NOMEM;
  }
  sim->ctx = ctx;
  sim->c = c;
  sim->mode = mode;
  sim->last_checkpoint = -1;
  sim->drop_picture = -1;
  sim->progress_out = stderr;
  sim->progress_tty = -1;
  sim->wall_start = px_time_now();
  *out = sim;
  sim->solver = px_solver_find(solver_name);
  if (!sim->solver)
    return px_case_fail(c, "solver", "solver '%s' is not built into this partix",
                        solver_name ? solver_name : "");
  if (mode == PX_SIM_MODE_RUN) px_sim_tee_install(sim);
  PX_TRY(px_timeset_create(ctx, &sim->timers));
  sim->t_step = px_timeset_slot(sim->timers, "solver step");
  sim->t_output = px_timeset_slot(sim->timers, "output");
  sim->t_checkpoint = px_timeset_slot(sim->timers, "checkpoint");
  PX_TRY(px_sim_configure(sim, outdir));
  PX_TRY(sim->solver->create(sim, &sim->state));
  PX_TRY(px_sim_schedule(sim));
  return PX_STATUS_OK;
}

/* Open the run folder (RUN mode): the folder, run.log, copies of the input
 * files, and the resolved case.yaml. */
static enum px_status px_sim_open_outputs(struct px_sim *sim, const char *how) {
  char path[PX_SIM_PATH_MAX], line[PX_SIM_PATH_MAX + 256];
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  PX_TRY(px_file_mkdirs(sim->ctx, sim->outdir));
  /* the temporaries of a run that was killed while it wrote (kill -9, a
     crash, a power cut): the files they were to replace are intact */
  px_file_remove_stale_in(sim->ctx, sim->outdir);
  if (px_file_join(sim->ctx, path, sizeof path, sim->outdir, "input") == PX_STATUS_OK)
    px_file_remove_stale_in(sim->ctx, path);
  /* a header line in run.log before what was logged while building */
  snprintf(line, sizeof line, "partix %s: %s", px_version(), how);
  if (sim->log_tee) {
    char *held = sim->logbuf;
    size_t held_len = sim->loglen;
    sim->logbuf = NULL;
    sim->loglen = sim->logcap = 0;
    px_sim_log_line(sim, PX_LOG_LEVEL_INFO, line);
    if (held_len) px_sim_log_append(sim, held, held_len);
    px_mem_free(sim->ctx, held);
    PX_TRY(px_sim_log_open(sim));
  }
  PX_TRY(px_case_relocate_inputs(sim->c, sim->outdir, px_sim_copy_input, sim));
  PX_TRY(px_sim_output_path(sim, "case.yaml", path, sizeof path));
  PX_TRY(px_case_write_resolved(sim->c, path));
  return PX_STATUS_OK;
}

enum px_status px_sim_create(struct px_context *ctx, struct px_case *c, enum px_sim_mode mode,
                             struct px_sim **out) {
  enum px_status s;
  char how[PX_SIM_PATH_MAX + 64];
  if (!ctx || !c || !out) {
    px_case_free(c);
    return PX_STATUS_INVALID;
  }
  snprintf(how, sizeof how, "run of %s", px_case_file(c) ? px_case_file(c) : "a case");
  s = px_sim_build(ctx, c, mode, NULL, out);
  if (s == PX_STATUS_OK) s = px_sim_open_outputs(*out, how);
  if (s != PX_STATUS_OK) {
    px_sim_free(*out);
    *out = NULL;
  }
  return s;
}

void px_sim_free(struct px_sim *sim) {
  size_t i;
  if (!sim) return;
  if (sim->state && sim->solver && sim->solver->destroy) sim->solver->destroy(sim->state);
  px_sim_tee_remove(sim);
  if (sim->log) fclose(sim->log);
  px_mem_free(sim->ctx, sim->logbuf);
  for (i = 0; i < sim->nauto; ++i) px_mem_free(sim->ctx, sim->autos[i]);
  px_mem_free(sim->ctx, sim->autos);
  for (i = 0; i < sim->ninput; ++i) px_mem_free(sim->ctx, sim->inputs[i]);
  px_mem_free(sim->ctx, sim->inputs);
  px_backend_free(sim->be);
  px_case_free(sim->c);
  px_timeset_free(sim->timers);
  px_mem_free(sim->ctx, sim);
}

void px_sim_set_progress(struct px_sim *sim, FILE *out, int is_terminal) {
  if (!sim) return;
  sim->progress_out = out;
  sim->progress_tty = is_terminal;
}

/* ---- outputs ------------------------------------------------------------ */

static void px_sim_output_info(const struct px_sim *sim, struct px_sim_output *o) {
  memset(o, 0, sizeof *o);
  o->step = sim->step;
  o->time = (double)sim->step * sim->dt;
  o->dir = sim->outdir;
  o->resumed = sim->resumed;
  o->resume_time = sim->resume_time;
  o->keep_series = sim->keep_series;
  o->keep_snapshot = sim->keep_snapshot;
  o->drop_picture = sim->resumed ? sim->drop_picture : -1;
  o->render = sim->mode == PX_SIM_MODE_RENDER;
  o->pictures = o->render || sim->png;
}

enum px_sim_due {
  PX_SIM_DUE_SCHEDULED, /* the outputs whose period divides the step */
  PX_SIM_DUE_ALL,       /* every output (the initial state) */
  PX_SIM_DUE_FINAL      /* the end of the run: those the schedule missed */
};

static int px_sim_due(long step, long every, enum px_sim_due due) {
  int on = every > 0 && step % every == 0;
  return due == PX_SIM_DUE_ALL || (due == PX_SIM_DUE_SCHEDULED && on) ||
         (due == PX_SIM_DUE_FINAL && !on);
}

static enum px_status px_sim_outputs(struct px_sim *sim, enum px_sim_due due) {
  struct px_sim_output o;
  const struct px_solver_i *s = sim->solver;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  px_sim_output_info(sim, &o);
  o.final = due == PX_SIM_DUE_FINAL;
  px_timeset_start(sim->timers, sim->t_output);
  if (sim->csv && s->series && px_sim_due(sim->step, sim->log_every, due))
    PX_TRY(s->series(sim->state, &o));
  if (sim->vtk && s->snapshot && px_sim_due(sim->step, sim->every, due))
    PX_TRY(s->snapshot(sim->state, &o));
  if (sim->png && s->picture && px_sim_due(sim->step, sim->png_every, due))
    PX_TRY(s->picture(sim->state, &o));
  px_timeset_stop(sim->timers, sim->t_output);
  return PX_STATUS_OK;
}

/* ---- summary.json ------------------------------------------------------- */

static double px_sim_wall(const struct px_sim *sim) {
  return sim->wall_before + (px_time_now() - sim->wall_start);
}

/* The list of "a\tb" records as a JSON object {"a": "b", ...}. */
static void px_sim_put_pairs(FILE *f, char *const *list, size_t n) {
  size_t i;
  fputs("{", f);
  for (i = 0; i < n; ++i) {
    char key[512];
    const char *tab = strchr(list[i], '\t');
    if (!tab) continue;
    snprintf(key, sizeof key, "%.*s", (int)(tab - list[i]), list[i]);
    fputs(i ? ",\n    " : "\n    ", f);
    px_summary_fput_string(f, key);
    fputs(": ", f);
    px_summary_fput_string(f, tab + 1);
  }
  fputs(n ? "\n  }" : "}", f);
}

/* Write RUN_DIR/summary.json (atomically): the run, and the solver's report
 * of the quantities a user reports. `status` is "running", "finished",
 * "interrupted" or "failed" (then `message` says why). */
static enum px_status px_sim_write_summary(struct px_sim *sim, const char *status,
                                           const char *message) {
  struct px_summary *sum = NULL;
  struct px_sim_output o;
  struct px_file *file = NULL;
  char path[PX_SIM_PATH_MAX], *body = NULL, hash[32];
  size_t len = 0, i;
  FILE *f;
  enum px_status st;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  PX_TRY(px_summary_create(sim->ctx, &sum));
  px_sim_output_info(sim, &o);
  st = sim->solver->report ? sim->solver->report(sim->state, &o, sum) : PX_STATUS_OK;
  if (st == PX_STATUS_OK) st = px_summary_status(sum);
  if (st == PX_STATUS_OK) st = px_summary_json(sum, 4, &body, &len);
  px_summary_free(sum);
  if (st == PX_STATUS_OK) st = px_sim_output_path(sim, "summary.json", path, sizeof path);
  if (st == PX_STATUS_OK) st = px_file_open(sim->ctx, path, &file);
  if (st != PX_STATUS_OK) {
    px_mem_free(sim->ctx, body);
    return st;
  }
  f = px_file_stream(file);
  snprintf(hash, sizeof hash, "%016llx", (unsigned long long)px_case_hash(sim->c));
  fputs("{\n  \"partix\": ", f);
  px_summary_fput_string(f, px_version());
  fputs(",\n  \"solver\": ", f);
  px_summary_fput_string(f, sim->solver->name);
  fputs(",\n  \"title\": ", f);
  px_summary_fput_string(f, sim->title);
  fputs(",\n  \"case_hash\": ", f);
  px_summary_fput_string(f, hash);
  fputs(",\n  \"status\": ", f);
  px_summary_fput_string(f, status);
  if (message) {
    fputs(",\n  \"message\": ", f);
    px_summary_fput_string(f, message);
  }
  fprintf(f, ",\n  \"step\": %ld,\n  \"steps\": %ld,\n  \"time_s\": ", sim->step, sim->nsteps);
  px_summary_fput_real(f, (double)sim->step * sim->dt);
  fputs(",\n  \"end_time_s\": ", f);
  px_summary_fput_real(f, (double)sim->nsteps * sim->dt);
  fputs(",\n  \"dt_s\": ", f);
  px_summary_fput_real(f, sim->dt);
  fprintf(f, ",\n  \"wall_time_s\": %.3f", px_sim_wall(sim));
  fputs(",\n  \"backend\": {\"type\": ", f);
  px_summary_fput_string(f, px_backend_name(sim->be));
  fputs(", \"device\": ", f);
  px_summary_fput_string(f, px_backend_device(sim->be));
  fprintf(f, ", \"threads\": %d, \"precision\": ", px_backend_threads(sim->be));
  px_summary_fput_string(f, px_precision_name(sim->precision));
  fputs("},\n  \"inputs\": {", f);
  for (i = 0; i < sim->ninput; ++i) {
    char name[512];
    unsigned long long bytes = 0;
    const char *tab = strchr(sim->inputs[i], '\t');
    const char *tab2 = tab ? strchr(tab + 1, '\t') : NULL;
    if (!tab2) continue;
    snprintf(name, sizeof name, "%.*s", (int)(tab - sim->inputs[i]), sim->inputs[i]);
    bytes = strtoull(tab + 1, NULL, 10);
    fputs(i ? ",\n    " : "\n    ", f);
    px_summary_fput_string(f, name);
    fprintf(f, ": {\"bytes\": %llu, \"fnv1a64\": \"%s\"}", bytes, tab2 + 1);
  }
  fputs(sim->ninput ? "\n  }" : "}", f);
  fputs(",\n  \"automatic\": ", f);
  px_sim_put_pairs(f, sim->autos, sim->nauto);
  fputs(",\n  \"quantities\": {\n", f);
  if (body) fputs(body, f);
  fputs("  }\n}\n", f);
  px_mem_free(sim->ctx, body);
  return px_file_commit(file);
}

/* The wall time recorded by the summary.json in `dir`, 0 when none. */
static double px_sim_read_wall(struct px_context *ctx, const char *dir) {
  char path[PX_SIM_PATH_MAX], *text = NULL, *at;
  size_t len = 0;
  double w = 0;
  if (px_file_join(ctx, path, sizeof path, dir, "summary.json") != PX_STATUS_OK) return 0;
  if (px_ioutil_read_file(ctx, path, &text, &len) != PX_STATUS_OK) {
    px_context_clear(ctx);
    return 0;
  }
  at = strstr(text, "\"wall_time_s\": ");
  if (at) w = strtod(at + 15, NULL);
  px_mem_free(ctx, text);
  return isfinite(w) && w > 0 ? w : 0;
}

/* 1 if the summary.json in `dir` says the run finished. */
static int px_sim_read_finished(struct px_context *ctx, const char *dir) {
  char path[PX_SIM_PATH_MAX], *text = NULL;
  size_t len = 0;
  int done;
  if (px_file_join(ctx, path, sizeof path, dir, "summary.json") != PX_STATUS_OK) return 0;
  if (px_ioutil_read_file(ctx, path, &text, &len) != PX_STATUS_OK) {
    px_context_clear(ctx);
    return 0;
  }
  done = strstr(text, "\"status\": \"finished\"") != NULL;
  px_mem_free(ctx, text);
  return done;
}

/* ---- checkpoints -------------------------------------------------------- */

static enum px_status px_sim_write_checkpoint(struct px_sim *sim) {
  struct px_checkpoint_writer *w = NULL;
  const char *text;
  double dt;
  enum px_status s;
  if (!sim->solver->save)
    return px_context_fail(sim->ctx, PX_STATUS_UNSUPPORTED,
                           "the %s solver cannot write checkpoints", sim->solver->name);
  px_timeset_start(sim->timers, sim->t_checkpoint);
  PX_TRY(px_checkpoint_writer_open(sim->ctx, sim->ckpath, sim->solver->name, px_case_hash(sim->c),
                                   (uint64_t)sim->step, (double)sim->step * sim->dt, &w));
  text = px_case_resolved_text(sim->c);
  dt = sim->dt;
  s = px_checkpoint_write(w, "case", PX_DTYPE_U8, strlen(text), text);
  if (s == PX_STATUS_OK) s = px_checkpoint_write(w, "driver.dt", PX_DTYPE_F64, 1, &dt);
  if (s == PX_STATUS_OK) s = sim->solver->save(sim->state, w);
  if (s != PX_STATUS_OK) {
    px_checkpoint_writer_abort(w);
    return px_context_prefix(sim->ctx, "writing checkpoint %s", sim->ckpath);
  }
  PX_TRY(px_checkpoint_writer_commit(w));
  px_timeset_stop(sim->timers, sim->t_checkpoint);
  sim->last_checkpoint = sim->step;
  px_log(sim->ctx, PX_LOG_LEVEL_DEBUG, "checkpoint at step %ld written to %s", sim->step,
         sim->ckpath);
  return PX_STATUS_OK;
}

enum px_status px_sim_checkpoint(struct px_sim *sim) {
  if (!sim) return PX_STATUS_INVALID;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  PX_TRY(px_sim_write_checkpoint(sim));
  return px_sim_write_summary(sim, "running", NULL);
}

/* Add where the failure happened and what is left to resume from. */
static enum px_status px_sim_diagnose(struct px_sim *sim, enum px_status s) {
  char where[256];
  /* a solver that finds a blow-up some steps late (a device checking every
     few steps) names the step it happened at itself */
  if (!strstr(px_context_message(sim->ctx), " at step ")) {
    snprintf(where, sizeof where, "step %ld (t = %.9g)", sim->step + 1,
             (double)(sim->step + 1) * sim->dt);
    px_context_prefix(sim->ctx, "%s", where);
  }
  if (sim->mode == PX_SIM_MODE_RUN) {
    if (sim->last_checkpoint >= 0)
      px_context_append(sim->ctx,
                        "\nthe last good checkpoint is %s (step %ld); resume with "
                        "`partix resume %s` after changing the case (e.g. --set time.dt=...)",
                        sim->ckpath, sim->last_checkpoint, sim->ckpath);
    else
      px_context_append(sim->ctx,
                        "\nno checkpoint was written before the failure "
                        "(set output.checkpoint_every to keep one)");
  }
  return s;
}

enum px_status px_sim_step(struct px_sim *sim) {
  enum px_status s;
  if (!sim) return PX_STATUS_INVALID;
  px_timeset_start(sim->timers, sim->t_step);
  s = sim->solver->step(sim->state, sim->step, (double)sim->step * sim->dt, sim->dt);
  px_timeset_stop(sim->timers, sim->t_step);
  if (s != PX_STATUS_OK) return px_sim_diagnose(sim, s);
  sim->step++;
  PX_TRY(px_sim_outputs(sim, PX_SIM_DUE_SCHEDULED));
  if (sim->mode == PX_SIM_MODE_RUN && sim->ck_every > 0 && sim->step % sim->ck_every == 0 &&
      sim->step < sim->nsteps)
    PX_TRY(px_sim_checkpoint(sim));
  return PX_STATUS_OK;
}

/* Record a run that stops on an error (run.log, summary.json) and return
 * the error with its message unchanged. */
static enum px_status px_sim_record_failure(struct px_sim *sim, enum px_status s) {
  char msg[2048];
  snprintf(msg, sizeof msg, "%s", px_context_message(sim->ctx));
  if (sim->mode != PX_SIM_MODE_RUN) return s;
  px_sim_log_line(sim, s == PX_STATUS_INTERRUPTED ? PX_LOG_LEVEL_INFO : PX_LOG_LEVEL_ERROR,
                  msg[0] ? msg : px_status_message(s));
  if (px_sim_write_summary(sim, s == PX_STATUS_INTERRUPTED ? "interrupted" : "failed",
                           msg[0] ? msg : px_status_message(s)) != PX_STATUS_OK)
    px_sim_log_line(sim, PX_LOG_LEVEL_WARN, px_context_message(sim->ctx));
  px_context_fail(sim->ctx, s, "%s", msg);
  return s;
}

enum px_status px_sim_run(struct px_sim *sim) {
  struct px_progress *progress = NULL, *logged = NULL;
  struct px_sim_output o;
  double wall0;
  long step0;
  enum px_status s = PX_STATUS_OK;
  if (!sim) return PX_STATUS_INVALID;
  wall0 = px_time_now();
  step0 = sim->step;
  if (sim->step == 0 && !sim->resumed) {
    s = px_sim_outputs(sim, PX_SIM_DUE_ALL);
    if (s != PX_STATUS_OK) return px_sim_record_failure(sim, s);
  }
  if (sim->progress_out)
    PX_TRY(px_progress_create(sim->ctx, sim->progress_out, sim->progress_tty, sim->nsteps, 10.0,
                              &progress));
  /* plain progress lines in run.log, whatever the console shows */
  if (sim->log &&
      px_progress_create(sim->ctx, sim->log, 0, sim->nsteps, 60.0, &logged) != PX_STATUS_OK)
    logged = NULL;
  while (sim->step < sim->nsteps) {
    long count;
    s = px_sim_step(sim);
    if (s != PX_STATUS_OK) break;
    count = sim->solver->count ? sim->solver->count(sim->state) : -1;
    px_progress_update(progress, sim->step, (double)sim->step * sim->dt, count);
    px_progress_update(logged, sim->step, (double)sim->step * sim->dt, count);
    if (sim->solver->done && sim->solver->done(sim->state)) {
      px_log(sim->ctx, PX_LOG_LEVEL_INFO, "%s: done at step %ld of at most %ld (t = %.9g s)",
             sim->solver->name, sim->step, sim->nsteps, (double)sim->step * sim->dt);
      break;
    }
    if (px_context_interrupted(sim->ctx)) {
      px_progress_finish(progress);
      px_progress_free(progress);
      px_progress_finish(logged);
      px_progress_free(logged);
      s = px_sim_write_checkpoint(sim);
      if (s != PX_STATUS_OK) return px_sim_record_failure(sim, s);
      px_context_fail(sim->ctx, PX_STATUS_INTERRUPTED,
                      "interrupted at step %ld; checkpoint written to %s (continue with "
                      "`partix resume %s`)",
                      sim->step, sim->ckpath, sim->ckpath);
      return px_sim_record_failure(sim, PX_STATUS_INTERRUPTED);
    }
  }
  if (s == PX_STATUS_OK) {
    px_progress_finish(progress);
    px_progress_finish(logged);
  }
  px_progress_free(progress);
  px_progress_free(logged);
  if (s != PX_STATUS_OK) return px_sim_record_failure(sim, s);
  if (sim->mode == PX_SIM_MODE_RUN) {
    /* the last state, whatever the schedule */
    s = px_sim_outputs(sim, PX_SIM_DUE_FINAL);
    if (s == PX_STATUS_OK) s = px_sim_write_checkpoint(sim);
    if (s == PX_STATUS_OK && sim->solver->finish) {
      px_sim_output_info(sim, &o);
      o.final = 1;
      s = sim->solver->finish(sim->state, &o);
    }
    if (s == PX_STATUS_OK) s = px_sim_write_summary(sim, "finished", NULL);
    if (s != PX_STATUS_OK) return px_sim_record_failure(sim, s);
  }
  {
    double wall = px_time_now() - wall0;
    px_log(sim->ctx, PX_LOG_LEVEL_INFO,
           "%ld steps in %.3f s (%.4g steps/s); peak memory %.1f MiB; output in %s",
           sim->step - step0, wall, wall > 0 ? (double)(sim->step - step0) / wall : 0.0,
           (double)px_mem_peak(sim->ctx, NULL) / 1048576.0, sim->outdir);
  }
  return PX_STATUS_OK;
}

/* ---- resuming and rendering --------------------------------------------- */

/* Directory part of a path ("." when none). */
static void px_sim_dirname(const char *path, char *buf, size_t size) {
  const char *slash = strrchr(path, '/');
  if (!slash) {
    snprintf(buf, size, ".");
  } else if (slash == path) {
    snprintf(buf, size, "/");
  } else {
    snprintf(buf, size, "%.*s", (int)(slash - path), path);
  }
}

/* Keys of every case that may change when a run is resumed: how far it
 * runs, what it writes, where it runs. Everything else defines the state
 * stored in the checkpoint. */
static const char *const px_sim_resume_keys[] = {
    "title",        "time.steps",     "time.end",        "time.dt",           "output",
    "backend.type", "backend.device", "backend.threads", "backend.workgroup", NULL};

/* 1 if `key` is `allowed` or inside it ("output" covers "output.every"). */
static int px_sim_key_within(const char *key, const char *allowed) {
  size_t n = strlen(allowed);
  return strncmp(key, allowed, n) == 0 && (key[n] == '\0' || key[n] == '.' || key[n] == '[');
}

static void px_sim_list_keys(char *buf, size_t size, const struct px_solver_i *solver) {
  const char *const *lists[2];
  size_t used = 0, k, i;
  lists[0] = px_sim_resume_keys;
  lists[1] = solver ? solver->resume_keys : NULL;
  buf[0] = '\0';
  for (k = 0; k < 2; ++k)
    for (i = 0; lists[k] && lists[k][i] && used + 1 < size; ++i) {
      int w = snprintf(buf + used, size - used, "%s%s%s", used ? ", " : "", lists[k][i],
                       strcmp(lists[k][i], "output") == 0 ? ".*" : "");
      if (w < 0) break;
      used += (size_t)w;
      if (used >= size) used = size - 1;
    }
}

/* Refuse an override that changes a key which defines the checkpoint's
 * state (stored: the case of the checkpoint; changed: with the overrides). */
static enum px_status px_sim_check_resume_keys(struct px_context *ctx, const char *checkpoint,
                                               const struct px_case *stored,
                                               const struct px_case *changed,
                                               const char *const *overrides, size_t n) {
  const struct px_solver_i *solver = px_solver_find(px_case_solver(stored));
  size_t i, k;
  for (i = 0; i < n; ++i) {
    char key[512], *a = NULL, *b = NULL, list[1024];
    const char *eq = strchr(overrides[i], '=');
    int allowed = 0, same;
    enum px_status st;
    snprintf(key, sizeof key, "%.*s", eq ? (int)(eq - overrides[i]) : (int)strlen(overrides[i]),
             overrides[i]);
    for (k = 0; px_sim_resume_keys[k]; ++k)
      if (px_sim_key_within(key, px_sim_resume_keys[k])) allowed = 1;
    for (k = 0; solver && solver->resume_keys && solver->resume_keys[k]; ++k)
      if (px_sim_key_within(key, solver->resume_keys[k])) allowed = 1;
    if (allowed) continue;
    st = px_case_value_text(stored, key, &a);
    if (st == PX_STATUS_OK) st = px_case_value_text(changed, key, &b);
    same = st == PX_STATUS_OK && ((!a && !b) || (a && b && strcmp(a, b) == 0));
    if (st == PX_STATUS_OK && !same) {
      px_sim_list_keys(list, sizeof list, solver);
      st = px_context_fail(
          ctx, PX_STATUS_CONFIG,
          "--set %s: %s cannot change when a run is resumed: the state in %s was built with "
          "%s = %s.\nKeys that may change on resume: %s.\nTo change %s, start a new run "
          "(partix run).",
          overrides[i], key, checkpoint, key, a ? a : "(not set)", list, key);
    }
    px_mem_free(ctx, a);
    px_mem_free(ctx, b);
    if (st != PX_STATUS_OK) return st;
  }
  return PX_STATUS_OK;
}

/* Which outputs of the resume step an earlier segment wrote only because it
 * ended there (see struct px_sim_output), from the schedule of the stored
 * case (an override may have changed the schedule since). */
static enum px_status px_sim_resume_schedule(struct px_sim *sim, const struct px_case *stored,
                                             double dt_before) {
  long every = 1, png_every = 0, log_every = 1;
  long k = sim->step;
  double half = 0.5 * (dt_before > 0 ? dt_before : sim->dt);
  PX_TRY(px_case_get_int(stored, "output.every", &every));
  PX_TRY(px_case_get_int(stored, "output.png_every", &png_every));
  PX_TRY(px_case_get_int(stored, "output.log_every", &log_every));
  if (png_every == 0) png_every = every;
  /* half a step either side of the resume time, so that a time printed to a
     few digits (a CSV row at the resume step) is kept whichever way it rounds */
  sim->keep_series = sim->resume_time + (log_every > 0 && k % log_every == 0 ? half : -half);
  sim->keep_snapshot = sim->resume_time + (every > 0 && k % every == 0 ? half : -half);
  sim->drop_picture = png_every > 0 && k % png_every == 0 ? -1 : k;
  return PX_STATUS_OK;
}

enum px_status px_sim_open(struct px_context *ctx, const char *checkpoint,
                           const char *const *overrides, size_t noverrides, enum px_sim_mode mode,
                           struct px_sim **out) {
  struct px_checkpoint *ck = NULL;
  struct px_case *c = NULL, *stored = NULL;
  struct px_sim *sim = NULL;
  enum px_dtype type;
  uint64_t len = 0, count = 0, ckstep;
  char *text = NULL, dir[PX_SIM_PATH_MAX], how[PX_SIM_PATH_MAX + 64];
  double dt = 0;
  size_t i;
  int has_dir = 0;
  enum px_status s;
  if (!ctx || !checkpoint || !out || (noverrides && !overrides)) return PX_STATUS_INVALID;
  *out = NULL;
  PX_TRY(px_checkpoint_open(ctx, checkpoint, &ck));
  s = px_checkpoint_find(ck, "case", &type, &len);
  if (s == PX_STATUS_OK && type != PX_DTYPE_U8)
    s = px_context_fail(ctx, PX_STATUS_FORMAT, "%s: section 'case' is not text", checkpoint);
  if (s == PX_STATUS_OK) {
    text = px_mem_alloc(ctx, "case text", (size_t)len + 1);
    if (!text) s = PX_STATUS_NOMEM;
  }
  if (s == PX_STATUS_OK) s = px_checkpoint_read(ck, "case", PX_DTYPE_U8, len, text);
  if (s == PX_STATUS_OK && px_checkpoint_find(ck, "driver.dt", &type, &count) == PX_STATUS_OK)
    s = px_checkpoint_read(ck, "driver.dt", PX_DTYPE_F64, 1, &dt);
  if (s != PX_STATUS_OK) goto done;
  text[len] = '\0';
  /* the header's step and time must be a step count a run can reach, at
     the time step x the stored dt */
  ckstep = px_checkpoint_step(ck);
  if ((double)ckstep > PX_SIM_MAX_STEPS || !isfinite(px_checkpoint_time(ck)) ||
      (dt > 0 && fabs(px_checkpoint_time(ck) - (double)ckstep * dt) >
                     1e-9 * fmax(1.0, fabs(px_checkpoint_time(ck))))) {
    s = px_context_fail(ctx, PX_STATUS_FORMAT,
                        "%s: damaged: step %llu at t = %g s does not fit its time step %g s "
                        "(or lies beyond %.0e steps)",
                        checkpoint, (unsigned long long)ckstep, px_checkpoint_time(ck), dt,
                        PX_SIM_MAX_STEPS);
    goto done;
  }
  /* the case as stored, and with the overrides */
  if (px_sim_fnv(text, (size_t)len) != px_checkpoint_case_hash(ck)) {
    /* the writer stores the resolved text and its hash (px_case_hash) */
    s = px_context_fail(ctx, PX_STATUS_FORMAT,
                        "%s: damaged or edited: its case does not match the case hash in its "
                        "header (%016llx, the case text gives %016llx)",
                        checkpoint, (unsigned long long)px_checkpoint_case_hash(ck),
                        (unsigned long long)px_sim_fnv(text, (size_t)len));
    goto done;
  }
  s = px_case_load_string(ctx, checkpoint, text, (size_t)len, NULL, 0, &stored);
  if (s == PX_STATUS_OK)
    s = px_case_load_string(ctx, checkpoint, text, (size_t)len, overrides, noverrides, &c);
  if (s != PX_STATUS_OK) goto done;
  if (px_case_solver(c) && strcmp(px_case_solver(c), px_checkpoint_solver(ck)) != 0) {
    s = px_context_fail(ctx, PX_STATUS_FORMAT,
                        "%s: checkpoint of solver '%s' but its case says '%s'", checkpoint,
                        px_checkpoint_solver(ck), px_case_solver(c));
    goto done;
  }
  if (mode == PX_SIM_MODE_RUN) {
    s = px_sim_check_resume_keys(ctx, checkpoint, stored, c, overrides, noverrides);
    if (s != PX_STATUS_OK) goto done;
  }
  /* The run continues next to its checkpoint unless told otherwise. */
  for (i = 0; i < noverrides; ++i)
    if (strncmp(overrides[i], "output.dir=", 11) == 0) has_dir = 1;
  px_sim_dirname(checkpoint, dir, sizeof dir);
  s = px_sim_build(ctx, c, mode, has_dir ? NULL : dir, &sim);
  c = NULL; /* owned by sim */
  if (s != PX_STATUS_OK) goto done;
  if (dt > 0 && dt != sim->dt) {
    px_log(ctx, PX_LOG_LEVEL_WARN,
           "time step changed from %.9g to %.9g on resume; the "
           "continuation is not bit-identical to an uninterrupted run",
           dt, sim->dt);
  }
  if (ckstep > (uint64_t)sim->nsteps && mode != PX_SIM_MODE_RUN) sim->nsteps = (long)ckstep;
  if (ckstep == (uint64_t)sim->nsteps && mode == PX_SIM_MODE_RUN &&
      !px_sim_read_finished(ctx, dir)) {
    /* killed after its last checkpoint, before its end-of-run products
       (plots, tables, the summary): resuming finishes it */
    px_log(ctx, PX_LOG_LEVEL_INFO,
           "%s: the run reached its last step (%llu) but did not finish "
           "(no \"finished\" in summary.json): writing its end-of-run products",
           checkpoint, (unsigned long long)ckstep);
  } else if (ckstep >= (uint64_t)sim->nsteps && mode == PX_SIM_MODE_RUN) {
    s = px_context_fail(ctx, PX_STATUS_CONFIG,
                        "%s: the run is at step %llu (t = %.9g s) and its case ends at step %ld "
                        "(t = %.9g s): nothing to run.\nTo run further, give a later end: "
                        "--steps N with N > %llu, or --more N for N more steps.",
                        checkpoint, (unsigned long long)ckstep, px_checkpoint_time(ck), sim->nsteps,
                        (double)sim->nsteps * sim->dt, (unsigned long long)ckstep);
    goto done;
  }
  sim->step = (long)ckstep;
  sim->resumed = 1;
  sim->resume_time = px_checkpoint_time(ck);
  sim->last_checkpoint = sim->step;
  s = px_sim_resume_schedule(sim, stored, dt);
  if (s != PX_STATUS_OK) goto done;
  if (!sim->solver->load) {
    s = px_context_fail(ctx, PX_STATUS_UNSUPPORTED, "the %s solver cannot resume",
                        sim->solver->name);
    goto done;
  }
  s = sim->solver->load(sim->state, ck);
  if (s != PX_STATUS_OK) {
    px_context_prefix(ctx, "%s", checkpoint);
    goto done;
  }
  if (mode == PX_SIM_MODE_RUN) {
    sim->wall_before = px_sim_read_wall(ctx, dir);
    snprintf(how, sizeof how, "resume of %s at step %ld", checkpoint, sim->step);
    s = px_sim_open_outputs(sim, how);
    if (s != PX_STATUS_OK) goto done;
    px_log(ctx, PX_LOG_LEVEL_INFO, "resuming %s at step %ld (t = %.9g) of %ld", sim->solver->name,
           sim->step, sim->resume_time, sim->nsteps);
  }
done:
  px_mem_free(ctx, text);
  px_case_free(stored);
  px_case_free(c);
  px_checkpoint_close(ck);
  if (s != PX_STATUS_OK) {
    px_sim_free(sim);
    return s;
  }
  *out = sim;
  return PX_STATUS_OK;
}

enum px_status px_sim_resume(struct px_context *ctx, const char *checkpoint,
                             const char *const *overrides, size_t noverrides, struct px_sim **out) {
  return px_sim_open(ctx, checkpoint, overrides, noverrides, PX_SIM_MODE_RUN, out);
}

enum px_status px_sim_render(struct px_sim *sim) {
  struct px_sim_output o;
  if (!sim) return PX_STATUS_INVALID;
  if (!sim->solver->picture && !sim->solver->finish)
    return px_context_fail(sim->ctx, PX_STATUS_UNSUPPORTED, "the %s solver draws no pictures",
                           sim->solver->name);
  px_sim_output_info(sim, &o);
  o.resumed = 0;
  o.render = 1;
  o.pictures = 1;
  if (sim->solver->picture) PX_TRY(sim->solver->picture(sim->state, &o));
  if (sim->solver->finish) PX_TRY(sim->solver->finish(sim->state, &o));
  return PX_STATUS_OK;
}

long px_sim_step_index(const struct px_sim *sim) { return sim ? sim->step : 0; }
long px_sim_step_count(const struct px_sim *sim) { return sim ? sim->nsteps : 0; }
double px_sim_time(const struct px_sim *sim) { return sim ? (double)sim->step * sim->dt : 0.0; }
double px_sim_dt(const struct px_sim *sim) { return sim ? sim->dt : 0.0; }
const char *px_sim_output_dir(const struct px_sim *sim) { return sim ? sim->outdir : ""; }
const char *px_sim_checkpoint_path(const struct px_sim *sim) { return sim ? sim->ckpath : ""; }
const struct px_case *px_sim_case(const struct px_sim *sim) { return sim ? sim->c : NULL; }
struct px_context *px_sim_context(const struct px_sim *sim) {
  return sim ? sim->ctx : NULL;
}
struct px_backend *px_sim_backend(const struct px_sim *sim) {
  return sim ? sim->be : NULL;
}
enum px_precision px_sim_precision(const struct px_sim *sim) {
  return sim ? sim->precision : PX_PRECISION_DOUBLE;
}
enum px_sim_mode px_sim_mode(const struct px_sim *sim) {
  return sim ? sim->mode : PX_SIM_MODE_CHECK;
}

void px_sim_note_auto(struct px_sim *sim, const char *key, const char *fmt, ...) {
  char value[512], *entry, **grown;
  size_t i, klen, vlen;
  va_list ap;
  if (!sim || !key || !fmt) return;
  va_start(ap, fmt);
  vsnprintf(value, sizeof value, fmt, ap);
  va_end(ap);
  px_log(sim->ctx, PX_LOG_LEVEL_INFO, "automatic: %s = %s", key, value);
  klen = strlen(key);
  vlen = strlen(value);
  entry = px_mem_alloc(sim->ctx, "automatic setting", klen + vlen + 2);
  if (!entry) return; /* the log line above still records it */
  memcpy(entry, key, klen);
  entry[klen] = '\t';
  memcpy(entry + klen + 1, value, vlen + 1);
  for (i = 0; i < sim->nauto; ++i)
    if (strncmp(sim->autos[i], key, klen) == 0 && sim->autos[i][klen] == '\t') {
      px_mem_free(sim->ctx, sim->autos[i]);
      sim->autos[i] = entry;
      return;
    }
  grown =
      px_mem_realloc(sim->ctx, "automatic settings", sim->autos, (sim->nauto + 1) * sizeof *grown);
  if (!grown) {
    px_mem_free(sim->ctx, entry);
    return;
  }
  sim->autos = grown;
  sim->autos[sim->nauto++] = entry;
}

/* A byte count for people: "812 MB", "8.1 TB" (powers of 1000), "24 GiB"
 * for the machine's memory (powers of 1024, as the system reports it). */
static void px_sim_bytes_text(double b, int binary, char *buf, size_t size) {
  static const char *const dec[] = {"B", "kB", "MB", "GB", "TB", "PB", "EB"};
  static const char *const bin[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  double unit = binary ? 1024.0 : 1000.0;
  int k = 0;
  while (b >= unit && k < 6) {
    b /= unit;
    ++k;
  }
  snprintf(buf, size, "%.*f %s", b < 10 && k ? 1 : 0, b, binary ? bin[k] : dec[k]);
}

enum px_status px_sim_require_memory(struct px_sim *sim, double bytes, const char *key,
                                     const char *what) {
  long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  double have = pages > 0 && page > 0 ? (double)pages * (double)page : 0;
  double limit = sim ? (double)px_context_memory_limit(sim->ctx) : 0;
  int limited = limit > 0 && (have <= 0 || limit < have);
  char need[32], mem[32], *value = NULL;
  enum px_status st;
  if (!sim) return PX_STATUS_INVALID;
  if (limited) have = limit;
  if (isfinite(bytes) && (have <= 0 || bytes <= have)) return PX_STATUS_OK;
  px_sim_bytes_text(isfinite(bytes) ? bytes : 1e300, 0, need, sizeof need);
  px_sim_bytes_text(have, 1, mem, sizeof mem);
  if (px_case_value_text(sim->c, key, &value) != PX_STATUS_OK) value = NULL;
  st = px_case_fail(
      sim->c, key, "%s%s%s needs %s for %s; %s %s%s", value ? key : "", value ? " = " : "",
      value ? value : "this size", isfinite(bytes) ? need : "more than can be counted", what,
      limited ? "the run's memory limit is" : "this machine has", mem, limited ? "" : " of memory");
  px_mem_free(sim->ctx, value);
  return st;
}

enum px_status px_sim_output_path(const struct px_sim *sim, const char *name, char *buf,
                                  size_t size) {
  return px_file_join(sim->ctx, buf, size, sim->outdir, name);
}
