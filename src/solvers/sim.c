/* The run driver: one time loop for every solver. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "partix/file.h"
#include "partix/memory.h"
#include "partix/progress.h"
#include "partix/timer.h"
#include "solvers/solver.h"

#define PX_SIM_PATH_MAX 4096

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
  int outputs_since_resume;
  long last_checkpoint; /* step of the last checkpoint written, -1 none */
  struct px_timeset *timers; /* owned */
  int t_step, t_output, t_checkpoint;
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

/* Backend, precision and output settings from the case. */
static enum px_status px_sim_configure(struct px_sim *sim) {
  const char *type = NULL, *prec = NULL, *dir = NULL;
  long device = 0, threads = 0, workgroup = 0;
  PX_TRY(px_case_get_string(sim->c, "backend.type", &type));
  PX_TRY(px_sim_get_long(sim, "backend.device", &device));
  PX_TRY(px_sim_get_long(sim, "backend.threads", &threads));
  PX_TRY(px_sim_get_long(sim, "backend.workgroup", &workgroup));
  PX_TRY(px_case_get_string(sim->c, "backend.precision", &prec));
  if (px_precision_parse(prec, &sim->precision) != PX_STATUS_OK)
    return px_case_fail(sim->c, "backend.precision", "unknown precision '%s'", prec);
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
  return PX_STATUS_OK;
}

/* dt from the case or the solver, and the number of steps. */
static enum px_status px_sim_schedule(struct px_sim *sim) {
  if (px_case_has(sim->c, "time.dt")) {
    PX_TRY(px_case_get_real(sim->c, "time.dt", &sim->dt));
  } else if (sim->solver->time_step) {
    PX_TRY(sim->solver->time_step(sim->state, &sim->dt));
  } else {
    return px_case_fail(sim->c, "time", "missing required key 'dt' (time step [s]): the %s solver "
                        "does not choose one automatically", sim->solver->name);
  }
  if (!(sim->dt > 0) || !isfinite(sim->dt))
    return px_context_fail(sim->ctx, PX_STATUS_INTERNAL, "invalid time step %g", sim->dt);
  if (px_case_has(sim->c, "time.steps")) {
    PX_TRY(px_case_get_int(sim->c, "time.steps", &sim->nsteps));
  } else {
    double end = 0;
    PX_TRY(px_case_get_real(sim->c, "time.end", &end));
    /* the last step may overshoot `end` by less than one dt */
    sim->nsteps = (long)ceil(end / sim->dt - 1e-9);
    if (sim->nsteps < 1) sim->nsteps = 1;
  }
  return PX_STATUS_OK;
}

static enum px_status px_sim_build(struct px_context *ctx, struct px_case *c,
                                   enum px_sim_mode mode, struct px_sim **out) {
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
  sim->progress_out = stderr;
  sim->progress_tty = -1;
  *out = sim;
  sim->solver = px_solver_find(solver_name);
  if (!sim->solver)
    return px_case_fail(c, "solver", "solver '%s' is not built into this partix",
                        solver_name ? solver_name : "");
  PX_TRY(px_timeset_create(ctx, &sim->timers));
  sim->t_step = px_timeset_slot(sim->timers, "solver step");
  sim->t_output = px_timeset_slot(sim->timers, "output");
  sim->t_checkpoint = px_timeset_slot(sim->timers, "checkpoint");
  PX_TRY(px_sim_configure(sim));
  if (mode == PX_SIM_MODE_RUN) PX_TRY(px_file_mkdirs(ctx, sim->outdir));
  PX_TRY(sim->solver->create(sim, &sim->state));
  PX_TRY(px_sim_schedule(sim));
  if (mode == PX_SIM_MODE_RUN) {
    char path[PX_SIM_PATH_MAX];
    PX_TRY(px_sim_output_path(sim, "case.yaml", path, sizeof path));
    PX_TRY(px_case_write_resolved(c, path));
  }
  return PX_STATUS_OK;
}

enum px_status px_sim_create(struct px_context *ctx, struct px_case *c, enum px_sim_mode mode,
                             struct px_sim **out) {
  enum px_status s;
  if (!ctx || !c || !out) {
    px_case_free(c);
    return PX_STATUS_INVALID;
  }
  s = px_sim_build(ctx, c, mode, out);
  if (s != PX_STATUS_OK) {
    px_sim_free(*out);
    *out = NULL;
  }
  return s;
}

