/* A forged checkpoint of a run on the opencl backend: the engine's
 * neighbour lists (granular.cl.*: a count per disc, its partners, their
 * contact histories) are checked before they reach the device, whose
 * kernel reads partners up to each disc's count. Each forgery is refused
 * naming its section; the file written again unchanged resumes and steps.
 * A capability the engine lacks (abm4) is refused at case check, at its key. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"
#include "px_test_ck.h"
#include "partix/sim.h"

static const char *const cl_case =
    "solver: granular\n"
    "backend: {type: opencl, precision: double}\n"
    "time: {steps: 400}\n"
    "output: {dir: out_hostile_cl, every: 400, png_every: 400, log_every: 100, png: false}\n"
    "granular:\n"
    "  gravity: [0, -10000]\n"
    "  media:\n"
    "    count: 40\n"
    "    radius: {distribution: uniform, min: 0.0018, max: 0.0022}\n"
    "    density: 7800\n"
    "    thickness: 0.004\n"
    "  contact: {kn: 2e5, restitution: 0.6, friction: 0.4}\n"
    "  bodies:\n"
    "    - name: container\n"
    "      motion: {type: fixed}\n"
    "  contours:\n"
    "    - {name: box, body: container, shape: {type: rectangle, min: [0, 0], max: [0.05, "
    "0.05]}, report: false}\n";

int main(void) {
  struct px_context *ctx = NULL;
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  struct px_test_ck f;
  const char *forged = "out_hostile_cl/forged.pxc";
  int32_t first = -1;  /* a disc with a partner */
  int32_t walled = -1; /* a disc with a wall candidate */
  size_t k;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  if (px_backend_opencl_device_count(ctx) == 0) {
    printf("no OpenCL device: skipped\n");
    px_context_free(ctx);
    return PX_TEST_SKIP;
  }
  px_test_fresh_dir("out_hostile_cl");
  PX_CHECK_OK(ctx, px_case_load_string(ctx, "case.yaml", cl_case, strlen(cl_case), NULL, 0, &c));
  PX_CHECK_OK(ctx, px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_run(sim));
    px_sim_free(sim);
  }
  if (!px_test_ck_load(ctx, "out_hostile_cl/checkpoint.pxc", &f) ||
      !px_test_ck_find(&f, "granular.cl.ncount")) {
    PX_CHECK_MSG(0, "no opencl checkpoint: %s", px_context_message(ctx));
    px_test_ck_free(&f);
    px_context_free(ctx);
    return px_test_report("test_granular_hostile_opencl");
  }
  {
    const struct px_test_ck_sec *nc = px_test_ck_find(&f, "granular.cl.ncount");
    for (k = 0; k < nc->count / 4 && first < 0; ++k) {
      int32_t cnt;
      memcpy(&cnt, nc->data + 4 * k, 4);
      if (cnt > 0) first = (int32_t)k;
    }
    PX_CHECK_MSG(first >= 0, "no disc with a neighbour");
    const struct px_test_ck_sec *wc = px_test_ck_find(&f, "granular.cl.wcount");
    for (k = 0; wc && k < wc->count / 4 && walled < 0; ++k) {
      int32_t cnt;
      memcpy(&cnt, wc->data + 4 * k, 4);
      if (cnt > 0) walled = (int32_t)k;
    }
    PX_CHECK_MSG(walled >= 0, "no disc with a wall candidate");
  }
  /* unchanged: resumes and steps */
  PX_CHECK_OK(ctx, px_test_ck_write(ctx, &f, forged));
  PX_CHECK_OK(ctx, px_sim_open(ctx, forged, NULL, 0, PX_SIM_MODE_CHECK, &sim));
  for (k = 0; sim && k < 3; ++k) PX_CHECK_OK(ctx, px_sim_step(sim));
  px_sim_free(sim);
  sim = NULL;
  {
    /* the lists hold 16 partners per disc (PX_GRAN_CL_NMAX) */
    const struct px_test_forgery fs[] = {
        {"granular.cl.ncount", PX_DTYPE_I32, first, 17, "granular.cl.ncount"},
        {"granular.cl.ncount", PX_DTYPE_I32, first, -1, "granular.cl.ncount"},
        {"granular.cl.ncount", PX_DTYPE_I32, -1, 2147483647.0, "granular.cl.ncount"},
        {"granular.cl.nbr", PX_DTYPE_I32, 16 * first, 1e6, "granular.cl.nbr"},
        {"granular.cl.nbr", PX_DTYPE_I32, 16 * first, -5, "granular.cl.nbr"},
        {"granular.cl.nbr", PX_DTYPE_I32, 16 * first, first, "granular.cl.nbr"},
        {"granular.cl.hxi", PX_DTYPE_F64, 16 * first, NAN, "granular.cl.hxi"},
        {"granular.cl.hdp", PX_DTYPE_F64, 16 * first, INFINITY, "granular.cl.hdp"},
        {"granular.cl.nbr", PX_DTYPE_U8, 0, 0, "granular.cl.nbr"},
        /* wall candidates (24 per disc) and the positions of the last
         * rebuild */
        {"granular.cl.wcount", PX_DTYPE_I32, walled, 25, "granular.cl.wcount"},
        {"granular.cl.wcount", PX_DTYPE_I32, walled, -3, "granular.cl.wcount"},
        {"granular.cl.wcand", PX_DTYPE_I32, 24 * walled, 1e6, "granular.cl.wcand"},
        {"granular.cl.wcand", PX_DTYPE_I32, 24 * walled, -1, "granular.cl.wcand"},
        {"granular.cl.xr", PX_DTYPE_F64, 0, NAN, "granular.cl.xr"},
        {"granular.cl.yr", PX_DTYPE_F64, -1, 1e300, "granular.cl.yr"},
        {"granular.cl.xr", PX_DTYPE_U8, 0, 0, "granular.cl.xr"},
    };
    px_test_ck_expect_refused(ctx, &f, fs, sizeof fs / sizeof fs[0], forged);
  }
  px_test_ck_free(&f);
  {
    /* the opencl engine integrates with velocity Verlet only */
    static const char head[] = "granular:\n", abm[] = "  integrator: abm4\n";
    const char *g = strstr(cl_case, head);
    char *text = malloc(strlen(cl_case) + sizeof abm);
    struct px_case *ca = NULL;
    enum px_status st;
    PX_CHECK(text != NULL && g != NULL);
    if (text && g) {
      const size_t at = (size_t)(g - cl_case) + strlen(head);
      memcpy(text, cl_case, at);
      strcpy(text + at, abm);
      strcat(text, cl_case + at);
      PX_CHECK_OK(ctx, px_case_load_string(ctx, "case.yaml", text, strlen(text), NULL, 0, &ca));
      st = ca ? px_sim_create(ctx, ca, PX_SIM_MODE_CHECK, &sim) : PX_STATUS_INVALID;
      PX_CHECK_MSG(st == PX_STATUS_CONFIG &&
                       strstr(px_context_message(ctx), "granular.integrator") &&
                       strstr(px_context_message(ctx), "Verlet"),
                   "abm4 on opencl: %s: %s", px_status_name(st), px_context_message(ctx));
      px_context_clear(ctx);
      if (st == PX_STATUS_OK) px_sim_free(sim);
      free(text);
    }
  }
  {
    /* a disc shot at 1e6 m/s crosses the box in one step and flies on
     * beyond every wall, where the device's rebuild does not look: the
     * host mirror's rebuild at each download (outputs, log rows) finds it,
     * and the run stops with the disc and the cause, as on the cpu engine */
    static const char fast[] =
        "solver: granular\n"
        "backend: {type: opencl, precision: double}\n"
        "time: {steps: 200}\n"
        "output: {dir: out_hostile_cl_fast, every: 50, png: false}\n"
        "granular:\n"
        "  media: {particles: [[0.02, 0.02, 0.002, 1e6, 0]], density: 7800, thickness: 0.004}\n"
        "  contact: {kn: 2e5, restitution: 0.6}\n"
        "  bodies: [{name: c}]\n"
        "  contours:\n"
        "    - {name: box, body: c, report: false, shape: {type: rectangle, min: [0, 0], max: "
        "[0.05, 0.05]}}\n";
    struct px_case *cf = NULL;
    enum px_status st = PX_STATUS_INVALID;
    px_test_fresh_dir("out_hostile_cl_fast");
    PX_CHECK_OK(ctx, px_case_load_string(ctx, "fast.yaml", fast, strlen(fast), NULL, 0, &cf));
    sim = NULL;
    if (cf) PX_CHECK_OK(ctx, px_sim_create(ctx, cf, PX_SIM_MODE_RUN, &sim));
    if (sim) {
      px_sim_set_progress(sim, NULL, 0);
      st = px_sim_run(sim);
      px_sim_free(sim);
    }
    PX_CHECK_MSG(st == PX_STATUS_NUMERIC &&
                     strstr(px_context_message(ctx), "has left the container at step") &&
                     strstr(px_context_message(ctx), "time step is too large for the speeds"),
                 "a disc at 1e6 m/s on opencl: %s: %s", px_status_name(st),
                 px_context_message(ctx));
    px_context_clear(ctx);
  }
  px_context_free(ctx);
  return px_test_report("test_granular_hostile_opencl");
}
