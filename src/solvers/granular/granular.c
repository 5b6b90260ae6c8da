/* The `granular` solver: 2D vibro-impact DEM of media discs in a vibrating
 * container with parts, and impact statistics along the contours (spec
 * granular.md). This file turns a case into a system (the stages of
 * px_gran_create_run; the keys are read in granular_case.c), picks the
 * engine that steps it by backend name (granular_engine.h) and plugs it into
 * the run driver; physics in system*.c / cpu_loops.h / *_kernel.h, outputs
 * in granular_output.c, checkpoints in granular_checkpoint.c. */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "compute/backend_impl.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/granular_case.h"
#include "solvers/granular/granular_impl.h"
#include "solvers/granular/wall_kernel.h"

/* The engines, by backend name (granular_engine.h). */
static const void *const px_gran_engines[] = {&px_gran_engine_cpu,
                                              PX_IF_OPENCL(&px_gran_engine_opencl, )};

/* Steps a run may take: the event records and contact slots count steps in
 * int (wall_kernel.h). */
#define PX_GRAN_STEPS_MAX 2147483647.0

static void px_gran_destroy(void *state);

/* Record the values chosen for the settings the case leaves to partix
 * (run.log, summary.json "automatic"). h: the segment length chosen (0: the
 * case gave it); skin: as the case gave it (0: automatic). */
static void px_gran_note_autos(struct px_gran_run *r, const struct px_gran_caps *caps, double h,
                               double skin, int auto_vmax) {
  struct px_case *c = r->c;
  const struct px_gran_sys *s = r->sys;
  double start = 0, frac = 0;
  size_t b;
  if (h > 0) px_sim_note_auto(r->sim, "granular.segment_length", "%.6g m (the smallest radius)", h);
  if (!(skin > 0))
    px_sim_note_auto(r->sim, "granular.skin",
                     "%.6g m (0.4 of the largest radius; neighbour grid cells of %.6g m)", s->skin,
                     s->gh);
  if (px_case_get_real(c, "granular.statistics.start", &start) == PX_STATUS_OK && start < 0)
    px_sim_note_auto(r->sim, "granular.statistics.start", "%.6g s (after settle)", r->sspec.start);
  for (b = 0; b < r->nbodies; ++b) {
    char key[96];
    double mstart = 0;
    if (r->motions[b].kind == PX_GRAN_MOTION_FIXED) continue;
    snprintf(key, sizeof key, "granular.bodies[%zu].motion.start", b);
    if (px_case_get_real(c, key, &mstart) == PX_STATUS_OK && mstart < 0)
      px_sim_note_auto(r->sim, key, "%.6g s (after settle)", r->motions[b].start);
  }
  if (auto_vmax)
    px_sim_note_auto(r->sim, "granular.statistics.speed_max", "%.6g m/s (%s)", r->speed_max,
                     r->speed_max == 1.0 ? "no wall moves: 1 m/s" : "3 x the fastest wall");
  if (px_case_has(c, "granular.media.fraction") &&
      px_case_get_real(c, "granular.media.fraction", &frac) == PX_STATUS_OK)
    px_sim_note_auto(r->sim, "granular.media.count", "%zu discs (fraction %.4g of the free area)",
                     s->n, frac);
  if (s->pp.normal == PX_GRAN_NORMAL_HYSTERETIC && !(s->pp.k2 > 0))
    px_sim_note_auto(r->sim, "granular.contact.k2", "%.6g N/m (kn / e^2)",
                     s->pp.kn / (s->pp.e * s->pp.e));
  if (r->geom.ncontours && s->pw.normal == PX_GRAN_NORMAL_HYSTERETIC && !(s->pw.k2 > 0))
    px_sim_note_auto(r->sim, "granular.wall_contact.k2", "%.6g N/m (kn / e^2)",
                     s->pw.kn / (s->pw.e * s->pw.e));
  if (caps->host_threads > 1) {
    const int asked = caps->host_threads;
    if (s->threads < asked)
      px_sim_note_auto(r->sim, "backend.threads",
                       "%d of %d (%zu discs: below 2048 discs per thread the threads would wait "
                       "more than they work)",
                       s->threads, asked, s->n);
    else if (s->threads > 1 && s->tune)
      px_sim_note_auto(r->sim, "backend.threads",
                       "1 or %d, measured while running (the faster is used; results do not "
                       "change; the share of each is in run.log at the end)",
                       s->threads);
  }
  px_log(r->ctx, PX_LOG_LEVEL_INFO,
         "granular: %zu discs, %zu boundary segments; contact time of the lightest pair "
         "t_c = %.6g s, dt = t_c / %.4g",
         s->n, r->geom.nseg, px_gran_sys_contact_time(s), px_gran_sys_contact_time(s) / s->dt);
}

