/* Hostile input to the vortex solver (issue 19; docs/running.md, "What
 * partix trusts"):
 *  - profile files are read with bounded sizes: a device (/dev/zero), a
 *    pipe or a directory is refused without reading or waiting; a file of
 *    more than 16 MiB, a line of more than 1024 bytes, a NUL byte, more than
 *    100001 points and coordinates beyond +-1e9 are refused with FILE:LINE;
 *  - the crossing checks of contours take O(n log n) for smooth contours (a
 *    100000-panel contour is checked in well under a second where the old
 *    pair loop took 40 s) and refuse, naming the limit, a contour they cannot
 *    clear within their work limit;
 *    the crossing found is the first pair (k, j), k < j, as the plain loop
 *    over all pairs finds it;
 *  - absurd sizes are refused at their key with the memory figure before
 *    any body is built: the schema's panel range matches what can run, and a
 *    case whose panel matrix exceeds the machine's memory is refused;
 *  - checkpoints with valid CRCs and forged contents (counts, non-finite
 *    and out-of-range values, missing or mistyped sections) are refused with
 *    PX_STATUS_FORMAT naming the file and the section, before anything is
 *    used. */
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/sim.h"
#include "px_test.h"
#include "px_test_ck.h"
#include "solvers/vortex/vortex_profile.h"
#include "vortex/vx_test_util.h"

#define PI 3.14159265358979323846

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void write_text(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  if (!f) return;
  fputs(text, f);
  fclose(f);
}

/* A closed circle of n panels as a point list (n + 1 lines, the first point
 * repeated), also a Selig file (the title is optional). */
static void write_circle(const char *path, size_t n) {
  FILE *f = fopen(path, "w");
  if (!f) return;
  for (size_t k = 0; k <= n; ++k) {
    double t = 2.0 * PI * (double)(k % n) / (double)n;
    fprintf(f, "%.15f %.15f\n", 0.5 + 0.5 * cos(t), 0.5 * sin(t));
  }
  fclose(f);
}

/* Read `path` as a Selig file and as a point list: both refused with
 * PX_STATUS_CONFIG and messages holding what1 and what2. */
static void expect_file_refused(struct px_context *ctx, const char *path, const char *what1,
                                const char *what2) {
  struct px_vortex_contour c;
  PX_CHECK_STATUS(ctx, px_vortex_profile_read_selig(ctx, path, 64, PX_VORTEX_SPACING_COSINE, &c),
                  PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, what1));
  if (what2) PX_CHECK(vx_test_message_has(ctx, what2));
  px_context_clear(ctx);
  PX_CHECK_STATUS(ctx, px_vortex_profile_read_points(ctx, path, 0, &c), PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, what1));
  if (what2) PX_CHECK(vx_test_message_has(ctx, what2));
  px_context_clear(ctx);
}

static void test_profile_files(struct px_context *ctx) {
  /* a device, a pipe with no writer (opening it used to wait forever), a
   * directory */
  expect_file_refused(ctx, "/dev/zero", "/dev/zero: not a regular file", "character device");
  unlink("vx_fifo.dat");
  PX_CHECK(mkfifo("vx_fifo.dat", 0600) == 0);
  expect_file_refused(ctx, "vx_fifo.dat", "vx_fifo.dat: not a regular file", "pipe");
  unlink("vx_fifo.dat");
  expect_file_refused(ctx, ".", ".: not a regular file", "directory");

  /* 17 MiB (sparse: NUL bytes) is beyond the 16 MiB a profile may hold */
  int fd = open("vx_huge.dat", O_WRONLY | O_CREAT | O_TRUNC, 0644);
  PX_CHECK(fd >= 0 && ftruncate(fd, 17L * 1024 * 1024) == 0);
  if (fd >= 0) close(fd);
  expect_file_refused(ctx, "vx_huge.dat", "vx_huge.dat: 17825792 bytes", "16777216");
  unlink("vx_huge.dat");

  /* a NUL byte, a line of 2000 bytes, a coordinate of 1e300 */
  FILE *f = fopen("vx_nul.dat", "wb");
  if (f) {
    fwrite("1 0\n0.5 0.06\0\n0 0\n", 1, 18, f);
    fclose(f);
  }
  expect_file_refused(ctx, "vx_nul.dat", "vx_nul.dat:2:", "NUL byte");
  char line[2100];
  memset(line, ' ', sizeof line);
  memcpy(line + 2000, "1 0\n", 5);
  f = fopen("vx_long.dat", "w");
  if (f) {
    fputs("1 0\n", f);
    fputs(line, f);
    fclose(f);
  }
  expect_file_refused(ctx, "vx_long.dat", "vx_long.dat:2:", "longer than 1024 bytes");
  write_text("vx_far.dat", "1 0\n0.5 0.06\n0 0\n1e300 -0.06\n1 0\n");
  expect_file_refused(ctx, "vx_far.dat", "vx_far.dat:4:", "beyond +-1e+09");

  /* more points than a profile file may hold: refused at the first one too
   * many, in a fraction of a second (the check of all pairs took minutes) */
  write_circle("vx_200k.dat", 200000);
  double t0 = now_s();
  expect_file_refused(ctx, "vx_200k.dat", "vx_200k.dat:100002:", "more than 100001 points");
  double t = now_s() - t0;
  PX_CHECK_MSG(t < 5.0, "refusing a 200000-point file took %.2f s", t);
  unlink("vx_200k.dat");
}

