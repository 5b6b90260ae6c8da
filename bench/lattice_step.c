/* Lattice step throughput: element-steps per second (one full RK4 step of
 * one element; leapfrog steps reported separately) for boxes of about 1e5
 * and 1e6 elements, per engine, scheme and precision, with the memory per
 * element, next to a naive baseline run in the same process.
 *
 * The baseline is a plain double-precision OpenMP RK4 loop of this model as
 * the original code writes it: array of structs, Cardan angles, a rotation
 * matrix from 6 sin/cos per element per stage, the Cardan kinematic
 * equations (1/cos, tan) for the angle rates, each element gathering its 6
 * links, separate passes for forces, stage update and matrices.
 *
 * Besides wall-clock element-steps/s (all the timed steps) it reports
 * element-steps per CPU second of the process (stable on a shared machine;
 * see cpu_seconds) and, the timed steps being run in up to 5 blocks (one
 * engine run each, timed alone: `blocks`), the rate's min/median/max over
 * the blocks.
 *
 * footprint_bytes_per_element: the memory the engine allocates per element
 * (state, stage buffers, links; the docs' "bytes per element"), not the
 * traffic of a step. bytes_per_step_model: a lower bound of that traffic,
 * the footprint read once per step (the stages read some arrays several
 * times); a model, not a count. threads_used: the team an OpenMP region of
 * the engine's thread count gets (measured; the cpu engine caps the threads
 * asked for at one per 16384 cells; 0 for an opencl device).
 * sum_precision: the arithmetic of the link forces and stage sums (the
 * precision column: float for single, double for double).
 *
 * --threads auto: all cores, the cpu engine's thread tuner (core/tuner.h)
 * choosing 1 or all per step as `partix run` does with backend.threads 0;
 * tuner "tune" / "fixed", parallel_step_fraction (the share of the timed
 * steps run on more than one thread) and threads_used_mean = 1 +
 * (threads_used - 1) x that share say what ran.
 *
 * triad: first, a STREAM triad on the cpu engine's threads (bench_util.h:
 * 24 bytes per element over 3 x 2^24 doubles, best of 7); each cpu line
 * then gives triad_bytes_per_s and model_bandwidth_fraction = its
 * bytes_per_step_model x steps/s over that triad (issue 22's share of the
 * bandwidth bound; the model being a lower bound of the traffic, so is the
 * fraction). --no-triad skips it (callgrind).
 *
 * --scheme, --precision, --integrator: run only that one (profiling, e.g.
 * under valgrind --tool=callgrind; docs/notes/lattice-poisson.md "Cost").
 *
 * Usage: lattice_step [--quick] [--sizes N,N] [--steps S] [--threads T|auto]
 *                     [--no-opencl] [--no-baseline] [--no-triad]
 *                     [--integrator rk4|leapfrog]
 *                     [--scheme gather|link_once] [--precision single|double]
 *                     [--poisson NU]
 * Prints one JSON object per line. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench_util.h"
#include "partix/partix.h"
#include "solvers/lattice/lattice_cpu.h"
#include "solvers/lattice/lattice_engine.h"

/* the timed steps of a line are run in up to this many blocks, each timed */
#define LT_BENCH_BLOCKS 5

/* Process CPU time [s] (all threads): on a shared, oversubscribed machine
 * element-steps per CPU second is the stable figure (with --threads 1 it is
 * the per-core throughput; with more threads it also counts barrier
 * spinning). */
static double cpu_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---------------------------------------------------------------------------
 * Naive baseline (double, AoS, Cardan angles). */
struct naive_el {
  double x[3], r[3], v[3], w[3]; /* displacement, Cardan angles, velocity, body rate */
};
struct naive_rate {
  double dx[3], dr[3], dv[3], dw[3];
};

/* A = Rx(a) Ry(b) Rz(c), as FRUND's UpdateMatrix. */
static void naive_matrix(const double r[3], double A[9]) {
  double sa = sin(r[0]), ca = cos(r[0]), sb = sin(r[1]), cb = cos(r[1]), sc = sin(r[2]),
         cc = cos(r[2]);
  A[0] = cb * cc;
  A[1] = -cb * sc;
  A[2] = sb;
  A[3] = sa * sb * cc + ca * sc;
  A[4] = -sa * sb * sc + ca * cc;
  A[5] = -sa * cb;
  A[6] = -ca * sb * cc + sa * sc;
  A[7] = ca * sb * sc + sa * cc;
  A[8] = ca * cb;
}