static int integ_is_abm(const struct px_case *c) {
  int integ = 0;
  px_case_get_enum(c, "granular.integrator", &integ);
  return integ == 1;
}

/* The engine for the run's backend, and what it can do: a capability the
 * case asks for and the engine lacks is refused here, at its key. */
static enum px_status px_gran_pick_engine(struct px_gran_run *r, struct px_backend *be,
                                          struct px_gran_caps *caps) {
  struct px_case *c = r->c;
  r->eng = be ? PX_BACKEND_PICK(be, "granular", px_gran_engines) : &px_gran_engine_cpu;
  if (!r->eng) {
    char msg[512];
    snprintf(msg, sizeof msg, "%s", px_context_message(r->ctx));
    return px_case_fail(c, "backend.type", "%s", msg);
  }
  r->eng->caps(be, caps);
  {
    /* over several ranks: the cpu engine, either integrator (system_ranks.c),
     * and the opencl one (granular_ranks_opencl.c) */
    const int K = px_comm_size(px_context_comm(r->ctx));
    if (K > 1 && !caps->ranks)
      return px_case_fail(c, "backend.type",
                          "the %s engine runs on one rank only (%d ranks asked): use "
                          "backend.type: cpu under mpirun, or run on one rank",
                          r->eng->name, K);
  }
  if (integ_is_abm(c) && !caps->abm4)
    return px_case_fail(c, "granular.integrator", "abm4 is not available on the %s backend (%s)",
                        r->eng->name, caps->why_no_abm4);
  if (px_sim_precision(r->sim) != PX_PRECISION_SINGLE && !caps->fp64)
    return px_case_fail(c, "backend.precision",
                        "%s precision needs double arithmetic, which the %s device lacks "
                        "(precision: single runs on it)",
                        px_precision_name(px_sim_precision(r->sim)), r->eng->name);
  return PX_STATUS_OK;
}

/* What px_gran_create_run reads and builds on its way, shared by its
 * stages (px_gran_setup_*); arrays owned, freed by px_gran_setup_free. */
struct px_gran_setup {
  struct px_gran_caps caps;    /* of the engine picked */
  double g[2];                 /* gravity [m/s^2] */
  double h;                    /* boundary segment length [m] (automatic: rmin) */
  double skin;                 /* neighbour-list skin as the case gives it (0: automatic) [m] */
  double smooth;               /* smooth_angle [deg] */
  double spc;                  /* steps per contact duration */
  double density;              /* [kg/m^3] */
  int integ;                   /* granular.integrator (1: abm4) */
  int dist;                    /* granular.media.radius.distribution */
  int listed;                  /* discs given one by one */
  int auto_h, auto_vmax;       /* segment length, speed range: automatic */
  struct px_gran_dist_spec ds; /* borrows radii, weights */
  double *x, *y, *rad, *m;     /* the discs: centres [m], radii [m], masses [kg] (n) */
  double *vel;                 /* listed discs: vx, vy [m/s], w [rad/s] (3 n) */
  size_t n;
  double *radii, *weights; /* a discrete distribution */
  double *frames;          /* contour frames at t = 0 */
  double window[4];        /* granular.media.window [m] */
  double tc_pp, tc_pw;     /* contact durations of the lightest discs [s] */
};

static void px_gran_setup_free(struct px_gran_run *r, struct px_gran_setup *S) {
  px_mem_free(r->ctx, S->frames);
  px_mem_free(r->ctx, S->x);
  px_mem_free(r->ctx, S->y);
  px_mem_free(r->ctx, S->rad);
  px_mem_free(r->ctx, S->m);
  px_mem_free(r->ctx, S->radii);
  px_mem_free(r->ctx, S->weights);
  px_mem_free(r->ctx, S->vel);
}

