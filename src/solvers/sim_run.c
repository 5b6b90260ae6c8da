/* The run driver: the time loop, its outputs, summary.json and checkpoints. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/file.h"
#include "partix/memory.h"
#include "partix/progress.h"
#include "partix/timer.h"
#include "partix/version.h"
#include "solvers/sim_impl.h"
#include "solvers/summary.h"

/* ---- outputs ------------------------------------------------------------ */

void px_sim_output_info(struct px_sim *sim, struct px_sim_output *o) {
  memset(o, 0, sizeof *o);
  o->sim = sim;
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

enum px_status px_sim_gather(struct px_sim *sim) {
  if (px_comm_size(sim->comm) < 2 || !sim->solver->gather || sim->gathered == sim->step)
    return PX_STATUS_OK;
  sim->gathered = sim->step;
  return px_comm_agree(sim->comm, sim->ctx, sim->solver->gather(sim->state), NULL);
}

/* The outputs due (rank 0 writes them after the solver's gather). */
static enum px_status px_sim_write_outputs(struct px_sim *sim, enum px_sim_due due) {
  struct px_sim_output o;
  const struct px_solver_i *s = sim->solver;
  int series = sim->csv && s->series && px_sim_due(sim->step, sim->log_every, due);
  int snapshot = sim->vtk && s->snapshot && px_sim_due(sim->step, sim->every, due);
  int picture = sim->png && s->picture && px_sim_due(sim->step, sim->png_every, due);
  if (!series && !snapshot && !picture) return PX_STATUS_OK;
  sim->wrote = 1; /* on every rank: the schedule is every rank's */
  if (snapshot || picture || !s->gather_series || px_comm_size(sim->comm) < 2 ||
      sim->gathered == sim->step)
    PX_TRY(px_sim_gather(sim));
  else /* a CSV row alone: what it reads, not the whole state */
    PX_TRY(px_comm_agree(sim->comm, sim->ctx, s->gather_series(sim->state), NULL));
  if (!sim->rank0) return PX_STATUS_OK;
  px_sim_output_info(sim, &o);
  o.final = due == PX_SIM_DUE_FINAL;
  if (series) PX_TRY(s->series(sim->state, &o));
  if (snapshot) PX_TRY(s->snapshot(sim->state, &o));
  if (picture) PX_TRY(s->picture(sim->state, &o));
  return PX_STATUS_OK;
}

static enum px_status px_sim_outputs(struct px_sim *sim, enum px_sim_due due) {
  enum px_status s;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  px_timeset_start(sim->timers, sim->t_output);
  sim->wrote = 0;
  s = px_sim_write_outputs(sim, due);
  px_timeset_stop(sim->timers, sim->t_output);
  s = px_comm_agree(sim->comm, sim->ctx, s, NULL);
  if (s == PX_STATUS_OK && sim->wrote) px_sim_notify(sim, PX_SIM_EVENT_OUTPUT);
  return s;
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
  if (sim->mode != PX_SIM_MODE_RUN || !sim->rank0) return PX_STATUS_OK;
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

/* ---- checkpoints -------------------------------------------------------- */

static enum px_status px_sim_save(struct px_sim *sim) {
  struct px_checkpoint_writer *w = NULL;
  const char *text;
  double dt;
  enum px_status s;
  if (!sim->solver->save)
    return px_context_fail(sim->ctx, PX_STATUS_UNSUPPORTED,
                           "the %s solver cannot write checkpoints", sim->solver->name);
  PX_TRY(px_sim_gather(sim));
  if (!sim->rank0) return PX_STATUS_OK;
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
  px_log(sim->ctx, PX_LOG_LEVEL_DEBUG, "checkpoint at step %ld written to %s", sim->step,
         sim->ckpath);
  return PX_STATUS_OK;
}

/* One checkpoint of the global state, written by rank 0 (atomically: the
 * previous one stays whole until the new one is complete). */
static enum px_status px_sim_write_checkpoint(struct px_sim *sim) {
  enum px_status s;
  px_timeset_start(sim->timers, sim->t_checkpoint);
  s = px_comm_agree(sim->comm, sim->ctx, px_sim_save(sim), NULL);
  px_timeset_stop(sim->timers, sim->t_checkpoint);
  if (s == PX_STATUS_OK) {
    sim->last_checkpoint = sim->step;
    px_sim_notify(sim, PX_SIM_EVENT_CHECKPOINT);
  }
  return s;
}

enum px_status px_sim_checkpoint(struct px_sim *sim) {
  if (!sim) return PX_STATUS_INVALID;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  if (sim->rank0) PX_TRY(px_sim_lock_outdir(sim)); /* again, after an end or a stop */
  PX_TRY(px_sim_write_checkpoint(sim));
  return px_comm_agree(sim->comm, sim->ctx, px_sim_write_summary(sim, "running", NULL), NULL);
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
  /* stopped: the folder is free (for a resume or a render, also from this
     process) until this run writes again */
  px_sim_unlock_outdir(sim);
  return s;
}

/* The outputs of the initial state, once, before the first step of a run
 * that starts at step 0 (a resumed run has them already). */
static enum px_status px_sim_begin(struct px_sim *sim) {
  enum px_status s;
  if (sim->started) return PX_STATUS_OK;
  sim->started = 1;
  if (sim->step != 0 || sim->resumed) return PX_STATUS_OK;
  s = px_sim_outputs(sim, PX_SIM_DUE_ALL);
  return s == PX_STATUS_OK ? s : px_sim_record_failure(sim, s);
}

/* The end of a run, once: the last state's outputs whatever the schedule,
 * the checkpoint, the solver's end-of-run products and summary.json. */
static enum px_status px_sim_end(struct px_sim *sim) {
  struct px_sim_output o;
  enum px_status s;
  if (sim->ended) return PX_STATUS_OK;
  sim->ended = 1;
  if (sim->mode != PX_SIM_MODE_RUN) return PX_STATUS_OK;
  s = px_sim_outputs(sim, PX_SIM_DUE_FINAL);
  if (s == PX_STATUS_OK) s = px_sim_write_checkpoint(sim);
  if (s == PX_STATUS_OK && sim->solver->finish && sim->rank0) {
    px_sim_output_info(sim, &o);
    o.final = 1;
    s = sim->solver->finish(sim->state, &o);
  }
  s = px_comm_agree(sim->comm, sim->ctx, s, NULL);
  if (s == PX_STATUS_OK)
    s = px_comm_agree(sim->comm, sim->ctx, px_sim_write_summary(sim, "finished", NULL), NULL);
  if (s != PX_STATUS_OK) return px_sim_record_failure(sim, s);
  /* finished: the folder is free, though the run may stay open (Python) */
  px_sim_unlock_outdir(sim);
  return s;
}

/* 1 when the run has reached its end: its last step, or its goal (a solver
 * that is done early, e.g. a converged relaxation). */
static int px_sim_reached_end(struct px_sim *sim) {
  if (sim->step >= sim->nsteps) return 1;
  if (sim->solver->done && sim->solver->done(sim->state)) {
    px_log(sim->ctx, PX_LOG_LEVEL_INFO, "%s: done at step %ld of at most %ld (t = %.9g s)",
           sim->solver->name, sim->step, sim->nsteps, (double)sim->step * sim->dt);
    return 1;
  }
  return 0;
}

/* A step with the outputs that fall due; the step-0 outputs before the
 * first, and the end-of-run products after the last (so a loop of steps
 * leaves the folder px_sim_run leaves). */
enum px_status px_sim_step(struct px_sim *sim) {
  enum px_status s;
  int interrupted;
  if (!sim) return PX_STATUS_INVALID;
  if (sim->ended)
    return px_context_fail(sim->ctx, PX_STATUS_INVALID,
                           "px_sim_step: the run has ended at step %ld (t = %.9g s)", sim->step,
                           (double)sim->step * sim->dt);
  /* again, where an interrupt released the folder (Python: step() after
     KeyboardInterrupt) */
  if (sim->mode == PX_SIM_MODE_RUN && sim->rank0 && sim->log) PX_TRY(px_sim_lock_outdir(sim));
  PX_TRY(px_sim_begin(sim));
  px_timeset_start(sim->timers, sim->t_step);
  s = sim->solver->step(sim->state, sim->step, (double)sim->step * sim->dt, sim->dt);
  /* one rank's failure (or Ctrl-C) is every rank's */
  interrupted = px_context_interrupted(sim->ctx);
  s = px_comm_agree(sim->comm, sim->ctx, s, &interrupted);
  sim->stop = interrupted;
  px_timeset_stop(sim->timers, sim->t_step);
  if (s != PX_STATUS_OK) return px_sim_diagnose(sim, s);
  sim->step++;
  PX_TRY(px_sim_outputs(sim, PX_SIM_DUE_SCHEDULED));
  if (sim->mode == PX_SIM_MODE_RUN && sim->ck_every > 0 && sim->step % sim->ck_every == 0 &&
      sim->step < sim->nsteps)
    PX_TRY(px_sim_checkpoint(sim));
  /* a run (not a check of a checkpoint, whose steps may go on) */
  if (sim->mode == PX_SIM_MODE_RUN && px_sim_reached_end(sim)) PX_TRY(px_sim_end(sim));
  px_sim_notify(sim, PX_SIM_EVENT_STEP);
  return PX_STATUS_OK;
}

/* run.log on K > 1 ranks: the time inside px_comm calls (messages, and
 * waits for slower ranks) and what rank 0 sent per step, since the loop's
 * start (comm0, ops0, bytes0 at step0): the inputs of the scaling model in
 * docs/running.md. Collective. */
static void px_sim_log_comm(struct px_sim *sim, double wall, double comm0, double ops0,
                            double bytes0, long step0) {
  double c = px_comm_seconds(sim->comm) - comm0, most = c, ops, bytes;
  double steps = sim->step > step0 ? (double)(sim->step - step0) : 1.0;
  if (px_comm_allreduce_double(sim->comm, &most, 1, PX_COMM_MAX) != PX_STATUS_OK) return;
  px_comm_traffic(sim->comm, &ops, &bytes);
  px_log(sim->ctx, PX_LOG_LEVEL_INFO,
         "communication (messages and waits for other ranks): %.3f s on rank 0, at most "
         "%.3f s on a rank, of %.3f s; per step on rank 0: %.3g ms, %.4g operations, %.4g bytes "
         "sent",
         c, most, wall, 1e3 * c / steps, (ops - ops0) / steps, (bytes - bytes0) / steps);
}

enum px_status px_sim_run(struct px_sim *sim) {
  struct px_progress *progress = NULL, *logged = NULL;
  double wall0, comm0, ops0, bytes0;
  long step0;
  enum px_status s = PX_STATUS_OK;
  if (!sim) return PX_STATUS_INVALID;
  wall0 = px_time_now();
  comm0 = px_comm_seconds(sim->comm);
  px_comm_traffic(sim->comm, &ops0, &bytes0);
  step0 = sim->step;
  PX_TRY(px_sim_begin(sim));
  if (sim->progress_out)
    PX_TRY(px_progress_create(sim->ctx, sim->progress_out, sim->progress_tty, sim->nsteps, 10.0,
                              &progress));
  /* plain progress lines in run.log, whatever the console shows */
  if (sim->log &&
      px_progress_create(sim->ctx, sim->log, 0, sim->nsteps, 60.0, &logged) != PX_STATUS_OK)
    logged = NULL;
  while (!sim->ended && sim->step < sim->nsteps) {
    long count;
    s = px_sim_step(sim);
    if (s != PX_STATUS_OK) break;
    count = sim->solver->count ? sim->solver->count(sim->state) : -1;
    px_progress_update(progress, sim->step, (double)sim->step * sim->dt, count);
    px_progress_update(logged, sim->step, (double)sim->step * sim->dt, count);
    if (sim->ended) break; /* its last step, or its goal: the products are written */
    if (sim->mode != PX_SIM_MODE_RUN && px_sim_reached_end(sim)) break;
    if (sim->stop || (px_comm_size(sim->comm) < 2 && px_context_interrupted(sim->ctx))) {
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
  if (s != PX_STATUS_OK) {
    /* the end-of-run products record their own failure */
    return sim->ended ? s : px_sim_record_failure(sim, s);
  }
  /* a run resumed at its last step (killed before its end-of-run products) */
  PX_TRY(px_sim_end(sim));
  {
    double wall = px_time_now() - wall0, peak = (double)px_mem_peak(sim->ctx, NULL) / 1048576.0;
    /* over ranks: the other ranks' largest and smallest peak too (rank 0
     * also holds what the outputs gather) */
    double others[2] = {0.0, 0.0};
    char tail[96] = "";
    if (px_comm_size(sim->comm) > 1) {
      px_sim_log_comm(sim, wall, comm0, ops0, bytes0, step0);
      others[0] = sim->rank0 ? 0.0 : peak;
      others[1] = sim->rank0 ? -HUGE_VAL : -peak;
      if (px_comm_allreduce_double(sim->comm, others, 2, PX_COMM_MAX) == PX_STATUS_OK)
        snprintf(tail, sizeof tail, " on rank 0, %.1f-%.1f MiB on ranks 1-%d", -others[1],
                 others[0], px_comm_size(sim->comm) - 1);
    }
    /* where the wall time went: the solver's steps (over ranks with the
     * waits for the others), the outputs, the checkpoints (their fsync) */
    px_log(sim->ctx, PX_LOG_LEVEL_INFO,
           "%ld steps in %.3f s (%.4g steps/s; steps %.3f s, outputs %.3f s, checkpoints %.3f s); "
           "peak memory %.1f MiB%s; output in %s",
           sim->step - step0, wall, wall > 0 ? (double)(sim->step - step0) / wall : 0.0,
           px_timeset_total(sim->timers, sim->t_step), px_timeset_total(sim->timers, sim->t_output),
           px_timeset_total(sim->timers, sim->t_checkpoint), peak, tail, sim->outdir);
  }
  return PX_STATUS_OK;
}