struct naive {
  int n0, n1, n2;
  size_t n;
  double h, k, kb, kt, m, I;
  struct naive_el *y0, *ys, *acc;
  struct naive_rate *rate;
  double *A; /* 9 per element */
};

static void naive_forces(struct naive *s, const struct naive_el *y) {
  long e;
  const int n0 = s->n0, n1 = s->n1, n2 = s->n2;
#pragma omp parallel for schedule(static)
  for (e = 0; e < (long)s->n; ++e) {
    int i = (int)(e % n0), j = (int)((e / n0) % n1), kk = (int)(e / ((long)n0 * n1));
    const double *A1 = s->A + 9 * e;
    double F[3] = {0, 0, 0}, M[3] = {0, 0, 0};
    int side;
    for (side = 0; side < 6; ++side) {
      int a = side % 3, sg = side < 3 ? -1 : 1, ijk[3] = {i, j, kk}, dims[3] = {n0, n1, n2};
      long nb;
      double c1[3] = {0, 0, 0}, c2[3] = {0, 0, 0}, p1[3], p2[3], d[3], g[3], f[3];
      const double *A2;
      int q;
      ijk[a] += sg;
      if (ijk[a] < 0 || ijk[a] >= dims[a]) continue;
      nb = ijk[0] + (long)n0 * (ijk[1] + (long)n1 * ijk[2]);
      A2 = s->A + 9 * nb;
      c1[a] = 0.5 * sg * s->h;
      c2[a] = -c1[a];
      for (q = 0; q < 3; ++q) {
        p1[q] = y[e].x[q] + A1[3 * q] * c1[0] + A1[3 * q + 1] * c1[1] + A1[3 * q + 2] * c1[2];
        p2[q] = y[nb].x[q] + A2[3 * q] * c2[0] + A2[3 * q + 1] * c2[1] + A2[3 * q + 2] * c2[2];
        /* x holds displacements: the reference positions differ by -sg h e_a,
         * so the gap is p1 - p2 - sg h e_a (zero at rest) */
        d[q] = p1[q] - p2[q] - (q == a ? sg * s->h : 0.0);
      }
      for (q = 0; q < 3; ++q) g[q] = A1[q] * d[0] + A1[3 + q] * d[1] + A1[6 + q] * d[2];
      for (q = 0; q < 3; ++q) f[q] = -s->k * g[q];
      for (q = 0; q < 3; ++q)
        F[q] += A1[3 * q] * f[0] + A1[3 * q + 1] * f[1] + A1[3 * q + 2] * f[2];
      M[0] += c1[1] * f[2] - c1[2] * f[1];
      M[1] += c1[2] * f[0] - c1[0] * f[2];
      M[2] += c1[0] * f[1] - c1[1] * f[0];
      for (q = 0; q < 3; ++q) M[q] -= (q == a ? s->kt : s->kb) * (y[e].r[q] - y[nb].r[q]);
    }
    {
      const double *r = y[e].r, *w = y[e].w;
      double sc = sin(r[2]), cc = cos(r[2]), cb = cos(r[1]), tb = tan(r[1]);
      int q;
      for (q = 0; q < 3; ++q) {
        s->rate[e].dx[q] = y[e].v[q];
        s->rate[e].dv[q] = F[q] / s->m;
        s->rate[e].dw[q] = M[q] / s->I;
      }
      s->rate[e].dr[0] = (w[0] * cc - w[1] * sc) / cb;
      s->rate[e].dr[1] = w[0] * sc + w[1] * cc;
      s->rate[e].dr[2] = (w[1] * sc - w[0] * cc) * tb + w[2];
    }
  }
}

static void naive_axpy(struct naive *s, struct naive_el *out, const struct naive_el *y, double c) {
  long e;
#pragma omp parallel for schedule(static)
  for (e = 0; e < (long)s->n; ++e) {
    int q;
    for (q = 0; q < 3; ++q) {
      out[e].x[q] = y[e].x[q] + c * s->rate[e].dx[q];
      out[e].r[q] = y[e].r[q] + c * s->rate[e].dr[q];
      out[e].v[q] = y[e].v[q] + c * s->rate[e].dv[q];
      out[e].w[q] = y[e].w[q] + c * s->rate[e].dw[q];
    }
  }
}