/* The run's scalar keys. */
static enum px_status px_gran_setup_read(struct px_gran_run *r, struct px_gran_setup *S) {
  struct px_case *c = r->c;
  PX_TRY(px_case_get_vector(c, "granular.gravity", S->g, 2));
  PX_TRY(px_case_get_real(c, "granular.settle", &r->settle));
  PX_TRY(px_case_get_enum(c, "granular.integrator", &S->integ));
  PX_TRY(px_case_get_real(c, "granular.steps_per_contact", &S->spc));
  PX_TRY(px_case_get_real(c, "granular.skin", &S->skin));
  PX_TRY(px_case_get_real(c, "granular.segment_length", &S->h));
  PX_TRY(px_case_get_real(c, "granular.smooth_angle", &S->smooth));
  PX_TRY(px_case_get_real(c, "granular.media.density", &S->density));
  PX_TRY(px_case_get_real(c, "granular.media.thickness", &r->thickness));
  PX_TRY(px_case_get_enum(c, "granular.media.radius.distribution", &S->dist));
  S->listed = px_case_has(c, "granular.media.particles");
  return PX_STATUS_OK;
}

/* The radius distribution (or the discs listed one by one), the automatic
 * segment length and the skin's bound. */
static enum px_status px_gran_setup_radii(struct px_gran_run *r, struct px_gran_setup *S) {
  struct px_case *c = r->c;
  struct px_gran_dist_spec *ds = &S->ds;
  double *radii, *weights;
  size_t k;
  enum px_status st;
  if (S->listed) {
    /* discs given one by one: their radii bound the segment length and cells */
    st = px_gran_read_particles(r, &S->x, &S->y, &S->rad, &S->vel, &S->n);
    if (st == PX_STATUS_OK) st = px_gran_listed_overlaps(r, S->x, S->y, S->rad, S->n);
    if (st != PX_STATUS_OK) return st;
    ds->kind = PX_GRAN_DIST_UNIFORM;
    ds->min = ds->max = S->rad[0];
    for (k = 1; k < S->n; ++k) {
      if (S->rad[k] < ds->min) ds->min = S->rad[k];
      if (S->rad[k] > ds->max) ds->max = S->rad[k];
    }
  } else if (S->dist == 2) {
    size_t nv = 0, nw = 0;
    PX_TRY(px_case_count(c, "granular.media.radius.values", &nv));
    PX_TRY(px_case_count(c, "granular.media.radius.weights", &nw));
    if (nv == 0) return px_case_fail(c, "granular.media.radius", "discrete: give `values`");
    if (nw != 0 && nw != nv)
      return px_case_fail(c, "granular.media.radius.weights",
                          "%zu weights for %zu values (one weight per radius)", nw, nv);
    S->radii = radii = px_mem_alloc(r->ctx, "granular media", nv * sizeof *radii);
    S->weights = weights = px_mem_alloc(r->ctx, "granular media", nv * sizeof *weights);
    if (!radii || !weights) return PX_STATUS_NOMEM;
    for (k = 0; k < nv; ++k) {
      char key[96];
      snprintf(key, sizeof key, "granular.media.radius.values[%zu]", k);
      px_case_get_real(c, key, &radii[k]);
      weights[k] = 1;
      if (nw) {
        snprintf(key, sizeof key, "granular.media.radius.weights[%zu]", k);
        px_case_get_real(c, key, &weights[k]);
      }
    }
    ds->kind = PX_GRAN_DIST_DISCRETE;
    ds->n = nv;
    ds->radii = radii;
    ds->weights = weights;
  } else {
    if (!px_case_has(c, "granular.media.radius.min") ||
        !px_case_has(c, "granular.media.radius.max")) {
      if (S->dist == 0)
        return px_case_fail(c, "granular.media.radius",
                            "uniform: give `min` and `max` (equal "
                            "for one size)");
    }
    if (S->dist == 0) {
      PX_TRY(px_case_get_real(c, "granular.media.radius.min", &ds->min));
      PX_TRY(px_case_get_real(c, "granular.media.radius.max", &ds->max));
      if (ds->max < ds->min)
        return px_case_fail(c, "granular.media.radius.max", "max %g < min %g", ds->max, ds->min);
      ds->kind = PX_GRAN_DIST_UNIFORM;
    } else {
      if (!px_case_has(c, "granular.media.radius.mean") ||
          !px_case_has(c, "granular.media.radius.sd"))
        return px_case_fail(c, "granular.media.radius", "normal: give `mean` and `sd`");
      PX_TRY(px_case_get_real(c, "granular.media.radius.mean", &ds->mean));
      PX_TRY(px_case_get_real(c, "granular.media.radius.sd", &ds->sd));
      ds->min = px_case_has(c, "granular.media.radius.min") ? 0 : 0.5 * ds->mean;
      ds->max = 1.5 * ds->mean;
      if (px_case_has(c, "granular.media.radius.min"))
        PX_TRY(px_case_get_real(c, "granular.media.radius.min", &ds->min));
      if (px_case_has(c, "granular.media.radius.max"))
        PX_TRY(px_case_get_real(c, "granular.media.radius.max", &ds->max));
      if (!(ds->min < ds->max) || !(ds->mean > ds->min) || !(ds->mean < ds->max))
        return px_case_fail(c, "granular.media.radius", "normal: need min < mean < max");
      ds->kind = PX_GRAN_DIST_NORMAL;
    }
  }
  S->auto_h = !(S->h > 0);
  if (S->auto_h) S->h = px_gran_dist_rmin(ds);
  if (!(S->skin <= PX_GRAN_SKIN_MAX * px_gran_dist_rmax(ds)))
    return px_case_fail(c, "granular.skin",
                        "%g m: more than %g times the largest radius %g m (every disc would list "
                        "hundreds of neighbours; 0.2 to 1 radius is usual)",
                        S->skin, PX_GRAN_SKIN_MAX, px_gran_dist_rmax(ds));
  return PX_STATUS_OK;
}