/* The plain reference of the crossing test: every pair of non-adjacent
 * panels in lexicographic order (the loop the tree replaced); the first
 * crossing pair into *k, *j, or 0 for none. Segments touch or cross as in
 * vortex_profile.c. */
static double orient(double ax, double ay, double bx, double by, double cx, double cy) {
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}
static int on_seg(double d, double x, double y, double x0, double y0, double x1, double y1) {
  return d == 0.0 && fmin(x0, x1) <= x && x <= fmax(x0, x1) && fmin(y0, y1) <= y &&
         y <= fmax(y0, y1);
}
static int seg_cross(const struct px_vortex_contour *c, size_t k, size_t j) {
  size_t k1 = (k + 1) % c->n, j1 = (j + 1) % c->n;
  double x1 = c->x[k], y1 = c->y[k], x2 = c->x[k1], y2 = c->y[k1];
  double x3 = c->x[j], y3 = c->y[j], x4 = c->x[j1], y4 = c->y[j1];
  if (fmax(x1, x2) < fmin(x3, x4) || fmax(x3, x4) < fmin(x1, x2) || fmax(y1, y2) < fmin(y3, y4) ||
      fmax(y3, y4) < fmin(y1, y2))
    return 0;
  double d1 = orient(x3, y3, x4, y4, x1, y1), d2 = orient(x3, y3, x4, y4, x2, y2);
  double d3 = orient(x1, y1, x2, y2, x3, y3), d4 = orient(x1, y1, x2, y2, x4, y4);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 1;
  return on_seg(d1, x1, y1, x3, y3, x4, y4) || on_seg(d2, x2, y2, x3, y3, x4, y4) ||
         on_seg(d3, x3, y3, x1, y1, x2, y2) || on_seg(d4, x4, y4, x1, y1, x2, y2);
}
static int first_crossing(const struct px_vortex_contour *c, size_t *k, size_t *j) {
  for (*k = 0; *k < c->n; ++*k)
    for (*j = *k + 2; *j < c->n; ++*j)
      if (!(*k == 0 && *j == c->n - 1) && seg_cross(c, *k, *j)) return 1;
  return 0;
}

/* Star polygons of 300 vertices at pseudo-random radii and angles (a fixed
 * linear congruential sequence), some crossing themselves where the angles
 * run backwards: the tree finds the reference's first pair, or none. */
