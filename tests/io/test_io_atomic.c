/* A full disk never tears an output file. RLIMIT_FSIZE (with SIGXFSZ
 * ignored, so write() fails with EFBIG instead of killing us) simulates a
 * disk that fills up during a write: every writer must then return
 * PX_STATUS_IO with a message naming the file, leave the previous file
 * byte-for-byte intact and leave no temporary file behind; a CSV series keeps
 * whole rows only. */
#include <signal.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "io/ioutil.h"
#include "partix/csv.h"
#include "partix/figure.h"
#include "partix/vtk.h"
#include "px_test.h"
#include "px_test_fonts.h"

#define LIMIT (256 * 1024) /* bytes a file may have while the "disk is full" */
#define NP 40000           /* particles: a .vtp of about 1 MB */

static struct rlimit saved;

static void disk_full(int on) {
  struct rlimit r = saved;
  if (on) r.rlim_cur = LIMIT;
  PX_CHECK(setrlimit(RLIMIT_FSIZE, &r) == 0);
}

static char *slurp(struct px_context *ctx, const char *path, size_t *len) {
  char *text = NULL;
  if (px_ioutil_read_file(ctx, path, &text, len) != PX_STATUS_OK) return NULL;
  return text;
}

static int no_temporary(const char *path) {
  char tmp[512];
  snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)getpid());
  return !px_file_exists(tmp);
}

/* The failed write left `path` as it was, said why, and cleaned up. */
static void check_intact(struct px_context *ctx, const char *path, const char *before,
                         size_t before_len) {
  size_t len = 0;
  char *after;
  PX_CHECK_MSG(strstr(px_context_message(ctx), path) != NULL, "message \"%s\" names %s",
               px_context_message(ctx), path);
  PX_CHECK_MSG(strstr(px_context_message(ctx), "too large") != NULL ||
                   strstr(px_context_message(ctx), "No space") != NULL,
               "message \"%s\" gives the reason", px_context_message(ctx));
  after = slurp(ctx, path, &len);
  PX_CHECK_MSG(after && len == before_len && memcmp(after, before, len) == 0,
               "%s changed by a failed write", path);
  PX_CHECK(no_temporary(path));
  px_mem_free(ctx, after);
}

static void test_vtk(struct px_context *ctx, double *x, double *y, double *g) {
  struct px_vtk *v = NULL;
  char *before;
  size_t len;
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  /* the old file: small */
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 100, x, y, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_vertices(v));
  PX_CHECK_OK(ctx, px_vtk_write(v, "atomic.vtp"));
  before = slurp(ctx, "atomic.vtp", &len);
  PX_CHECK(before && len < LIMIT);
  /* the new one does not fit */
  px_vtk_reset(v);
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, NP, x, y, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_vertices(v));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "Gamma", PX_DTYPE_F64, NP, g));
  disk_full(1);
  PX_CHECK_STATUS(ctx, px_vtk_write(v, "atomic.vtp"), PX_STATUS_IO);
  disk_full(0);
  if (before) check_intact(ctx, "atomic.vtp", before, len);
  px_mem_free(ctx, before);
  /* and it does once there is room again */
  PX_CHECK_OK(ctx, px_vtk_write(v, "atomic.vtp"));
  PX_CHECK(no_temporary("atomic.vtp"));
  px_vtk_free(v);
}

static void test_pvd(struct px_context *ctx) {
  struct px_vtk_series *s = NULL;
  char name[2100], *before = NULL;
  size_t len = 0, n = 0;
  enum px_status st = PX_STATUS_OK;
  memset(name, 'a', 2000); /* about 2 kB per entry */
  name[2000] = '\0';
  PX_CHECK_OK(ctx, px_vtk_series_open(ctx, "atomic.pvd", &s));
  disk_full(1);
  while (st == PX_STATUS_OK && n < 10000) {
    px_mem_free(ctx, before);
    before = slurp(ctx, "atomic.pvd", &len);
    st = px_vtk_series_add(s, (double)n, name);
    ++n;
  }
  disk_full(0);
  PX_CHECK(st == PX_STATUS_IO);
  PX_CHECK(n > 50);                          /* it did grow to the limit first */
  PX_CHECK(px_vtk_series_count(s) == n - 1); /* the failed entry is not kept */
  if (before) check_intact(ctx, "atomic.pvd", before, len);
  px_mem_free(ctx, before);
  px_vtk_series_close(s);
}