/* The bodies and their motions, then the contours (the geometry, binned). */
static enum px_status px_gran_setup_walls(struct px_gran_run *r, struct px_gran_setup *S) {
  struct px_case *c = r->c;
  size_t nc, k;
  enum px_status st;
  PX_TRY(px_gran_bodies(r));
  px_gran_geom_init(&r->geom);
  r->geom.smooth_angle = S->smooth * PX_GRAN_DEG;
  st = px_case_count(c, "granular.contours", &nc);
  {
    double box[4] = {DBL_MAX, DBL_MAX, -DBL_MAX, -DBL_MAX};
    for (k = 0; k < nc && st == PX_STATUS_OK; ++k) {
      char cp[64];
      snprintf(cp, sizeof cp, "granular.contours[%zu]", k);
      st = px_gran_contour(r, cp, S->h, px_gran_dist_rmax(&S->ds), box);
    }
  }
  /* the run's memory per boundary segment: geometry (9 values), state
   * copies (7), statistics (16), their view (4), bins (~16 ints) */
  if (st == PX_STATUS_OK)
    st = px_sim_require_memory(r->sim, (double)r->geom.nseg * (36 * 8 + 16 * 4),
                               "granular.segment_length", "the boundary segments");
  if (st != PX_STATUS_OK) return st;
  PX_TRY(px_gran_as_case(r, px_gran_geom_finish(r->ctx, &r->geom, 4 * px_gran_dist_rmax(&S->ds)),
                         "granular.contours"));
  /* with the contours' boxes (px_gran_geom_finish) */
  return px_gran_motion_jumps(r, px_gran_dist_rmin(&S->ds));
}

/* The system: precision, threads, integrator, laws and walls; the masses
 * and contact times of the lightest discs checked before any is placed. */