static void test_crossings_against_reference(struct px_context *ctx) {
  uint64_t seed = 12345;
  int crossed = 0, simple = 0;
  for (int trial = 0; trial < 60; ++trial) {
    struct px_vortex_contour c = {0};
    const size_t n = 300;
    c.n = n;
    c.x = px_mem_alloc(ctx, "test", n * sizeof(double));
    c.y = px_mem_alloc(ctx, "test", n * sizeof(double));
    if (!c.x || !c.y) break;
    const double back = 0.02 * (double)(trial % 6); /* chance of an angle stepping back */
    double th = 0.0;
    for (size_t k = 0; k < n; ++k) {
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      double u = (double)(seed >> 11) / 9007199254740992.0;
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      double v = (double)(seed >> 11) / 9007199254740992.0;
      double r = 1.0 + 0.5 * u;
      c.x[k] = r * cos(th);
      c.y[k] = r * sin(th);
      th += 2.0 * PI / (double)n * (v < back ? -3.0 : 1.0 + 2.0 * back * 2.0 * v);
      if (k == n - 1 || th >= 2.0 * PI * (double)(n - 1) / (double)n) {
        c.n = k + 1;
        break;
      }
    }
    snprintf(c.source, sizeof c.source, "star %d", trial);
    size_t k = 0, j = 0;
    int ref = c.n >= 8 && first_crossing(&c, &k, &j);
    int rev = 0;
    enum px_status st = c.n >= 8 ? px_vortex_profile_check(ctx, &c, &rev) : PX_STATUS_CONFIG;
    if (c.n >= 8 && ref) {
      char want[64];
      snprintf(want, sizeof want, "self-intersecting contour: panel %zu (", k);
      PX_CHECK_MSG(st == PX_STATUS_CONFIG, "star %d: crossing %zu x %zu missed", trial, k, j);
      PX_CHECK(vx_test_message_has(ctx, want));
      snprintf(want, sizeof want, " crosses panel %zu (", j);
      PX_CHECK(vx_test_message_has(ctx, want));
      ++crossed;
    } else if (c.n >= 8 && !strstr(px_context_message(ctx), "folds back") &&
               !strstr(px_context_message(ctx), "coincide")) {
      PX_CHECK_MSG(st == PX_STATUS_OK, "star %d: %s", trial, px_context_message(ctx));
      ++simple;
    }
    px_context_clear(ctx);
    px_vortex_contour_free(ctx, &c);
  }
  printf("stars: %d crossing, %d simple\n", crossed, simple);
  PX_CHECK(crossed >= 10 && simple >= 5);
}

/* The crossing checks of large contours: a smooth 100000-panel contour
 * passes quickly (the pair loop took ~40 s), so do two such bodies side by
 * side, and a crossing among them is found; a contour whose panels all
 * overlap one another's boxes is refused when the work limit runs out. */
static void test_large_contours(struct px_context *ctx) {
  struct px_vortex_contour a, b;
  int rev = 0;
  write_circle("vx_100k.txt", 100000);
  double t0 = now_s();
  PX_CHECK_OK(ctx, px_vortex_profile_read_points(ctx, "vx_100k.txt", 0, &a));
  double t = now_s() - t0;
  PX_CHECK(a.n == 100000);
  PX_CHECK_MSG(t < 5.0, "reading and checking a 100000-panel contour took %.2f s", t);
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, 100000, &b));
  px_vortex_profile_place(&b, 1.5 + 1e-3, 0.0, 1.0, 0.0); /* 1 mm apart */
  t0 = now_s();
  PX_CHECK_OK(ctx, px_vortex_profile_check(ctx, &b, &rev));
  PX_CHECK_OK(ctx, px_vortex_profile_check_pair(ctx, &a, &b));
  px_vortex_profile_place(&b, -2e-3, 0.0, 1.0, 0.0); /* now 1 mm into a */
  PX_CHECK_STATUS(ctx, px_vortex_profile_check_pair(ctx, &a, &b), PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "overlap: panel"));
  t = now_s() - t0;
  PX_CHECK_MSG(t < 5.0, "checking two 100000-panel bodies took %.2f s", t);
  px_context_clear(ctx);
  /* a bow tie of 100000 panels: the first crossing pair is named (panel
   * 12499 ends on the crossing point, where panel 62499 ends too) */
  for (size_t k = 0; k < 4; ++k) {
    const double bx[4] = {0, 1, 1, 0}, by[4] = {0, 1, 0, 1};
    for (size_t j = 0; j < 25000; ++j) {
      double f = (double)j / 25000.0;
      a.x[25000 * k + j] = bx[k] + f * (bx[(k + 1) % 4] - bx[k]);
      a.y[25000 * k + j] = by[k] + f * (by[(k + 1) % 4] - by[k]);
    }
  }
  px_mem_free(ctx, a.line);
  a.line = NULL;
  PX_CHECK_STATUS(ctx, px_vortex_profile_check(ctx, &a, &rev), PX_STATUS_CONFIG);
  PX_CHECK(vx_test_message_has(ctx, "self-intersecting contour: panel 12499 "));
  PX_CHECK(vx_test_message_has(ctx, "crosses panel 62499 "));
  px_context_clear(ctx);
  px_vortex_contour_free(ctx, &a);
  px_vortex_contour_free(ctx, &b);

  /* a zigzag of 20000 panels 1e-5 apart closed on the left, turned by 45
   * degrees: a simple polygon whose panels' boxes all overlap, so the
   * crossing test would compare every pair (2e8 tests); it stops at its
   * limit, 1e7 + 400 n = 1.8e7 tests */
  const size_t nz = 20000;
  struct px_vortex_contour z = {0};
  z.n = nz + 2;
  z.x = px_mem_alloc(ctx, "test", z.n * sizeof(double));
  z.y = px_mem_alloc(ctx, "test", z.n * sizeof(double));
  PX_CHECK(z.x && z.y);
  if (!z.x || !z.y) return;
  for (size_t k = 0; k < nz; ++k) {
    z.x[k] = (double)(k % 2);
    z.y[k] = 1e-5 * (double)k;
  }
  z.x[nz] = -1.0;
  z.y[nz] = z.y[nz - 1];
  z.x[nz + 1] = -1.0;
  z.y[nz + 1] = 0.0;
  px_vortex_profile_place(&z, 0.0, 0.0, 1.0, 45.0);
  snprintf(z.source, sizeof z.source, "zigzag");
  t0 = now_s();
  PX_CHECK_STATUS(ctx, px_vortex_profile_check(ctx, &z, &rev), PX_STATUS_CONFIG);
  t = now_s() - t0;
  PX_CHECK(vx_test_message_has(ctx, "zigzag: the self-intersection check"));
  PX_CHECK(vx_test_message_has(ctx, "gave up after 1.8e+07 tests"));
  printf("the zigzag of %zu panels was refused in %.2f s\n", nz, t);
  px_context_clear(ctx);
  px_vortex_contour_free(ctx, &z);
}

