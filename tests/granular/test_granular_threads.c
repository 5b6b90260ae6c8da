/* The cpu engine's results do not depend on how many threads actually run
 * (the run-time tuner switches between all and one): the work is split into
 * fixed particle ranges and every sum is taken in a fixed order. Three runs
 * of a vibrated box of 4800 discs with random velocities (rebuilds,
 * reorderings, wall impacts, friction histories): backend threads 2 with
 * both threads always active, the same with one thread always active, and
 * the same with the tuner switching; a fourth as the first, but with the
 * pair search keeping one partner per disc instead of 8, so that the
 * rebuilds' second search runs for most discs (the same lists either way).
 * Positions, velocities, spins and the per-segment statistics must be
 * bit-identical. And the statistics the
 * outputs read while contacts are in progress (px_gran_sys_stats_pending,
 * which leaves the system as it is) equal those a flush makes, bit for bit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"

#define NX 80
#define NY 60

/* mode 0: 2 threads active; 1: one thread active; 2: the tuner decides;
 * 3: as 0, the pair search keeping one partner per disc */
static struct px_gran_sys *run(struct px_context *ctx, const struct px_gran_geom *g,
                               const struct px_gran_motion *mo, int mode, long steps) {
  struct px_gran_sys *s = NULL;
  struct px_gran_stats_spec spec;
  uint64_t rng[4];
  int i, j;
  long k;
  if (px_gran_sys_create(ctx, PX_PRECISION_MIXED, 2, &s) != PX_STATUS_OK) return NULL;
  gt_law(&s->pp, 2e5, 0.7, 0.3);
  gt_law(&s->pw, 2e5, 0.6, 0.2);
  s->gravity[1] = -9.81;
  px_gran_sys_set_walls(s, g, mo, 1);
  px_rng_seed(rng, 5);
  for (j = 0; j < NY; ++j)
    for (i = 0; i < NX; ++i) {
      double x = 0.0022 + 0.0045 * i, y = 0.0022 + 0.0045 * j;
      double r = 0.0015 + 0.0005 * px_rng_uniform(rng), m = 7800 * 3.14159265 * r * r * 0.004;
      px_gran_sys_add(s, 1, &x, &y, &r, &m);
      px_gran_sys_set_velocity(s, (int32_t)(s->n - 1), 1.0 * (2 * px_rng_uniform(rng) - 1),
                               1.0 * (2 * px_rng_uniform(rng) - 1), 0);
    }
  if (mode == 3) s->pcache_n = 1;
  memset(&spec, 0, sizeof spec);
  spec.vmin = 0.01;
  spec.archard_k = 1e-4;
  spec.hardness = 1e9;
  PX_CHECK_OK(ctx, px_gran_sys_prepare(s, 0, 50));
  PX_CHECK_OK(ctx, px_gran_sys_stats_enable(s, &spec));
  PX_CHECK(s->threads == 2);
  s->tune = 0; /* mode 2 alternates the count itself, every 50 steps */
  s->active = mode == 1 ? 1 : 2;
  for (k = 0; k < steps; ++k) {
    if (mode == 2 && k % 50 == 0) s->active = s->active > 1 ? 1 : 2; /* as the tuner would */
    if (px_gran_sys_step(s) != PX_STATUS_OK) {
      PX_CHECK_MSG(0, "step %ld: %s", k, px_context_message(ctx));
      break;
    }
  }
  {
    /* the outputs' view of the statistics = a flush, without the flush */
    const size_t ns = g->nseg;
    double *v = malloc(4 * ns * sizeof *v);
    size_t q, differ = 0;
    double pending = 0;
    if (!v) return s;
    memcpy(v, s->stats.impulse, ns * sizeof *v);
    memcpy(v + ns, s->stats.slide, ns * sizeof *v);
    memcpy(v + 2 * ns, s->stats.archard, ns * sizeof *v);
    memcpy(v + 3 * ns, s->stats.ctime, ns * sizeof *v);
    px_gran_sys_stats_pending(s, v, v + ns, v + 2 * ns, v + 3 * ns);
    for (q = 0; q < ns; ++q) pending += v[3 * ns + q] - s->stats.ctime[q];
    px_gran_sys_stats_flush(s);
    for (q = 0; q < ns; ++q)
      if (v[q] != s->stats.impulse[q] || v[ns + q] != s->stats.slide[q] ||
          v[2 * ns + q] != s->stats.archard[q] || v[3 * ns + q] != s->stats.ctime[q])
        ++differ;
    PX_CHECK_MSG(pending > 0, "no wall contact in progress at the end (%g s)", pending);
    PX_CHECK_MSG(differ == 0, "%zu segments: pending view != flush", differ);
    free(v);
  }
  return s;
}