static enum px_status px_gran_setup_system(struct px_gran_run *r, struct px_gran_setup *S) {
  struct px_case *c = r->c;
  PX_TRY(px_gran_sys_create(r->ctx, px_sim_precision(r->sim), S->caps.host_threads, &r->sys));
  /* a thread count the user fixed is kept; left to partix, it is tuned */
  r->sys->tune = px_backend_threads_auto(px_sim_backend(r->sim));
  r->sys->integrator = S->integ == 1 ? PX_GRAN_INTEGRATOR_ABM4 : PX_GRAN_INTEGRATOR_VERLET;
  r->sys->gravity[0] = S->g[0], r->sys->gravity[1] = S->g[1];
  r->sys->skin = S->skin > 0 ? S->skin : -1;
  PX_TRY(px_gran_law(r, "granular.contact", NULL, &r->sys->pp));
  PX_TRY(px_gran_law(r, "granular.wall_contact", &r->sys->pp, &r->sys->pw));
  px_gran_sys_set_walls(r->sys, &r->geom, r->motions, r->nbodies);
  /* masses and contact times before any disc is placed: a stiffness out of
   * all proportion to the masses (kn = 1e308) has no contact time to
   * resolve, and no time step */
  {
    const double rlo = px_gran_dist_rmin(&S->ds), rhi = px_gran_dist_rmax(&S->ds);
    const double mlo = S->density * PX_GRAN_PI * rlo * rlo * r->thickness;
    const double mhi = S->density * PX_GRAN_PI * rhi * rhi * r->thickness;
    if (!(mlo > 0) || !(mhi <= DBL_MAX))
      return px_case_fail(c, "granular.media.density",
                          "discs of radius %g to %g m, density %g kg/m^3 and thickness %g m "
                          "weigh %g to %g kg: not positive finite masses",
                          rlo, rhi, S->density, r->thickness, mlo, mhi);
    S->tc_pp = px_gran_law_contact_time(&r->sys->pp, 0.5 * mlo);
    S->tc_pw = px_gran_law_contact_time(&r->sys->pw, mlo);
    if (!(S->tc_pp > 0) || !isfinite(S->tc_pp) || !(S->tc_pw > 0) || !isfinite(S->tc_pw)) {
      const int wall = !(S->tc_pw > 0) || !isfinite(S->tc_pw);
      const struct px_gran_law_spec *L = wall ? &r->sys->pw : &r->sys->pp;
      char key[96];
      return px_case_fail(c, px_gran_law_key(c, wall, "kn", key),
                          "kn = %g N/m on discs of %g kg gives a contact duration t_c = %g s: "
                          "not a positive finite time (the stiffness is out of all proportion to "
                          "the masses)",
                          L->kn, mlo, wall ? S->tc_pw : S->tc_pp);
    }
  }

  return PX_STATUS_OK;
}

/* The discs: the filling (or the listed discs) with the contours where they
 * are at t = 0, counted and their memory checked before any is placed. */