static void test_png(struct px_context *ctx) {
  struct px_figure *fig = NULL;
  static float noise[512 * 512];
  uint64_t rng[PX_RNG_WORDS];
  char *before;
  size_t len, i;
  PX_CHECK_OK(ctx, px_figure_create(ctx, 200, 150, &fig));
  PX_CHECK_OK(ctx, px_figure_write_png(fig, "atomic.png"));
  before = slurp(ctx, "atomic.png", &len);
  px_figure_free(fig);
  /* random noise does not compress: a PNG of about 1.5 MB */
  px_rng_seed(rng, 3);
  for (i = 0; i < 512 * 512; ++i) noise[i] = (float)px_rng_uniform(rng);
  PX_CHECK_OK(ctx, px_figure_create(ctx, 900, 800, &fig));
  PX_CHECK_OK(ctx, px_figure_add_raster(fig, PX_DTYPE_F32, 512, 512, noise, 0, 1, 0, 1));
  disk_full(1);
  PX_CHECK_STATUS(ctx, px_figure_write_png(fig, "atomic.png"), PX_STATUS_IO);
  disk_full(0);
  if (before) check_intact(ctx, "atomic.png", before, len);
  px_mem_free(ctx, before);
  px_figure_free(fig);
}

static void test_csv(struct px_context *ctx, double *x, double *y) {
  static const char *const names[2] = {"t [s]", "E [J]"};
  const double *cols[2];
  struct px_csv *csv = NULL;
  char *before, *text;
  size_t len, rows = 0, lines = 0, k;
  enum px_status st = PX_STATUS_OK;
  /* one-shot table */
  cols[0] = x, cols[1] = y;
  PX_CHECK_OK(ctx, px_csv_write_table(ctx, "atomic_table.csv", 2, names, 10, cols, 17));
  before = slurp(ctx, "atomic_table.csv", &len);
  disk_full(1);
  PX_CHECK_STATUS(ctx, px_csv_write_table(ctx, "atomic_table.csv", 2, names, NP, cols, 17),
                  PX_STATUS_IO);
  disk_full(0);
  if (before) check_intact(ctx, "atomic_table.csv", before, len);
  px_mem_free(ctx, before);

  /* a time series that hits the full disk: whole rows only, then resumes */
  PX_CHECK_OK(ctx, px_csv_open(ctx, "atomic_series.csv", 2, names, &csv));
  PX_CHECK_OK(ctx, px_csv_set_precision(csv, 17));
  disk_full(1);
  while (st == PX_STATUS_OK && rows < (size_t)NP) {
    double row[2];
    row[0] = x[rows];
    row[1] = y[rows];
    st = px_csv_row(csv, row);
    if (st == PX_STATUS_OK) ++rows;
  }
  disk_full(0);
  PX_CHECK(st == PX_STATUS_IO);
  PX_CHECK(strstr(px_context_message(ctx), "atomic_series.csv") != NULL);
  PX_CHECK(px_csv_rows(csv) == rows);
  PX_CHECK_OK(ctx, px_csv_close(csv));
  text = slurp(ctx, "atomic_series.csv", &len);
  PX_CHECK(text && len > 0 && text[len - 1] == '\n'); /* no torn row */
  for (k = 0; text && k < len; ++k) lines += text[k] == '\n';
  PX_CHECK_MSG(lines == rows + 1, "%zu lines for %zu rows", lines, rows);
  px_mem_free(ctx, text);
  PX_CHECK_OK(ctx, px_csv_open_resume(ctx, "atomic_series.csv", 2, names, 1e300, &csv));
  PX_CHECK(px_csv_rows(csv) == rows);
  PX_CHECK_OK(ctx, px_csv_close(csv));
}

int main(void) {
  struct px_context *ctx = NULL;
  double *x = malloc(NP * sizeof *x), *y = malloc(NP * sizeof *y), *g = malloc(NP * sizeof *g);
  size_t i;
  signal(SIGXFSZ, SIG_IGN);
  PX_CHECK(getrlimit(RLIMIT_FSIZE, &saved) == 0);
  if (saved.rlim_max != RLIM_INFINITY && saved.rlim_max < LIMIT) {
    fprintf(stderr, "RLIMIT_FSIZE hard limit %lu is below the test's %d bytes\n",
            (unsigned long)saved.rlim_max, LIMIT);
    return EXIT_FAILURE;
  }
  for (i = 0; i < NP; ++i) {
    x[i] = 0.001 * (double)i;
    y[i] = 1.0 / (1.0 + (double)i);
    g[i] = (double)i;
  }
  px_context_create(&ctx);
  test_vtk(ctx, x, y, g);
  test_pvd(ctx);
  test_png(ctx);
  test_csv(ctx, x, y);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  free(x), free(y), free(g);
  px_test_release_fonts();
  return px_test_report("test_io_atomic");
}