static void naive_matrices(struct naive *s, const struct naive_el *y) {
  long e;
#pragma omp parallel for schedule(static)
  for (e = 0; e < (long)s->n; ++e) naive_matrix(y[e].r, s->A + 9 * e);
}

static void naive_step(struct naive *s, double dt) {
  static const double c[4] = {0.5, 0.5, 1.0, 0.0}, b[4] = {1.0, 2.0, 2.0, 1.0};
  int st;
  long e;
  memset(s->acc, 0, s->n * sizeof *s->acc);
  naive_matrices(s, s->y0);
  for (st = 0; st < 4; ++st) {
    const struct naive_el *ys = st == 0 ? s->y0 : s->ys;
    naive_forces(s, ys);
    naive_axpy(s, s->acc, s->acc, b[st]);
    if (st < 3) {
      naive_axpy(s, s->ys, s->y0, c[st] * dt);
      naive_matrices(s, s->ys);
    }
  }
#pragma omp parallel for schedule(static)
  for (e = 0; e < (long)s->n; ++e) {
    int q;
    for (q = 0; q < 3; ++q) {
      s->y0[e].x[q] += dt / 6.0 * s->acc[e].x[q];
      s->y0[e].r[q] += dt / 6.0 * s->acc[e].r[q];
      s->y0[e].v[q] += dt / 6.0 * s->acc[e].v[q];
      s->y0[e].w[q] += dt / 6.0 * s->acc[e].w[q];
    }
  }
}

static double naive_run(int n0, int n1, int n2, int steps, double *bytes, double *cpu_rate) {
  struct naive s;
  double c0, t0, t1, E = 2.1e11, rho = 7850.0, h = 1e-3, dt;
  size_t e;
  s.n0 = n0;
  s.n1 = n1;
  s.n2 = n2;
  s.n = (size_t)n0 * (size_t)n1 * (size_t)n2;
  s.h = h;
  s.k = E * h;
  s.kb = E * h * h * h / 12.0;
  s.kt = 0.5 * E * 0.1406 * h * h * h;
  s.m = rho * h * h * h;
  s.I = s.m * h * h / 6.0;
  s.y0 = (struct naive_el *)calloc(s.n, sizeof *s.y0);
  s.ys = (struct naive_el *)calloc(s.n, sizeof *s.ys);
  s.acc = (struct naive_el *)calloc(s.n, sizeof *s.acc);
  s.rate = (struct naive_rate *)calloc(s.n, sizeof *s.rate);
  s.A = (double *)calloc(9 * s.n, sizeof(double));
  if (!s.y0 || !s.ys || !s.acc || !s.rate || !s.A) return -1.0;
  for (e = 0; e < s.n; ++e) s.y0[e].v[2] = 1e-3 * (double)(e % 7); /* some motion */
  dt = 0.5 * h / sqrt(E / rho);
  naive_step(&s, dt);
  c0 = cpu_seconds();
  t0 = omp_get_wtime();
  {
    int k;
    for (k = 0; k < steps; ++k) naive_step(&s, dt);
  }
  t1 = omp_get_wtime();
  *cpu_rate = (double)s.n * steps / (cpu_seconds() - c0);
  *bytes = (double)(3 * sizeof(struct naive_el) + sizeof(struct naive_rate) + 9 * sizeof(double));
  free(s.y0);
  free(s.ys);
  free(s.acc);
  free(s.rate);
  free(s.A);
  return (double)s.n * steps / (t1 - t0);
}

/* ---------------------------------------------------------------------------
 * partix engines */
/* --threads auto: the cpu engine tunes its thread count */
static int tune_threads;
/* --poisson NU: Poisson's ratio of the partix engines (lattice.poisson; the
 * naive baseline has none) */
static double poisson;
/* --scheme, --precision: run only that one (-1: all) */
static int only_scheme = -1, only_prec = -1;
/* the triad's bandwidth [bytes/s] measured in this run on the cpu engine's
 * threads (0: not measured, --no-triad) */
static double triad_bw;