/* A case refused by px_sim_create (check mode) with PX_STATUS_CONFIG and a
 * message holding what1 and what2; returns the seconds it took. */
static double expect_case_refused(struct px_context *ctx, const char *text, const char *what1,
                                  const char *what2) {
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  double t0 = now_s();
  enum px_status s = px_case_load_string(ctx, "big.yaml", text, strlen(text), NULL, 0, &c);
  if (s == PX_STATUS_OK) s = px_sim_create(ctx, c, PX_SIM_MODE_CHECK, &sim);
  double t = now_s() - t0;
  PX_CHECK_MSG(s == PX_STATUS_CONFIG, "accepted or wrong status %s: %s", px_status_name(s),
               px_context_message(ctx));
  PX_CHECK(vx_test_message_has(ctx, what1));
  if (what2) PX_CHECK(vx_test_message_has(ctx, what2));
  px_sim_free(sim);
  px_context_clear(ctx);
  return t;
}

/* 16 bodies of 100000 panels: a 1600016 x 1600016 panel matrix of 20 TB,
 * beyond any machine, refused at the first body's panels with the figure
 * before a body is built (the case passed the schema, and checking the
 * pairs of bodies took hours); a million panels is beyond the schema's
 * range; 16 point lists of 100000 panels each are read and checked, then
 * refused at the file key. */
static void test_sizes(struct px_context *ctx) {
  char text[8192];
  size_t pos = (size_t)snprintf(text, sizeof text,
                                "solver: vortex\ntime: {dt: 1e-5, steps: 10}\n"
                                "output: {dir: out_vx_big}\nvortex:\n  nu: 0.01\n"
                                "  v_inf: [1, 0]\n  bodies:\n");
  for (int i = 0; i < 16; ++i)
    pos += (size_t)snprintf(text + pos, sizeof text - pos,
                            "    - {type: circle, radius: 0.5, panels: 100000, position: "
                            "[%d, 0]}\n",
                            3 * i);
  double t = expect_case_refused(ctx, text, "big.yaml:8:43: vortex.bodies[0].panels",
                                 "= 100000 needs 36 TB for the 1600016 x 1600016 panel matrix");
  PX_CHECK_MSG(t < 5.0, "refusing 16 x 100000 panels took %.2f s", t);

  const char *million =
      "solver: vortex\ntime: {dt: 1e-5, steps: 10}\n"
      "output: {dir: out_vx_big}\nvortex:\n  nu: 0.01\n  v_inf: [1, 0]\n"
      "  bodies:\n    - {type: circle, radius: 0.5, panels: 1000000}\n";
  expect_case_refused(ctx, million, "big.yaml:8:43: vortex.bodies[0].panels",
                      "must be in [8, 100000]");

  write_circle("vx_100k_b.txt", 100000);
  pos = (size_t)snprintf(text, sizeof text,
                         "solver: vortex\ntime: {dt: 1e-5, steps: 10}\n"
                         "output: {dir: out_vx_big}\nvortex:\n  nu: 0.01\n"
                         "  v_inf: [1, 0]\n  bodies:\n");
  for (int i = 0; i < 16; ++i)
    pos +=
        (size_t)snprintf(text + pos, sizeof text - pos,
                         "    - {type: points, file: vx_100k_b.txt, position: [%d, 0]}\n", 3 * i);
  expect_case_refused(ctx, text, "vortex.bodies[0].file = \"vx_100k_b.txt\" needs 36 TB",
                      "panel matrix of the bodies' 1600000 panels");
  unlink("vx_100k_b.txt");
}