int main(void) {
  struct px_context *ctx = NULL;
  struct px_gran_geom g;
  struct px_gran_motion mo;
  struct px_gran_sys *s[4] = {NULL, NULL, NULL, NULL};
  const long steps = 800;
  int m;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_gran_geom_init(&g);
  PX_CHECK_OK(ctx, gt_rect(ctx, &g, 0, 0, 0.3599, 0.2699, 0.0015, 0, "box"));
  PX_CHECK_OK(ctx, px_gran_geom_finish(ctx, &g, 0.008));
  px_gran_motion_init(&mo);
  mo.kind = PX_GRAN_MOTION_HARMONIC;
  mo.amp[0] = mo.amp[1] = 0.002;
  mo.freq[0] = mo.freq[1] = 100;
  mo.phase[1] = 1.5707963267948966;
  mo.ramp = 0.002; /* starts from rest at the filled position */
  for (m = 0; m < 4; ++m) s[m] = run(ctx, &g, &mo, m, steps);
  if (s[0] && s[1] && s[2] && s[3]) {
    int32_t id;
    size_t k, diff = 0;
    double imp = 0;
    PX_CHECK_MSG(s[0]->rebuilds >= 5, "rebuilds: %ld", s[0]->rebuilds);
    for (m = 1; m < 4; ++m) {
      PX_CHECK(s[m]->rebuilds == s[0]->rebuilds);
      for (id = 0; id < (int32_t)s[0]->n; ++id) {
        double a[8], b[8];
        px_gran_sys_get(s[0], id, a);
        px_gran_sys_get(s[m], id, b);
        if (memcmp(a, b, sizeof a) != 0) ++diff;
      }
      for (k = 0; k < g.nseg; ++k) {
        if (memcmp(&s[0]->stats.impacts[k], &s[m]->stats.impacts[k], sizeof(double)) != 0 ||
            memcmp(&s[0]->stats.en[k], &s[m]->stats.en[k], sizeof(double)) != 0 ||
            memcmp(&s[0]->stats.impulse[k], &s[m]->stats.impulse[k], sizeof(double)) != 0 ||
            memcmp(&s[0]->stats.archard[k], &s[m]->stats.archard[k], sizeof(double)) != 0)
          ++diff;
        if (m == 1) imp += s[0]->stats.impacts[k];
      }
    }
    printf(
        "%zu discs, %ld steps, %ld rebuilds, %g wall impacts, %ld steps on 2 threads in the "
        "switching run; records differing: %zu\n",
        s[0]->n, steps, s[0]->rebuilds, imp, s[2]->steps_parallel, diff);
    PX_CHECK(imp > 10);
    PX_CHECK(s[0]->steps_parallel == steps && s[1]->steps_parallel == 0);
    PX_CHECK(s[2]->steps_parallel > 0 && s[2]->steps_parallel < steps);
    PX_CHECK(diff == 0);
  }
  for (m = 0; m < 4; ++m) px_gran_sys_free(s[m]);
  px_gran_geom_free(ctx, &g);
  px_context_free(ctx);
  return px_test_report("test_granular_threads");
}
