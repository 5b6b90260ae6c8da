/* The run driver: one time loop for every solver (building a run, its input
 * files, accessors; run.log in sim_log.c, the loop in sim_run.c, resuming in
 * sim_resume.c). */
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT: the cores a process may use */
#include <math.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <errno.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/text.h"
#include "io/ioutil.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "partix/timer.h"
#include "partix/version.h"
#include "solvers/solver.h"
#include "solvers/sim_impl.h"

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
/* ---- input files -------------------------------------------------------- */

/* 64-bit FNV-1a of a buffer (names an input file's content in summary.json). */
uint64_t px_sim_fnv(const char *data, size_t len) {
  return px_text_fnv1a(PX_FNV1A_OFFSET, data, len);
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
/* Warn when the threads of the cpu backend outnumber the cores this process
 * may run on (its CPU affinity: taskset, a batch system's cgroup, or mpirun,
 * which binds each of 1-2 ranks to one core by default): they would share
 * those cores and every step would wait for the descheduled one. */
static void px_sim_check_affinity(struct px_sim *sim) {
  cpu_set_t set;
  long usable;
  int threads = px_backend_threads(sim->be);
  if (!px_backend_host_memory(sim->be)) return; /* a device computes */
  if (sched_getaffinity(0, sizeof set, &set) != 0) return;
  usable = CPU_COUNT(&set);
  if (usable > 0 && threads > usable)
    px_log(sim->ctx, PX_LOG_LEVEL_WARN,
           "backend.threads = %d, but this process may run on %ld core%s (its CPU affinity)%s: "
           "the threads share %s and each step waits for the slowest",
           threads, usable, usable == 1 ? "" : "s",
           px_comm_size(sim->comm) > 1
               ? "; mpirun binds each rank to cores: give each rank T cores with "
                 "`mpirun --map-by slot:PE=T` (or --bind-to none)"
               : "",
           usable == 1 ? "it" : "them");
}

/* The case's backend; an OpenCL device per rank from backend.device and
 * backend.node_devices. */
static enum px_status px_sim_start_backend(struct px_sim *sim, const char *type, long device,
                                           long node_devices, long threads) {
  if (node_devices > 1) { /* (the cpu backend has one device, whatever the index) */
    /* share the node's devices out among its ranks */
    const int local = px_comm_local_rank(sim->comm);
    const long first = device;
    device = first + local % node_devices;
    if (px_backend_create(sim->ctx, type, (int)device, (int)threads, &sim->be) != PX_STATUS_OK) {
      char msg[1024];
      snprintf(msg, sizeof msg, "%s", px_context_message(sim->ctx));
      return px_case_fail(sim->c, "backend.node_devices",
                          "the node's rank %d takes device %ld + (%d mod %ld) = %ld: %s", local,
                          first, local, node_devices, device, msg);
    }
    if (px_comm_size(sim->comm) > 1 && !px_backend_host_memory(sim->be))
      px_log(sim->ctx, PX_LOG_LEVEL_INFO,
             "OpenCL devices shared out by node: the node's rank i uses device %ld + (i mod %ld) "
             "(%d rank%s on rank 0's node)",
             first, node_devices, px_comm_local_size(sim->comm),
             px_comm_local_size(sim->comm) == 1 ? "" : "s");
  } else if (px_backend_create(sim->ctx, type, (int)device, (int)threads, &sim->be) !=
             PX_STATUS_OK) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(sim->ctx));
    /* the key the user gave: a device that does not exist is backend.device's */
    return px_case_fail(sim->c,
                        px_case_has(sim->c, "backend.device") ? "backend.device" : "backend.type",
                        "cannot start the %s backend: %s", type, msg);
  }
  return PX_STATUS_OK;
}