void px_sim_free(struct px_sim *sim) {
  if (!sim) return;
  if (sim->state && sim->solver && sim->solver->destroy) sim->solver->destroy(sim->state);
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

static void px_sim_output_info(const struct px_sim *sim, struct px_sim_output *o) {
  o->step = sim->step;
  o->time = (double)sim->step * sim->dt;
  o->dir = sim->outdir;
  o->resumed = sim->resumed && !sim->outputs_since_resume;
  o->resume_time = sim->resume_time;
}

/* The outputs that fall due after `sim->step` steps (force: all of them). */
static enum px_status px_sim_outputs(struct px_sim *sim, int force) {
  struct px_sim_output o;
  const struct px_solver_i *s = sim->solver;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  px_sim_output_info(sim, &o);
  px_timeset_start(sim->timers, sim->t_output);
  if (sim->csv && s->series && (force || sim->step % sim->log_every == 0))
    PX_TRY(s->series(sim->state, &o));
  if (sim->vtk && s->snapshot && (force || sim->step % sim->every == 0))
    PX_TRY(s->snapshot(sim->state, &o));
  if (sim->png && s->picture && (force || sim->step % sim->png_every == 0))
    PX_TRY(s->picture(sim->state, &o));
  px_timeset_stop(sim->timers, sim->t_output);
  sim->outputs_since_resume = 1;
  return PX_STATUS_OK;
}

enum px_status px_sim_checkpoint(struct px_sim *sim) {
  struct px_checkpoint_writer *w = NULL;
  const char *text;
  double dt;
  enum px_status s;
  if (!sim) return PX_STATUS_INVALID;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
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

/* Add where the failure happened and what is left to resume from. */
static enum px_status px_sim_diagnose(struct px_sim *sim, enum px_status s) {
  char where[256];
  snprintf(where, sizeof where, "step %ld (t = %.9g)", sim->step + 1,
           (double)(sim->step + 1) * sim->dt);
  px_context_prefix(sim->ctx, "%s", where);
  if (sim->mode == PX_SIM_MODE_RUN) {
    if (sim->last_checkpoint >= 0)
      px_context_append(sim->ctx, "\nthe last good checkpoint is %s (step %ld); resume with "
                        "`partix resume %s` after changing the case (e.g. --set time.dt=...)",
                        sim->ckpath, sim->last_checkpoint, sim->ckpath);
    else
      px_context_append(sim->ctx, "\nno checkpoint was written before the failure "
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
  PX_TRY(px_sim_outputs(sim, 0));
  if (sim->mode == PX_SIM_MODE_RUN && sim->ck_every > 0 && sim->step % sim->ck_every == 0 &&
      sim->step < sim->nsteps)
    PX_TRY(px_sim_checkpoint(sim));
  return PX_STATUS_OK;
}

enum px_status px_sim_run(struct px_sim *sim) {
  struct px_progress *progress = NULL;
  struct px_sim_output o;
  double wall0;
  long step0;
  enum px_status s = PX_STATUS_OK;
  if (!sim) return PX_STATUS_INVALID;
  wall0 = px_time_now();
  step0 = sim->step;
  if (sim->step == 0 && !sim->resumed) PX_TRY(px_sim_outputs(sim, 1));
  if (sim->progress_out)
    PX_TRY(px_progress_create(sim->ctx, sim->progress_out, sim->progress_tty, sim->nsteps, 10.0,
                              &progress));
  while (sim->step < sim->nsteps) {
    s = px_sim_step(sim);
    if (s != PX_STATUS_OK) break;
    px_progress_update(progress, sim->step, (double)sim->step * sim->dt,
                       sim->solver->count ? sim->solver->count(sim->state) : -1);
    if (px_context_interrupted(sim->ctx)) {
      px_progress_finish(progress);
      px_progress_free(progress);
      progress = NULL;
      s = px_sim_checkpoint(sim);
      if (s != PX_STATUS_OK) return s;
      return px_context_fail(sim->ctx, PX_STATUS_INTERRUPTED,
                             "interrupted at step %ld; checkpoint written to %s (continue with "
                             "`partix resume %s`)", sim->step, sim->ckpath, sim->ckpath);
    }
  }
  if (progress) {
    if (s == PX_STATUS_OK) px_progress_finish(progress);
    px_progress_free(progress);
  }
  if (s != PX_STATUS_OK) return s;
  if (sim->mode == PX_SIM_MODE_RUN) {
    PX_TRY(px_sim_checkpoint(sim));
    if (sim->solver->finish) {
      px_sim_output_info(sim, &o);
      PX_TRY(sim->solver->finish(sim->state, &o));
    }
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

enum px_status px_sim_resume(struct px_context *ctx, const char *checkpoint,
                             const char *const *overrides, size_t noverrides,
                             struct px_sim **out) {
  struct px_checkpoint *ck = NULL;
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  enum px_dtype type;
  uint64_t len = 0, count = 0;
  char *text = NULL;
  const char **all = NULL;
  char dirset[PX_SIM_PATH_MAX + 16], dir[PX_SIM_PATH_MAX];
  double dt = 0;
  size_t i;
  int has_dir = 0;
  enum px_status s;
  if (!ctx || !checkpoint || !out) return PX_STATUS_INVALID;
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
  /* The run continues next to its checkpoint unless told otherwise. */
  for (i = 0; i < noverrides; ++i)
    if (strncmp(overrides[i], "output.dir=", 11) == 0) has_dir = 1;
  all = px_mem_calloc(ctx, "overrides", noverrides + 2, sizeof *all);
  if (!all) {
    s = PX_STATUS_NOMEM;
    goto done;
  }
  for (i = 0; i < noverrides; ++i) all[i] = overrides[i];
  if (!has_dir) {
    px_sim_dirname(checkpoint, dir, sizeof dir);
    snprintf(dirset, sizeof dirset, "output.dir=%s", dir);
    all[noverrides++] = dirset;
  }
  s = px_case_load_string(ctx, checkpoint, text, (size_t)len, all, noverrides, &c);
  if (s != PX_STATUS_OK) goto done;
  if (px_case_solver(c) && strcmp(px_case_solver(c), px_checkpoint_solver(ck)) != 0) {
    s = px_context_fail(ctx, PX_STATUS_FORMAT, "%s: checkpoint of solver '%s' but its case says '%s'",
                        checkpoint, px_checkpoint_solver(ck), px_case_solver(c));
    px_case_free(c);
    goto done;
  }
  s = px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim);
  if (s != PX_STATUS_OK) goto done;
  if (dt > 0 && dt != sim->dt) {
    px_log(ctx, PX_LOG_LEVEL_WARN, "time step changed from %.9g to %.9g on resume; the "
           "continuation is not bit-identical to an uninterrupted run", dt, sim->dt);
  }
  sim->step = (long)px_checkpoint_step(ck);
  sim->resumed = 1;
  sim->resume_time = px_checkpoint_time(ck);
  sim->last_checkpoint = sim->step;
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
  px_log(ctx, PX_LOG_LEVEL_INFO, "resuming %s at step %ld (t = %.9g) of %ld", sim->solver->name,
         sim->step, sim->resume_time, sim->nsteps);
done:
  px_mem_free(ctx, text);
  px_mem_free(ctx, all);
  px_checkpoint_close(ck);
  if (s != PX_STATUS_OK) {
    px_sim_free(sim);
    return s;
  }
  *out = sim;
  return PX_STATUS_OK;
}

enum px_status px_sim_render(struct px_sim *sim) {
  struct px_sim_output o;
  if (!sim) return PX_STATUS_INVALID;
  if (!sim->solver->picture && !sim->solver->finish)
    return px_context_fail(sim->ctx, PX_STATUS_UNSUPPORTED, "the %s solver draws no pictures",
                           sim->solver->name);
  px_sim_output_info(sim, &o);
  o.resumed = 0;
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
struct px_context *px_sim_context(const struct px_sim *sim) { return sim ? sim->ctx : NULL; }
struct px_backend *px_sim_backend(const struct px_sim *sim) { return sim ? sim->be : NULL; }
enum px_precision px_sim_precision(const struct px_sim *sim) {
  return sim ? sim->precision : PX_PRECISION_DOUBLE;
}
enum px_sim_mode px_sim_mode(const struct px_sim *sim) {
  return sim ? sim->mode : PX_SIM_MODE_CHECK;
}

enum px_status px_sim_output_path(const struct px_sim *sim, const char *name, char *buf,
                                  size_t size) {
  return px_file_join(sim->ctx, buf, size, sim->outdir, name);
}
