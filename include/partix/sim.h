/* A simulation run: a validated case, a backend, a solver and the run driver
 * (time loop, output schedule, progress, checkpoints, Ctrl-C, blow-up
 * diagnosis). `partix run` and `partix resume` are thin wrappers over this. */
#ifndef PARTIX_SIM_H
#define PARTIX_SIM_H

#include <stdio.h>

#include "partix/case.h"
#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_sim;

/* Names of the solvers built into this library, NULL-terminated. */
PX_API const char *const *px_sim_solver_names(void);
/* One-line description of a solver, NULL if unknown. */
PX_API const char *px_sim_solver_summary(const char *name);

enum px_sim_mode {
  PX_SIM_MODE_RUN = 0,   /* create the output directory, write outputs */
  PX_SIM_MODE_CHECK = 1, /* build the problem to validate it; write nothing */
  PX_SIM_MODE_RENDER = 2 /* a run's state from its checkpoint, to draw its
                            pictures again (px_sim_render); writes nothing else */
};

/* Build a run from a loaded case (ownership of `c` passes to the sim, also on
 * failure). Semantic errors in the case (geometry, parameters) are reported as
 * file:line:col messages with PX_STATUS_CONFIG. */
PX_API enum px_status px_sim_create(struct px_context *ctx, struct px_case *c,
                                    enum px_sim_mode mode, struct px_sim **out);
/* Continue a run from a checkpoint, in the checkpoint's folder unless an
 * override sets output.dir. `overrides` ("key=value", may be NULL) change the
 * stored case: how far it runs (time.steps, time.end; the new end must lie
 * after the checkpoint, else PX_STATUS_CONFIG), time.dt, output.*, backend.*
 * except precision, and the keys the solver lists (pictures); an override
 * that changes any other key is refused by name (PX_STATUS_CONFIG), because
 * the checkpoint's state was built with the stored value. The run's folder
 * is not touched before every check has passed. */
PX_API enum px_status px_sim_resume(struct px_context *ctx, const char *checkpoint,
                                    const char *const *overrides, size_t noverrides,
                                    struct px_sim **out);
/* Open a run from its checkpoint: PX_SIM_MODE_RUN is px_sim_resume;
 * PX_SIM_MODE_RENDER loads the state to draw it (px_sim_render) and writes
 * nothing else: not the case, the log or the summary. */
PX_API enum px_status px_sim_open(struct px_context *ctx, const char *checkpoint,
                                  const char *const *overrides, size_t noverrides,
                                  enum px_sim_mode mode, struct px_sim **out);
/* NULL-safe. */
PX_API void px_sim_free(struct px_sim *sim);

/* Where progress goes (default stderr; is_terminal < 0: detect). */
PX_API void px_sim_set_progress(struct px_sim *sim, FILE *out, int is_terminal);
/* Run to the end time/step count. Returns PX_STATUS_INTERRUPTED after writing
 * a checkpoint when the context's interrupt flag is raised, PX_STATUS_NUMERIC
 * with a diagnosis when the solver detects a blow-up. */
PX_API enum px_status px_sim_run(struct px_sim *sim);
/* Advance one step, with the outputs that fall due. */
PX_API enum px_status px_sim_step(struct px_sim *sim);
/* Draw the pictures of the current state and the end-of-run plots again
 * (after px_sim_resume: the run's last checkpointed state), e.g. with other
 * picture settings given as overrides. */
PX_API enum px_status px_sim_render(struct px_sim *sim);
/* Write a checkpoint now (to the run's checkpoint path). */
PX_API enum px_status px_sim_checkpoint(struct px_sim *sim);

PX_API long px_sim_step_index(const struct px_sim *sim);
/* 1 once the run has ended (its last step, or its goal reached early): its
 * end-of-run products are written and px_sim_step refuses to go on. */
PX_API int px_sim_ended(const struct px_sim *sim);
PX_API long px_sim_step_count(const struct px_sim *sim);
PX_API double px_sim_time(const struct px_sim *sim);
PX_API double px_sim_dt(const struct px_sim *sim);
PX_API const char *px_sim_output_dir(const struct px_sim *sim);
PX_API const char *px_sim_checkpoint_path(const struct px_sim *sim);
PX_API const struct px_case *px_sim_case(const struct px_sim *sim);
PX_API struct px_context *px_sim_context(const struct px_sim *sim);

#ifdef __cplusplus
}
#endif
#endif