static enum px_status px_gran_setup_media(struct px_gran_run *r, struct px_gran_setup *S) {
  struct px_case *c = r->c;
  struct px_gran_fill_spec fs;
  double *frames;
  size_t k;
  int fillm = 0;
  enum px_status st = PX_STATUS_OK;
  /* media: filled with the contours where they are at t = 0 */
  S->frames = frames =
      px_mem_calloc(r->ctx, "granular fill", r->geom.ncontours * PX_GRAN_CTR_COUNT, sizeof *frames);
  if (!frames) return PX_STATUS_NOMEM;
  for (k = 0; k < r->geom.ncontours; ++k)
    px_gran_motion_frame(&r->motions[r->geom.contours[k].body], 0.0,
                         frames + k * PX_GRAN_CTR_COUNT);
  memset(&fs, 0, sizeof fs);
  {
    long count = 0, seed = 1;
    if (px_case_has(c, "granular.media.count")) {
      px_case_get_int(c, "granular.media.count", &count);
      fs.count = (size_t)count;
    } else {
      px_case_get_real(c, "granular.media.fraction", &fs.fraction);
    }
    px_case_get_enum(c, "granular.media.fill", &fillm);
    fs.method = fillm == 1 ? PX_GRAN_FILL_RANDOM : PX_GRAN_FILL_LATTICE;
    px_case_get_real(c, "granular.media.gap", &fs.gap);
    px_case_get_int(c, "granular.media.seed", &seed);
    fs.seed = (uint64_t)seed;
    fs.down[0] = S->g[0], fs.down[1] = S->g[1];
    if (px_case_has(c, "granular.media.window")) {
      px_case_get_vector(c, "granular.media.window", S->window, 4);
      fs.window = S->window;
    }
  }
  /* how many discs, and their memory, before any is placed */
  {
    const char *nkey = S->listed                                ? "granular.media.particles"
                       : px_case_has(c, "granular.media.count") ? "granular.media.count"
                                                                : "granular.media.fraction";
    size_t nn = S->n;
    if (!S->listed) {
      st = px_gran_fill_count(r->ctx, &r->geom, frames, &S->ds, &fs, &nn);
      /* a window that holds nothing is the window's error */
      st = px_gran_as_case(r, st,
                           fs.window && strncmp(px_context_message(r->ctx), "window", 6) == 0
                               ? "granular.media.window"
                               : nkey);
    }
    if (st == PX_STATUS_OK)
      st = px_sim_require_memory(
          r->sim, (double)nn * px_gran_sys_particle_bytes(px_sim_precision(r->sim), S->integ == 1),
          nkey, "the discs");
    if (st != PX_STATUS_OK) return st;
  }
  if (!S->listed)
    PX_TRY(px_gran_as_case(
        r, px_gran_fill(r->ctx, &r->geom, frames, &S->ds, &fs, &S->x, &S->y, &S->rad, &S->n),
        "granular.media"));
  S->m = px_mem_alloc(r->ctx, "granular fill", (S->n ? S->n : 1) * sizeof *S->m);
  if (!S->m) return PX_STATUS_NOMEM;
  for (k = 0; k < S->n; ++k)
    S->m[k] = S->density * PX_GRAN_PI * S->rad[k] * S->rad[k] * r->thickness;
  st = px_gran_sys_add(r->sys, S->n, S->x, S->y, S->rad, S->m);
  for (k = 0; S->listed && k < S->n && st == PX_STATUS_OK; ++k)
    st = px_gran_sys_set_velocity(r->sys, (int32_t)k, S->vel[3 * k], S->vel[3 * k + 1],
                                  S->vel[3 * k + 2]);
  return st;
}

/* The time step (prepare: the lists, the automatic dt, the checks of the
 * discs' places), and the steps of the run: the statistics count steps in
 * int. */
static enum px_status px_gran_setup_time(struct px_gran_run *r, struct px_gran_setup *S) {
  struct px_case *c = r->c;
  {
    double dt = 0;
    enum px_status st;
    if (px_case_has(c, "time.dt")) px_case_get_real(c, "time.dt", &dt);
    st = px_gran_sys_prepare(r->sys, dt, S->spc);
    if (st == PX_STATUS_CONFIG && r->sys->fail_id >= 0) {
      /* a particle out of place: name its row (listed) or the filling */
      char key[96];
      if (S->listed)
        snprintf(key, sizeof key, "granular.media.particles[%ld]", (long)r->sys->fail_id);
      else
        snprintf(key, sizeof key, "granular.media");
      st = px_gran_as_case(r, st, key);
    } else if (st == PX_STATUS_CONFIG)
      st = px_gran_as_case(r, st, px_case_has(c, "time.dt") ? "time.dt" : "granular.contact");
    if (st != PX_STATUS_OK) return st;
    r->dt = r->sys->dt;
  }
  /* the steps of the run: the statistics count steps in int */
  {
    long steps = 0;
    double end = 0, nsteps;
    char lkey[96];
    const char *key;
    if (px_case_has(c, "time.steps")) {
      px_case_get_int(c, "time.steps", &steps);
      nsteps = (double)steps;
      key = "time.steps";
    } else {
      px_case_get_real(c, "time.end", &end);
      nsteps = ceil(end / r->dt - 1e-9);
      key = px_case_has(c, "time.dt") ? "time.dt"
                                      : px_gran_law_key(c, S->tc_pw < S->tc_pp, "kn", lkey);
    }
    if (!(nsteps <= PX_GRAN_STEPS_MAX))
      return px_case_fail(c, key,
                          "%.4g steps of dt = %.4g s (contact duration t_c = %.4g s): more "
                          "than the %.0f steps a granular run may take",
                          nsteps, r->dt, px_gran_sys_contact_time(r->sys), PX_GRAN_STEPS_MAX);
  }
  return PX_STATUS_OK;
}