static int engine_run(struct px_context *ctx, const struct px_lattice_engine_i *vt,
                      struct px_backend *be, int n0, int n1, int n2, enum px_precision p,
                      enum px_lattice_scheme scheme, enum px_lattice_integrator integ, int threads,
                      int steps, double *rate, double *bytes, double *cpu_rate, int *engine_threads,
                      double *par_frac, struct px_bench_stats *blk, int *nblk) {
  struct px_lattice_grid g;
  struct px_lattice_model m;
  struct px_lattice_params par;
  struct px_lattice_bc bc;
  struct px_lattice_engine_opts o;
  void *e = NULL;
  double dt, t0, t1, c0;
  memset(&par, 0, sizeof par);
  par.E = 2.1e11;
  par.rho = 7850.0;
  par.zeta = 0.02;
  par.nu = poisson;
  memset(&bc, 0, sizeof bc);
  bc.sel.face = PX_LATTICE_FACE_X_MIN;
  bc.fix = 63;
  if (px_lattice_grid_box(ctx, 1e-3, n0, n1, n2, &g) != PX_STATUS_OK) return -1;
  if (px_lattice_model_build(ctx, &m, &g, &par, &bc, 1) != PX_STATUS_OK) return -1;
  memset(&o, 0, sizeof o);
  o.integ = integ;
  o.precision = p;
  o.scheme = scheme;
  o.threads = threads;
  o.tune = tune_threads;
  o.backend = be;
  if (vt->create(ctx, &m, &o, &e) != PX_STATUS_OK) {
    px_lattice_model_free(ctx, &m);
    return -1;
  }
  dt = 0.5 * px_lattice_model_dt_limit(&m, integ);
  if (vt->run(e, 0, 0.0, dt, 2) != PX_STATUS_OK) return -1;
  if (be) px_backend_finish(be);
  c0 = cpu_seconds();
  t0 = omp_get_wtime();
  {
    /* the cpu engine's tuner (private: lattice_cpu.h) counts the steps run
     * on more than one thread */
    struct px_tuner *tu =
        vt == &px_lattice_engine_cpu ? &((struct px_lattice_cpu *)e)->tuner : NULL;
    const long s0 = tu ? tu->steps : 0, p0 = tu ? tu->steps_parallel : 0;
    /* the timed steps in blocks, each timed: the spread of the rate */
    double br[LT_BENCH_BLOCKS];
    const int nb = steps < LT_BENCH_BLOCKS ? steps : LT_BENCH_BLOCKS;
    for (int k = 0; k < nb; ++k) {
      const int a = steps * k / nb, b = steps * (k + 1) / nb;
      const double b0 = omp_get_wtime();
      if (vt->run(e, 2 + a, (2 + a) * dt, dt, b - a) != PX_STATUS_OK) return -1;
      if (be) px_backend_finish(be);
      br[k] = (double)m.grid.count * (b - a) / (omp_get_wtime() - b0);
    }
    *blk = px_bench_stats(br, (size_t)nb);
    *nblk = nb;
    *par_frac =
        tu && tu->steps > s0 ? (double)(tu->steps_parallel - p0) / (double)(tu->steps - s0) : 0.0;
    if (tu && tu->most == 1) *par_frac = 0.0;
  }
  if (be) px_backend_finish(be);
  t1 = omp_get_wtime();
  *rate = (double)m.grid.count * steps / (t1 - t0);
  *cpu_rate = (double)m.grid.count * steps / (cpu_seconds() - c0);
  *bytes = (double)vt->bytes(e) * (double)m.nalloc / (double)m.grid.count;
  {
    /* the cpu engine's own thread count: px_lattice_cpu_threads
     * (lattice_cpu.c) caps it at one thread per 16384 cells (rule repeated
     * here: the engine does not expose it) */
    const size_t cells = m.n0p * (size_t)m.grid.n[1] * (size_t)m.grid.n[2];
    const int want = threads > 0 ? threads : omp_get_max_threads();
    const int most = (int)(cells / 16384) + 1;
    *engine_threads = be ? 0 : want > most ? most : want;
  }
  vt->destroy(e);
  px_lattice_model_free(ctx, &m);
  return 0;
}

static const char *prec_name(enum px_precision p) {
  return p == PX_PRECISION_DOUBLE ? "double" : "single";
}

/* One JSON line per integrator x precision x scheme of engine vt (on backend
 * be: opencl; NULL: cpu with `threads`), cubes of n^3, st steps (leapfrog 4 st). */
