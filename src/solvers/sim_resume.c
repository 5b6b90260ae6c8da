/* The run driver: resuming a run from its checkpoint, and rendering. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "io/ioutil.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "solvers/sim_impl.h"

/* ---- summary.json of an earlier segment --------------------------------- */

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
  char status[32];
  px_sim_summary_field(ctx, dir, "status", status, sizeof status);
  return strcmp(status, "finished") == 0;
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

/* 1 if paths a and b name the same existing folder. */
static int px_sim_same_dir(const char *a, const char *b) {
  struct stat sa, sb;
  return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* Keys of every case that may change when a run is resumed: how far it
 * runs, what it writes, where it runs. Everything else defines the state
 * stored in the checkpoint. */
static const char *const px_sim_resume_keys[] = {"title",
                                                 "time.steps",
                                                 "time.end",
                                                 "time.dt",
                                                 "output",
                                                 "backend.type",
                                                 "backend.device",
                                                 "backend.node_devices",
                                                 "backend.threads",
                                                 "backend.workgroup",
                                                 NULL};

/* 1 if `key` is `allowed` or inside it ("output" covers "output.every"). */
static int px_sim_key_within(const char *key, const char *allowed) {
  size_t n = strlen(allowed);
  return strncmp(key, allowed, n) == 0 && (key[n] == '\0' || key[n] == '.' || key[n] == '[');
}

/* 1 if `key` is within one of the keys of list (NULL-terminated; NULL: none). */
static int px_sim_key_in(const char *key, const char *const *list) {
  for (size_t k = 0; list && list[k]; ++k)
    if (px_sim_key_within(key, list[k])) return 1;
  return 0;
}

/* The key of override "key=value" into key. */
static void px_sim_override_key(const char *override, char *key, size_t size) {
  const char *eq = strchr(override, '=');
  snprintf(key, size, "%.*s", eq ? (int)(eq - override) : (int)strlen(override), override);
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
  size_t i;
  for (i = 0; i < n; ++i) {
    char key[512], *a = NULL, *b = NULL, list[1024];
    int same;
    enum px_status st;
    px_sim_override_key(overrides[i], key, sizeof key);
    if (px_sim_key_in(key, px_sim_resume_keys) ||
        px_sim_key_in(key, solver ? solver->resume_keys : NULL))
      continue;
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

/* Drawing a run's pictures again takes picture settings only (output.*
 * but its folder, title, backend.*, and the solver's resume keys: its
 * picture and report settings): the pictures show the stored state at its
 * stored time, which every other key would misdescribe (a changed modulus
 * or time step draws the stored displacements with other stresses or at
 * another time), and they go into the run's own folder. */
static const char *const px_sim_render_keys[] = {"title", "output", "backend", NULL};

static enum px_status px_sim_check_render_keys(struct px_context *ctx, const char *checkpoint,
                                               const struct px_case *stored,
                                               const char *const *overrides, size_t n) {
  const struct px_solver_i *solver = px_solver_find(px_case_solver(stored));
  size_t i;
  for (i = 0; i < n; ++i) {
    char key[512];
    px_sim_override_key(overrides[i], key, sizeof key);
    if (px_sim_key_within(key, "output.dir"))
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "--set %s: render draws the pictures of %s again in that run's "
                             "own folder: output.dir cannot change.\nTo keep the pictures "
                             "already there, copy the folder (cp -a) and render the copy.",
                             overrides[i], checkpoint);
    if (!px_sim_key_in(key, px_sim_render_keys) &&
        !px_sim_key_in(key, solver ? solver->resume_keys : NULL))
      return px_context_fail(
          ctx, PX_STATUS_CONFIG,
          "--set %s: render draws the state stored in %s, in its own folder: "
          "it takes picture settings only (output.*, title, backend.*, the "
          "solver's picture keys).\nTo see the run with %s changed, run it again "
          "(partix run DIR/case.yaml --out OTHER --set ...).",
          overrides[i], checkpoint, key);
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

/* The folder a run from `checkpoint` continues in, into dir: the
 * checkpoint's own, which holds the record of its earlier steps (the series,
 * pictures, summary.json) that a folder of its own would lack. Resuming
 * (RUN mode), output.dir (c, from the overrides) may name that folder only,
 * and a summary.json there must be of the checkpoint's solver (a checkpoint
 * copied into another run's folder would continue that folder's record with
 * another run). */
static enum px_status px_sim_resume_folder(struct px_context *ctx, const char *checkpoint,
                                           const struct px_checkpoint *ck, struct px_case *c,
                                           const char *const *overrides, size_t n,
                                           enum px_sim_mode mode, char *dir, size_t size) {
  char solver[64];
  const char *to = NULL;
  size_t i;
  int has_dir = 0;
  px_sim_dirname(checkpoint, dir, size);
  if (mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  px_sim_summary_field(ctx, dir, "solver", solver, sizeof solver);
  if (solver[0] && strcmp(solver, "unreadable") != 0 && strcmp(solver, "unknown") != 0 &&
      strcmp(solver, px_checkpoint_solver(ck)) != 0)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s is a checkpoint of a %s run, but its folder %s holds a %s run "
                           "(summary.json): a checkpoint resumes in the folder of its own run",
                           checkpoint, px_checkpoint_solver(ck), dir, solver);
  for (i = 0; i < n; ++i)
    if (strncmp(overrides[i], "output.dir=", 11) == 0) has_dir = 1;
  if (!has_dir) return PX_STATUS_OK;
  PX_TRY(px_case_get_string(c, "output.dir", &to));
  if (px_sim_same_dir(dir, to)) return PX_STATUS_OK;
  return px_case_fail(c, "output.dir",
                      "a run resumes in its own folder %s, which holds the record of its "
                      "earlier steps: resumed into %s, that folder would hold the last part "
                      "only.\nTo branch the run, copy its folder (cp -a %s %s) and resume "
                      "the copy.",
                      dir, to, dir, to);
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
  enum px_status s;
  if (!ctx || !checkpoint || !out || (noverrides && !overrides)) return PX_STATUS_INVALID;
  *out = NULL;
  s = px_checkpoint_open(ctx, checkpoint, &ck);
  if (s == PX_STATUS_OK) s = px_checkpoint_find(ck, "case", &type, &len);
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
  } else if (mode == PX_SIM_MODE_RENDER) {
    s = px_sim_check_render_keys(ctx, checkpoint, stored, overrides, noverrides);
    if (s != PX_STATUS_OK) goto done;
  }
  s = px_sim_resume_folder(ctx, checkpoint, ck, c, overrides, noverrides, mode, dir, sizeof dir);
  if (s != PX_STATUS_OK) goto done;
  s = px_sim_build(ctx, c, mode, dir, 0, &sim);
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
  /* every rank reads the checkpoint; each learns whether any failed */
  s = px_comm_agree(px_context_comm(ctx), ctx, s, NULL);
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
  /* its pictures go into the run's folder: not while a run writes it */
  if (sim->rank0) PX_TRY(px_sim_lock_outdir(sim));
  px_sim_output_info(sim, &o);
  o.resumed = 0;
  o.render = 1;
  o.pictures = 1;
  if (sim->solver->picture) PX_TRY(sim->solver->picture(sim->state, &o));
  if (sim->solver->finish) PX_TRY(sim->solver->finish(sim->state, &o));
  return PX_STATUS_OK;
}