/* ---- forged checkpoints ------------------------------------------------- */

enum forge_op {
  SET_F64,   /* element `index` (-1: the last) of an f64 section := value */
  SET_N,     /* vortex.n := (uint64_t)value */
  SET_N_ALL, /* vortex.n := value, and every wake section resized to it */
  RESIZE,    /* the section holds (uint64_t)value elements */
  RETYPE_N,  /* vortex.n stored as one f64 of value */
  DROP       /* the section is missing */
};

struct forge {
  const char *section;
  enum forge_op op;
  long index;
  double value;
  const char *expect; /* in the message, after the file's name */
};

/* Forge, write vx_forged.pxc, open it as `partix verify` does (check mode):
 * refused with PX_STATUS_FORMAT, naming the file and `expect`. */
static void expect_forgery_refused(struct px_context *ctx, const struct px_test_ck *orig,
                                   const struct forge *fg) {
  struct px_test_ck f;
  px_test_ck_copy(orig, &f);
  struct px_test_ck_sec *s = px_test_ck_find(&f, fg->section);
  struct px_test_ck_sec *ns = px_test_ck_find(&f, "vortex.n");
  PX_CHECK(s != NULL && ns != NULL);
  if (!s || !ns) {
    px_test_ck_free(&f);
    return;
  }
  /* the count the forgery writes (the ops that use it give one in range of uint64) */
  uint64_t u = fg->value >= 0 && fg->value < 18446744073709551616.0 ? (uint64_t)fg->value : 0;
  switch (fg->op) {
    case SET_F64: {
      size_t at = fg->index < 0 ? (size_t)s->count - 1 : (size_t)fg->index;
      if (at < s->count) memcpy(s->data + 8 * at, &fg->value, 8);
      break;
    }
    case SET_N: memcpy(ns->data, &u, 8); break;
    case SET_N_ALL: {
      static const char *const wake[5] = {"vortex.x", "vortex.y", "vortex.gamma",
                                          "vortex.velocity_u", "vortex.velocity_v"};
      memcpy(ns->data, &u, 8);
      for (int q = 0; q < 5; ++q) px_test_ck_resize(px_test_ck_find(&f, wake[q]), u);
      break;
    }
    case RESIZE: px_test_ck_resize(s, u); break;
    case RETYPE_N:
      ns->type = PX_DTYPE_F64;
      memcpy(ns->data, &fg->value, 8);
      break;
    case DROP: px_test_ck_drop(&f, fg->section); break;
  }
  PX_CHECK_OK(ctx, px_test_ck_write(ctx, &f, "vx_forged.pxc"));
  px_test_ck_free(&f);
  enum px_status st = px_test_ck_verify(ctx, "vx_forged.pxc");
  PX_CHECK_MSG(st == PX_STATUS_FORMAT, "%s (op %d, value %g): %s: %s", fg->section, (int)fg->op,
               fg->value, px_status_name(st), px_context_message(ctx));
  PX_CHECK(vx_test_message_has(ctx, "vx_forged.pxc"));
  PX_CHECK(vx_test_message_has(ctx, fg->expect));
  px_context_clear(ctx);
}