static void bench_engine(struct px_context *ctx, const struct px_lattice_engine_i *vt,
                         struct px_backend *be, int n, int st, int threads, int only_integ) {
  long elems = (long)n * n * n;
  for (int integ = 0; integ < 2; ++integ)
    for (int p = 0; p < 2; ++p)
      for (int sc = PX_LATTICE_SCHEME_GATHER; sc <= PX_LATTICE_SCHEME_LINK_ONCE; ++sc) {
        enum px_precision pr = p ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
        double rate, bytes, cpu_rate, load0, load1, par_frac = 0;
        struct px_bench_stats blk;
        int eng_threads = 0, nblk = 0;
        char where[160];
        if (only_integ >= 0 && integ != only_integ) continue;
        if ((only_scheme >= 0 && sc != only_scheme) || (only_prec >= 0 && p != only_prec)) continue;
        if (be && pr == PX_PRECISION_DOUBLE && !px_backend_has_fp64(be)) continue;
        const int req = be ? 0 : threads > 0 ? threads : omp_get_max_threads();
        load0 = px_bench_load1();
        if (engine_run(ctx, vt, be, n, n, n, pr, (enum px_lattice_scheme)sc,
                       (enum px_lattice_integrator)integ, threads, integ ? 4 * st : st, &rate,
                       &bytes, &cpu_rate, &eng_threads, &par_frac, &blk, &nblk) != 0) {
          fprintf(stderr, "%s engine failed: %s\n", vt->name, px_context_message(ctx));
          continue;
        }
        load1 = px_bench_load1();
        where[0] = 0;
        if (be) snprintf(where, sizeof where, "\"device\":\"%s\",", px_backend_device(be));
        printf(
            "{\"bench\":\"lattice_step\",\"engine\":\"%s\",\"integrator\":\"%s\","
            "\"precision\":\"%s\",\"sum_precision\":\"%s\",\"scheme\":\"%s\","
            "\"elements\":%ld,%s\"element_steps_per_s\":%.4g,"
            "\"element_steps_per_s_min\":%.4g,\"element_steps_per_s_median\":%.4g,"
            "\"element_steps_per_s_max\":%.4g,\"blocks\":%d,"
            "\"element_steps_per_cpu_s\":%.4g,\"footprint_bytes_per_element\":%.0f,"
            "\"bytes_per_step_model\":%.4g,\"poisson\":%g",
            vt->name, integ ? "leapfrog" : "rk4", prec_name(pr),
            pr == PX_PRECISION_DOUBLE ? "double" : "float",
            sc == PX_LATTICE_SCHEME_LINK_ONCE ? "link_once" : "gather", elems, where, rate, blk.min,
            blk.median, blk.max, nblk, cpu_rate, bytes, bytes * (double)elems, poisson);
        if (!be)
          printf(",\"tuner\":\"%s\",\"parallel_step_fraction\":%.3f,\"threads_used_mean\":%.3f",
                 tune_threads && eng_threads > 1 ? "tune" : "fixed", par_frac,
                 1.0 + (eng_threads - 1) * par_frac);
        /* the model's traffic per second against the triad of this run: a
           lower bound of the share of the bandwidth the step uses */
        if (!be && triad_bw > 0.0)
          printf(",\"triad_bytes_per_s\":%.4g,\"model_bandwidth_fraction\":%.3f", triad_bw,
                 bytes * rate / triad_bw);
        px_bench_json_env(stdout, req, be ? 0 : px_bench_threads_used(eng_threads), load0, load1);
        printf("}\n");
        fflush(stdout);
      }
}