static enum px_status px_sim_configure(struct px_sim *sim, const char *outdir) {
  const char *type = NULL, *prec = NULL, *dir = NULL;
  long device = 0, node_devices = 1, threads = 0, workgroup = 0;
  const int device_given = px_case_has(sim->c, "backend.device");
  PX_TRY(px_case_get_string(sim->c, "backend.type", &type));
  if (device_given)
    PX_TRY(px_sim_get_long(sim, "backend.device", &device));
  else /* the first GPU, not whatever device the ICD loader lists first */
    device = px_backend_default_device(type);
  PX_TRY(px_sim_get_long(sim, "backend.node_devices", &node_devices));
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
  PX_TRY(px_sim_start_backend(sim, type, device, node_devices, threads));
  if (!px_backend_host_memory(sim->be) && !device_given)
    px_sim_note_auto(sim, "backend.device",
                     "%ld (the first GPU or accelerator that `partix info` lists, else device 0): "
                     "%s",
                     device, px_backend_device(sim->be));
  px_sim_check_affinity(sim);
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

void px_sim_summary_field(struct px_context *ctx, const char *dir, const char *field, char *buf,
                          size_t size) {
  char path[PX_SIM_PATH_MAX], key[64], *text = NULL;
  size_t len = 0;
  const char *at;
  buf[0] = '\0';
  if (px_file_join(ctx, path, sizeof path, dir, "summary.json") != PX_STATUS_OK ||
      !px_file_exists(path))
    return;
  if (px_ioutil_read_file(ctx, path, &text, &len) != PX_STATUS_OK) {
    px_context_clear(ctx);
    snprintf(buf, size, "unreadable");
    return;
  }
  /* summary.json is partix's own output (sim_run.c): "key": "value" */
  snprintf(key, sizeof key, "\"%s\": \"", field);
  at = strstr(text, key);
  if (at) {
    at += strlen(key);
    snprintf(buf, size, "%.*s", (int)strcspn(at, "\""), at);
  } else {
    snprintf(buf, size, "unknown");
  }
  px_mem_free(ctx, text);
}

/* A new run's folder must not hold another run's record: a checkpoint, a
 * summary.json, or the case.yaml and run.log every run writes first (a run
 * that failed, or was killed before its first checkpoint, left outputs
 * that are the record of what happened: a new run would mix its files with
 * them). partix never replaces a run's results. */
static enum px_status px_sim_check_fresh(struct px_sim *sim) {
  char status[32], path[PX_SIM_PATH_MAX];
  const int has_ck = px_file_exists(sim->ckpath);
  int has_case = 0, has_log = 0;
  if (px_file_join(sim->ctx, path, sizeof path, sim->outdir, "case.yaml") == PX_STATUS_OK)
    has_case = px_file_exists(path);
  if (px_file_join(sim->ctx, path, sizeof path, sim->outdir, "run.log") == PX_STATUS_OK)
    has_log = px_file_exists(path);
  px_sim_summary_field(sim->ctx, sim->outdir, "status", status, sizeof status);
  if (!has_ck && !status[0] && !has_case && !has_log) return PX_STATUS_OK;
  /* a run in progress there says so: the folder's lock, taken now (the
     folder exists), refuses this run with "being written" */
  PX_TRY(px_sim_lock_outdir(sim));
  if (has_ck)
    return px_case_fail(sim->c, "output.dir",
                        "%s holds a run already (a checkpoint%s%s): partix does not replace a "
                        "run's results.\nContinue that run with `partix resume %s`, give this "
                        "run another folder (--out DIR), or remove %s first.",
                        sim->outdir, status[0] ? ", summary.json: " : "", status, sim->ckpath,
                        sim->outdir);
  return px_case_fail(sim->c, "output.dir",
                      "%s holds a run already (%s%s, no checkpoint): its outputs and run.log "
                      "are that run's record, which partix does not replace.\nGive this run "
                      "another folder (--out DIR), or remove %s first.",
                      sim->outdir, status[0] ? "summary.json: " : "the files of a run stopped ",
                      status[0] ? status : "before its first checkpoint", sim->outdir);
}

/* Make the run folder and lock it for this process (flock on the folder,
 * released by the kernel when the process ends, however it ends): a second
 * partix writing the same folder at the same time is refused instead of
 * interleaving two runs' files. */
enum px_status px_sim_lock_outdir(struct px_sim *sim) {
  int fd;
  if (sim->lock_fd >= 0) return PX_STATUS_OK;
  PX_TRY(px_file_mkdirs(sim->ctx, sim->outdir));
  fd = open(sim->outdir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0)
    return px_context_fail(sim->ctx, PX_STATUS_IO, "cannot open the run folder %s: %s", sim->outdir,
                           strerror(errno));
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    close(fd);
    if (err == EWOULDBLOCK && sim->mode == PX_SIM_MODE_RENDER)
      return px_context_fail(sim->ctx, PX_STATUS_CONFIG,
                             "cannot draw the pictures of %s now: another partix process is "
                             "writing that folder (wait for it to end)",
                             sim->outdir);
    if (err == EWOULDBLOCK && sim->resumed)
      return px_context_fail(sim->ctx, PX_STATUS_CONFIG,
                             "%s is being written by another partix process: a run resumes "
                             "once that one has ended",
                             sim->outdir);
    if (err == EWOULDBLOCK)
      return px_case_fail(sim->c, "output.dir",
                          "%s is being written by another partix process: two runs cannot "
                          "share a folder (wait for it, or give this run another folder, "
                          "--out DIR)",
                          sim->outdir);
    return px_context_fail(sim->ctx, PX_STATUS_IO, "cannot lock the run folder %s: %s", sim->outdir,
                           strerror(err));
  }
  sim->lock_fd = fd;
  return PX_STATUS_OK;
}

void px_sim_unlock_outdir(struct px_sim *sim) {
  if (sim->lock_fd >= 0) close(sim->lock_fd);
  sim->lock_fd = -1;
}

/* Everything of a run that writes nothing: backend, solver, schedule. In
 * RUN mode the log tee is installed first, so that what the solver logs
 * while it builds the problem reaches run.log once the folder is open. */