/* The picture keys, and the histogram's speed range when the case leaves it. */
static void px_gran_setup_pictures(struct px_gran_run *r, struct px_gran_setup *S) {
  struct px_case *c = r->c;
  {
    int color = 0;
    long w = 1400, hgt = 1000;
    px_case_get_enum(c, "granular.picture.color", &color);
    px_case_get_int(c, "granular.picture.width", &w);
    px_case_get_int(c, "granular.picture.height", &hgt);
    px_case_get_real(c, "granular.picture.range", &r->range);
    r->color = color;
    r->width = (int)w;
    r->height = (int)hgt;
  }
  S->auto_vmax = !(r->speed_max > 0);
  if (S->auto_vmax) {
    /* three times the fastest wall, or 1 m/s */
    double vmax = 0;
    size_t b;
    for (b = 0; b < r->nbodies; ++b) {
      const double v = px_gran_motion_max_speed(&r->motions[b], 0);
      if (v > vmax) vmax = v;
    }
    r->speed_max = vmax > 0 ? 3 * vmax : 1.0;
  }
}

/* A case into a run ready to step: the stages in order, each failure at
 * its key. */
static enum px_status px_gran_create_run(struct px_gran_run *r) {
  struct px_backend *be = px_sim_backend(r->sim);
  struct px_gran_setup S;
  enum px_status st;
  memset(&S, 0, sizeof S);
  PX_TRY(px_gran_pick_engine(r, be, &S.caps));
  PX_TRY(px_gran_setup_read(r, &S));
  st = px_gran_setup_radii(r, &S);
  if (st == PX_STATUS_OK) st = px_gran_setup_walls(r, &S);
  if (st == PX_STATUS_OK) st = px_gran_setup_system(r, &S);
  if (st == PX_STATUS_OK) st = px_gran_setup_media(r, &S);
  if (st == PX_STATUS_OK) st = px_gran_setup_time(r, &S);
  if (st == PX_STATUS_OK) st = px_gran_stats_config(r);
  if (st == PX_STATUS_OK) st = px_gran_sys_stats_enable(r->sys, &r->sspec);
  if (st == PX_STATUS_OK) {
    px_gran_setup_pictures(r, &S);
    st = r->eng->create(be, r->sys, &r->engine);
  }
  if (st == PX_STATUS_OK) px_gran_note_autos(r, &S.caps, S.auto_h ? S.h : 0, S.skin, S.auto_vmax);
  px_gran_setup_free(r, &S);
  return st;
}

static enum px_status px_gran_create(struct px_sim *sim, void **state) {
  struct px_gran_run *r;
  struct px_context *ctx = px_sim_context(sim);
  enum px_status st;
  *state = NULL;
  r = px_mem_calloc(ctx, "granular run", 1, sizeof *r);
  if (!r) return PX_STATUS_NOMEM;
  r->sim = sim;
  r->ctx = ctx;
  r->c = (struct px_case *)(size_t)px_sim_case(sim);
  r->last_step = -1;
  r->first_step = -1;
  px_gran_geom_init(&r->geom);
  st = px_gran_create_run(r);
  if (st != PX_STATUS_OK) {
    px_gran_destroy(r);
    return st;
  }
  *state = r;
  return PX_STATUS_OK;
}

static void px_gran_destroy(void *state) {
  struct px_gran_run *r = state;
  size_t b;
  if (!r) return;
  px_gran_out_close(r);
  if (r->engine) r->eng->destroy(r->engine);
  px_gran_sys_free(r->sys);
  px_gran_geom_free(r->ctx, &r->geom);
  for (b = 0; b < r->nbodies; ++b) px_gran_motion_free(r->ctx, &r->motions[b]);
  px_mem_free(r->ctx, r->motions);
  px_mem_free(r->ctx, r->bodies);
  px_mem_free(r->ctx, r->report);
  px_gran_fn_free(r->ctx, &r->hardening);
  px_gran_fn_free(r->ctx, &r->residual);
  px_mem_free(r->ctx, r->plot);
  px_mem_free(r->ctx, r);
}