int main(int argc, char **argv) {
  struct px_context *ctx;
  int sizes[2] = {46, 100}, nsizes = 2, steps = 0, threads = 0, use_ocl = 1, baseline = 1, a, si;
  int triad = 1;
  int only_integ = -1; /* --integrator: run only that one (profiling) */
  for (a = 1; a < argc; ++a) {
    if (strcmp(argv[a], "--quick") == 0) {
      sizes[0] = 24;
      nsizes = 1;
      steps = 5;
    } else if (strcmp(argv[a], "--sizes") == 0 && a + 1 < argc) {
      nsizes = sscanf(argv[++a], "%d,%d", &sizes[0], &sizes[1]);
    } else if (strcmp(argv[a], "--steps") == 0 && a + 1 < argc) {
      steps = atoi(argv[++a]);
    } else if (strcmp(argv[a], "--threads") == 0 && a + 1 < argc) {
      ++a;
      tune_threads = strcmp(argv[a], "auto") == 0;
      threads = tune_threads ? 0 : atoi(argv[a]);
    } else if (strcmp(argv[a], "--no-opencl") == 0) {
      use_ocl = 0;
    } else if (strcmp(argv[a], "--no-baseline") == 0) {
      baseline = 0;
    } else if (strcmp(argv[a], "--no-triad") == 0) {
      triad = 0;
    } else if (strcmp(argv[a], "--poisson") == 0 && a + 1 < argc) {
      poisson = atof(argv[++a]);
    } else if (strcmp(argv[a], "--integrator") == 0 && a + 1 < argc) {
      ++a;
      only_integ = strcmp(argv[a], "rk4") == 0 ? 0 : 1;
    } else if (strcmp(argv[a], "--scheme") == 0 && a + 1 < argc &&
               (strcmp(argv[a + 1], "gather") == 0 || strcmp(argv[a + 1], "link_once") == 0)) {
      ++a;
      only_scheme =
          strcmp(argv[a], "gather") == 0 ? PX_LATTICE_SCHEME_GATHER : PX_LATTICE_SCHEME_LINK_ONCE;
    } else if (strcmp(argv[a], "--precision") == 0 && a + 1 < argc &&
               (strcmp(argv[a + 1], "single") == 0 || strcmp(argv[a + 1], "double") == 0)) {
      ++a;
      only_prec = strcmp(argv[a], "double") == 0 ? 1 : 0;
    } else {
      fprintf(stderr,
              "usage: %s [--quick] [--sizes N,N] [--steps S] [--threads T|auto] "
              "[--no-opencl] [--no-baseline] [--no-triad] [--integrator rk4|leapfrog] "
              "[--scheme gather|link_once] [--precision single|double] [--poisson NU]\n",
              argv[0]);
      return 2;
    }
  }
  if (threads > 0) omp_set_num_threads(threads);
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  if (triad) {
    /* three arrays of 2^24 doubles (384 MiB), far above any last-level cache */
    const int tt = threads > 0 ? threads : omp_get_max_threads();
    const double load0 = px_bench_load1();
    double med = 0.0;
    triad_bw = px_bench_triad(tt, (size_t)1 << 24, 7, &med);
    printf(
        "{\"bench\":\"triad\",\"bytes_per_s\":%.4g,\"bytes_per_s_median\":%.4g,"
        "\"bytes_per_element\":24,\"elements\":%d,\"reps\":7",
        triad_bw, med, 1 << 24);
    px_bench_json_env(stdout, tt, px_bench_threads_used(tt), load0, px_bench_load1());
    printf("}\n");
    fflush(stdout);
  }
  for (si = 0; si < nsizes; ++si) {
    int n = sizes[si], st = steps > 0 ? steps : (n <= 50 ? 20 : 4);
    if (baseline) {
      long elems = (long)n * n * n;
      const double load0 = px_bench_load1();
      double bytes = 0.0, cpu_rate = 0.0, rate = naive_run(n, n, n, st, &bytes, &cpu_rate);
      const double load1 = px_bench_load1();
      printf(
          "{\"bench\":\"lattice_step\",\"engine\":\"naive\",\"integrator\":\"rk4\","
          "\"precision\":\"double\",\"sum_precision\":\"double\",\"scheme\":\"gather\","
          "\"elements\":%ld,\"element_steps_per_s\":%.4g,\"element_steps_per_cpu_s\":%.4g,"
          "\"footprint_bytes_per_element\":%.0f,\"bytes_per_step_model\":%.4g",
          elems, rate, cpu_rate, bytes, bytes * (double)elems);
      px_bench_json_env(stdout, omp_get_max_threads(), px_bench_threads_used(omp_get_max_threads()),
                        load0, load1);
      printf("}\n");
      fflush(stdout);
    }
    bench_engine(ctx, &px_lattice_engine_cpu, NULL, n, st, threads, only_integ);
#ifdef PX_HAVE_OPENCL
    if (use_ocl && px_backend_opencl_device_count(ctx) > 0) {
      struct px_backend *be = NULL;
      if (px_backend_create(ctx, "opencl", px_backend_default_device("opencl"), 0, &be) ==
          PX_STATUS_OK) {
        bench_engine(ctx, &px_lattice_engine_opencl, be, n, st, 0, only_integ);
        px_backend_free(be);
      }
    }
#else
    (void)use_ocl;
#endif
  }
  px_context_free(ctx);
  return 0;
}