enum px_status px_sim_build(struct px_context *ctx, struct px_case *c, enum px_sim_mode mode,
                            const char *outdir, int fresh, struct px_sim **out) {
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
  sim->comm = px_context_comm(ctx);
  sim->rank0 = px_comm_rank(sim->comm) == 0;
  sim->gathered = -1;
  sim->lock_fd = -1;
  *out = sim;
  /* every rank of a job runs one case: ranks started with other options
     (an MPMD launch, another copy of the case file on a node) would pair
     their collectives wrongly, hang or run other physics on their share.
     First, before any collective that depends on the case. */
  if (px_comm_size(sim->comm) > 1) {
    uint64_t first = px_case_hash(c);
    enum px_status st = px_comm_bcast(sim->comm, &first, sizeof first, 0);
    if (st == PX_STATUS_OK && first != px_case_hash(c))
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "rank %d was given another case than rank 0 (its resolved case, "
                           "options applied, has hash %016llx, rank 0's %016llx): every rank of "
                           "a job runs the same case with the same options",
                           px_comm_rank(sim->comm), (unsigned long long)px_case_hash(c),
                           (unsigned long long)first);
    PX_TRY(px_comm_agree(sim->comm, ctx, st, NULL));
  }
  sim->solver = px_solver_find(solver_name);
  if (!sim->solver)
    return px_case_fail(c, "solver", "solver '%s' is not built into this partix",
                        solver_name ? solver_name : "");
  if (px_comm_size(sim->comm) > 1 && !sim->solver->ranks)
    return px_context_fail(ctx, PX_STATUS_UNSUPPORTED,
                           "the %s solver does not run a case over several MPI ranks yet "
                           "(started as %d ranks): run it on one rank, with threads "
                           "(backend.threads) or an OpenCL device",
                           sim->solver->name, px_comm_size(sim->comm));
  /* run.log holds rank 0's log: the ranks agree on what fails */
  if (mode == PX_SIM_MODE_RUN && sim->rank0) px_sim_tee_install(sim);
  if (px_comm_size(sim->comm) > 1)
    px_log(ctx, PX_LOG_LEVEL_INFO, "%d MPI ranks (rank 0 writes the run folder)",
           px_comm_size(sim->comm));
  PX_TRY(px_timeset_create(ctx, &sim->timers));
  sim->t_step = px_timeset_slot(sim->timers, "solver step");
  sim->t_output = px_timeset_slot(sim->timers, "output");
  sim->t_checkpoint = px_timeset_slot(sim->timers, "checkpoint");
  /* the ranks agree before create, whose collectives a rank that failed
     here (its own device: backend.node_devices) would never join */
  PX_TRY(px_comm_agree(sim->comm, ctx, px_sim_configure(sim, outdir), NULL));
  /* before the solver is built (it may take minutes): a folder that holds
     another run is refused at once */
  if (mode == PX_SIM_MODE_RUN && fresh)
    PX_TRY(
        px_comm_agree(sim->comm, ctx, sim->rank0 ? px_sim_check_fresh(sim) : PX_STATUS_OK, NULL));
  {
    /* test hook (tests/cli: test_mpi_fail_create_*): rank R fails the way a
       solver's create fails on one rank, while the others go on into create */
    const char *r = getenv("PX_TEST_FAIL_CREATE_RANK");
    if (r && px_comm_size(sim->comm) > 1 && atoi(r) == px_comm_rank(sim->comm))
      return px_context_fail(ctx, PX_STATUS_BACKEND,
                             "PX_TEST_FAIL_CREATE_RANK: rank %d fails in the solver's create",
                             px_comm_rank(sim->comm));
  }
  PX_TRY(sim->solver->create(sim, &sim->state));
  PX_TRY(px_sim_schedule(sim));
  return PX_STATUS_OK;
}

/* Open the run folder (RUN mode): the folder, run.log, copies of the input
 * files, and the resolved case.yaml. */
enum px_status px_sim_open_outputs(struct px_sim *sim, const char *how) {
  char path[PX_SIM_PATH_MAX], line[PX_SIM_PATH_MAX + 256];
  if (sim->mode != PX_SIM_MODE_RUN || !sim->rank0) return PX_STATUS_OK;
  PX_TRY(px_sim_lock_outdir(sim));
  /* again under the lock: another process may have started a run here
     while this one built its solver */
  if (!sim->resumed) PX_TRY(px_sim_check_fresh(sim));
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
  s = px_sim_build(ctx, c, mode, NULL, 1, out);
  if (s == PX_STATUS_OK) s = px_sim_open_outputs(*out, how);
  /* every rank learns whether any failed (rank 0 makes the folder) */
  s = px_comm_agree(px_context_comm(ctx), ctx, s, NULL);
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
  px_sim_tables_free(sim);
  if (sim->log) fclose(sim->log);
  px_sim_unlock_outdir(sim);
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
long px_sim_step_index(const struct px_sim *sim) { return sim ? sim->step : 0; }
long px_sim_step_count(const struct px_sim *sim) { return sim ? sim->nsteps : 0; }
int px_sim_ended(const struct px_sim *sim) { return sim ? sim->ended : 0; }
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
  px_text_bytes(isfinite(bytes) ? bytes : 1e300, 0, need, sizeof need);
  px_text_bytes(have, 1, mem, sizeof mem);
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
