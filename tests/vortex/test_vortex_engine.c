/* The vortex engine table (vortex_engine.h):
 *  - the engine is picked by the backend's name, and every engine a build
 *    holds gives every block of a step (no NULL where the driver calls);
 *  - an engine states what it can compute: the cpu engine every precision and
 *    the FMM, the opencl one no FMM and fp64 only where its device has it;
 *  - a case asking for the FMM on the opencl backend is refused at
 *    vortex.velocity.method, never run with the direct sum instead;
 *  - the driver runs the blocks in order and keeps the clock: after k steps
 *    the engine is at step k and time k dt, every block timed. */
#include <string.h>

#include "partix/memory.h"
#include "partix/sim.h"
#include "px_test.h"
#include "solvers/vortex/vortex_engine.h"
#include "vortex/vx_test_util.h"

static void check_table(const struct px_vortex_engine_i *ops) {
  PX_CHECK(ops->caps && ops->begin && ops->generation && ops->convective && ops->diffusive &&
           ops->loads && ops->move && ops->inside && ops->restructure);
}

static void test_pick_cpu(struct px_context *ctx) {
  struct px_backend *be = NULL;
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, 1, &be));
  if (!be) return;
  const struct px_vortex_engine_i *ops = px_vortex_engine_pick(be);
  PX_CHECK(ops == &px_vortex_engine_cpu);
  if (ops) check_table(ops);
  struct px_vortex_caps caps;
  PX_CHECK_OK(ctx, px_vortex_engine_caps(be, &caps));
  PX_CHECK(caps.fp64 == 1 && caps.fmm == 1 && caps.mixed == 1);
  px_backend_free(be);
}

/* On the OpenCL backend where a device is found (skipped otherwise). */
static void test_pick_opencl(struct px_context *ctx) {
  struct px_backend *be = NULL;
  if (px_backend_create(ctx, "opencl", 0, 1, &be) != PX_STATUS_OK) {
    px_context_clear(ctx);
    printf("test_vortex_engine: no OpenCL device, opencl checks skipped\n");
    return;
  }
  const struct px_vortex_engine_i *ops = px_vortex_engine_pick(be);
  PX_CHECK(ops && strcmp(ops->backend, "opencl") == 0);
  if (ops) check_table(ops);
  struct px_vortex_caps caps;
  PX_CHECK_OK(ctx, px_vortex_engine_caps(be, &caps));
  PX_CHECK(caps.fmm == 0 && caps.mixed == 1);
  PX_CHECK(caps.fp64 == px_backend_has_fp64(be));
  px_backend_free(be);

  const char *text =
      "solver: vortex\nbackend: {type: opencl, precision: mixed}\n"
      "time: {dt: 0.0125, steps: 2}\noutput: {dir: out_vx_engine}\n"
      "vortex:\n  nu: 0.005\n  v_inf: [1, 0]\n  velocity: {method: fmm}\n"
      "  bodies:\n    - {type: circle, radius: 0.5, panels: 40}\n";
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  enum px_status s = px_case_load_string(ctx, "fmm.yaml", text, strlen(text), NULL, 0, &c);
  if (s == PX_STATUS_OK) s = px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim);
  PX_CHECK_MSG(s == PX_STATUS_CONFIG, "accepted or wrong status %s: %s", px_status_name(s),
               px_context_message(ctx));
  PX_CHECK(vx_test_message_has(ctx, "vortex.velocity.method"));
  PX_CHECK(vx_test_message_has(ctx, "runs on the cpu backend only, not on 'opencl'"));
  px_sim_free(sim);
  px_context_clear(ctx);
}

static void test_driver_clock(struct px_context *ctx) {
  struct px_vortex_config cfg;
  vx_test_cylinder_config(&cfg, 0.012, 0.008, 1);
  struct px_vortex_contour body;
  struct px_backend *be;
  struct px_vortex_engine *e = vx_test_cylinder_engine(ctx, &cfg, 40, &body, &be);
  if (e) {
    for (int k = 0; k < 3; ++k) PX_CHECK_OK(ctx, px_vortex_engine_step(e));
    PX_CHECK(e->step == 3);
    PX_CHECK_NEAR(e->time, 3 * cfg.dt, 1e-15);
    PX_CHECK(e->w.n > 0 && e->n_born > 0);
    for (int b = 0; b < PX_VORTEX_BLOCK_COUNT_; ++b) PX_CHECK(e->block_time[b] >= 0.0);
  }
  px_vortex_engine_free(e);
  px_vortex_contour_free(ctx, &body);
  px_backend_free(be);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  test_pick_cpu(ctx);
  test_pick_opencl(ctx);
  test_driver_clock(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_vortex_engine");
}