static enum px_status px_gran_time_step(void *state, double *dt) {
  const struct px_gran_run *r = state;
  *dt = r->dt;
  return PX_STATUS_OK;
}

static enum px_status px_gran_step(void *state, long step, double t, double dt) {
  struct px_gran_run *r = state;
  if (r->first_step < 0) r->first_step = step;
  if (!r->impacts_checked) {
    /* the first step of this process: a resumed run logs impacts from here
     * (rank 0 writes the outputs) */
    if (step > 0 && px_comm_rank(px_context_comm(r->ctx)) == 0)
      PX_TRY(px_gran_out_impacts_resume(r, t));
    r->impacts_checked = 1;
  }
  (void)t;
  return r->eng->step(r->engine, step, dt);
}

static long px_gran_count(const void *state) {
  const struct px_gran_run *r = state;
  return r && r->sys ? (long)r->sys->n : 0;
}

static enum px_status px_gran_snapshot(void *state, const struct px_sim_output *o) {
  PX_TRY(px_gran_sync(state));
  return px_gran_out_snapshot(state, o);
}
static enum px_status px_gran_series(void *state, const struct px_sim_output *o) {
  PX_TRY(px_gran_sync(state));
  return px_gran_out_series(state, o);
}
static enum px_status px_gran_picture(void *state, const struct px_sim_output *o) {
  PX_TRY(px_gran_sync(state));
  return px_gran_out_picture(state, o);
}
static enum px_status px_gran_finish(void *state, const struct px_sim_output *o) {
  struct px_gran_run *r = state;
  const struct px_gran_sys *s = r->sys;
  PX_TRY(px_gran_sync(state));
  /* what the thread tuner chose depends on the machine's load: run.log only
   * (summary.json stays the same for the same results) */
  if (!o->render && s->threads > 1 && px_tuner_tuning(&s->tuner) && o->step > r->first_step &&
      r->first_step >= 0)
    px_log(r->ctx, PX_LOG_LEVEL_INFO,
           "backend.threads: %d threads in %.1f %% of the steps of this process, 1 in the others",
           s->threads, 100.0 * (double)s->steps_parallel / (double)(o->step - r->first_step));
  return px_gran_out_finish(state, o);
}
static enum px_status px_gran_report(void *state, const struct px_sim_output *o,
                                     struct px_summary *sum) {
  return px_gran_out_report(state, o, sum);
}
/* Over ranks: the owners' state onto every rank (outputs and save read
 * rank 0's). */
static enum px_status px_gran_gather(void *state) {
  struct px_gran_run *r = state;
  return r->engine && r->eng->gather ? r->eng->gather(r->engine) : PX_STATUS_OK;
}
static enum px_status px_gran_save_fn(void *state, struct px_checkpoint_writer *w) {
  return px_gran_save(state, w);
}
static enum px_status px_gran_load_fn(void *state, struct px_checkpoint *ck) {
  return px_gran_load(state, ck);
}

/* Keys that only change how the results are drawn. */
static const char *const px_gran_resume_keys[] = {"granular.picture", "granular.statistics.picture",
                                                  "granular.statistics.hardening.unit",
                                                  "granular.statistics.residual_stress.unit", NULL};

const struct px_solver_i px_solver_granular = {
    .name = "granular",
    .summary =
        "2D vibro-impact DEM: media discs in vibrating containers, impact statistics on parts",
    .create = px_gran_create,
    .destroy = px_gran_destroy,
    .time_step = px_gran_time_step,
    .step = px_gran_step,
    .snapshot = px_gran_snapshot,
    .series = px_gran_series,
    .picture = px_gran_picture,
    .finish = px_gran_finish,
    .save = px_gran_save_fn,
    .load = px_gran_load_fn,
    .count = px_gran_count,
    .report = px_gran_report,
    .results = px_gran_results,
    .resume_keys = px_gran_resume_keys,
    .ranks = 1,
    .gather = px_gran_gather};