static void test_checkpoints(struct px_context *ctx) {
  const char *text =
      "solver: vortex\n"
      "backend: {type: cpu, threads: 2, precision: double}\n"
      "time: {dt: 0.02, steps: 10}\n"
      "output: {dir: out_vx_hostile, every: 1000, png: false, vtk: false, "
      "csv: false}\n"
      "vortex:\n  nu: 0.005\n  v_inf: [1.0, 0.0]\n  bodies:\n"
      "    - {type: circle, radius: 0.5, panels: 64}\n";
  struct px_sim *sim = vx_test_sim(ctx, "hostile.yaml", text);
  PX_CHECK(sim != NULL);
  if (!sim) return;
  PX_CHECK_OK(ctx, px_sim_run(sim));
  px_sim_free(sim);
  struct px_test_ck orig;
  PX_CHECK(px_test_ck_load(ctx, "out_vx_hostile/checkpoint.pxc", &orig));
  struct px_test_ck_sec *ns = px_test_ck_find(&orig, "vortex.n");
  PX_CHECK(ns != NULL && orig.step == 10);
  if (!ns) {
    px_test_ck_free(&orig);
    return;
  }
  uint64_t n = 0;
  memcpy(&n, ns->data, 8);
  PX_CHECK(n > 100);
  /* the real file, written again, opens, resumes and steps */
  PX_CHECK_OK(ctx, px_test_ck_write(ctx, &orig, "vx_forged.pxc"));
  PX_CHECK_OK(ctx, px_test_ck_verify(ctx, "vx_forged.pxc"));
  /* 10 steps of 64 panels: at most 10 x 64 x 64 = 40960 vortices */
  const struct forge fg[] = {
      {"vortex.n", SET_N, 0, 4611686018427387904.0, "section 'vortex.n': 4611686018427387904"},
      {"vortex.n", SET_N_ALL, 0, 40961.0, "section 'vortex.n': 40961 vortices, more than"},
      {"vortex.n", SET_N, 0, (double)(n + 1), "section 'vortex.x' holds"},
      {"vortex.n", RETYPE_N, 0, 1e30, "section 'vortex.n' holds 1 values of type f64"},
      {"vortex.n", DROP, 0, 0.0, "section 'vortex.n' is missing"},
      {"vortex.gamma", DROP, 0, 0.0, "section 'vortex.gamma' is missing"},
      {"vortex.y", RESIZE, 0, (double)(n - 1), "section 'vortex.y' holds"},
      {"vortex.absorbed", RESIZE, 0, 63.0, "section 'vortex.absorbed' holds 63 values"},
      {"vortex.x", SET_F64, 3, NAN, "section 'vortex.x': value 3 is nan"},
      {"vortex.y", SET_F64, -1, INFINITY, "section 'vortex.y': value"},
      {"vortex.x", SET_F64, 1, 1e30, "sections 'vortex.x', 'vortex.y': vortex 1 at (1e+30"},
      {"vortex.y", SET_F64, 0, -41.0, "beyond vortex.dist_far = 20 m"},
      {"vortex.gamma", SET_F64, 2, NAN, "section 'vortex.gamma': value 2 is nan"},
      {"vortex.gamma", SET_F64, 0, 1e30, "section 'vortex.gamma': value 0 is 1e+30, not a"},
      {"vortex.gamma", SET_F64, -1, -1e30, "section 'vortex.gamma': value"},
      {"vortex.velocity_u", SET_F64, 0, NAN, "section 'vortex.velocity_u': value 0 is nan"},
      {"vortex.velocity_v", SET_F64, -1, -INFINITY, "section 'vortex.velocity_v': value"},
      {"vortex.absorbed", SET_F64, 5, NAN, "section 'vortex.absorbed': panel 5 absorbed nan"},
      {"vortex.absorbed", SET_F64, 0, 1e30, "section 'vortex.absorbed': panel 0 absorbed 1e+30"},
      {"vortex.absorbed", SET_F64, -1, -1e30, "section 'vortex.absorbed': panel 63"},
  };
  for (size_t k = 0; k < sizeof fg / sizeof fg[0]; ++k) expect_forgery_refused(ctx, &orig, &fg[k]);
  /* the unchanged copy still resumes and takes a step */
  PX_CHECK_OK(ctx, px_test_ck_write(ctx, &orig, "out_vx_hostile/checkpoint.pxc"));
  const char *more[] = {"time.steps=11"};
  sim = NULL;
  PX_CHECK_OK(ctx, px_sim_resume(ctx, "out_vx_hostile/checkpoint.pxc", more, 1, &sim));
  if (sim) {
    px_sim_set_progress(sim, NULL, 0);
    PX_CHECK_OK(ctx, px_sim_step(sim));
    PX_CHECK(px_sim_step_index(sim) == 11);
  }
  px_sim_free(sim);
  px_test_ck_free(&orig);
}

/* With an argument (files, crossings, contours, sizes, checkpoints) only
 * that part runs. */
int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  const char *only = argc > 1 ? argv[1] : NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  if (!only || strcmp(only, "files") == 0) test_profile_files(ctx);
  if (!only || strcmp(only, "crossings") == 0) test_crossings_against_reference(ctx);
  if (!only || strcmp(only, "contours") == 0) test_large_contours(ctx);
  if (!only || strcmp(only, "sizes") == 0) test_sizes(ctx);
  if (!only || strcmp(only, "checkpoints") == 0) test_checkpoints(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_vortex_hostile");
}
