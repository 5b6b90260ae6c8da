/* Writes the VTK files that tests/io/read_vtk.py reads back with VTK's own
 * XML readers (test io_vtk_read_by_vtk): every value below is a formula the
 * Python script evaluates too, mostly dyadic rationals so that float and
 * double files compare exactly. Also checks the builder's own errors.
 * Usage: test_io_vtk_write OUTDIR */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "partix/vtk.h"
#include "px_test.h"

#define NPART 1000
#define NBIG 100003 /* not a multiple of the writer's chunk size */
#define NBODY 40

static char outdir[2048];

static const char *out(const char *name) {
  static char buf[4096];
  snprintf(buf, sizeof buf, "%s/%s", outdir, name);
  return buf;
}

/* Particle i (same formulas in read_vtk.py). */
static double px_x(size_t i) { return 0.25 * (double)i - 3.0; }
static double px_y(size_t i) { return 0.125 * (double)(i % 17) - 1.0; }
static double px_gamma(size_t i) { return ((double)(i % 11) - 5.0) * 0.0625; }

static void write_particles(struct px_context *ctx, enum px_dtype dt, const char *name) {
  struct px_vtk *v = NULL;
  size_t i;
  int is32 = dt == PX_DTYPE_F32;
  size_t es = is32 ? 4 : 8;
  unsigned char *x = malloc(NPART * es), *y = malloc(NPART * es), *g = malloc(NPART * es);
  unsigned char *u = malloc(NPART * es), *w = malloc(NPART * es), *f = malloc(3 * NPART * es);
  unsigned char *third = malloc(NPART * es), *fxy = malloc(2 * NPART * es);
  int32_t *id = malloc(NPART * sizeof *id);
  for (i = 0; i < NPART; ++i) {
    double vals[6] = {px_x(i),         px_y(i),           px_gamma(i),
                      0.5 * (double)i, -0.25 * (double)i, (double)i / 3.0};
    unsigned char *dst[6] = {x, y, g, u, w, third};
    int k;
    for (k = 0; k < 6; ++k) {
      if (is32) {
        float fv = (float)vals[k];
        memcpy(dst[k] + i * 4, &fv, 4);
      } else {
        memcpy(dst[k] + i * 8, &vals[k], 8);
      }
    }
    for (k = 0; k < 3; ++k) {
      double fv = 0.5 * (double)(k + 1) * (double)i;
      if (is32) {
        float ff = (float)fv;
        memcpy(f + (3 * i + (size_t)k) * 4, &ff, 4);
        if (k < 2) memcpy(fxy + (2 * i + (size_t)k) * 4, &ff, 4);
      } else {
        memcpy(f + (3 * i + (size_t)k) * 8, &fv, 8);
        if (k < 2) memcpy(fxy + (2 * i + (size_t)k) * 8, &fv, 8);
      }
    }
    id[i] = (int32_t)i;
  }
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_points(v, dt, NPART, x, y, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_vertices(v));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "Gamma", dt, NPART, g));
  {
    const void *comps[2];
    comps[0] = u;
    comps[1] = w;
    PX_CHECK_OK(ctx, px_vtk_add_array(v, PX_VTK_ASSOC_POINT, "velocity", dt, NPART, 2, comps));
  }
  PX_CHECK_OK(ctx, px_vtk_add_array_aos(v, PX_VTK_ASSOC_POINT, "force", dt, NPART, 3, f));
  /* 2 interleaved components are written as a 3-vector with z = 0 */
  PX_CHECK_OK(ctx, px_vtk_add_array_aos(v, PX_VTK_ASSOC_POINT, "force_xy", dt, NPART, 2, fxy));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "id", PX_DTYPE_I32, NPART, id));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "third", dt, NPART, third));
  px_vtk_set_time(v, 0.5, 10);
  PX_CHECK_OK(ctx, px_vtk_add_field(v, "Cx", 0.123456789012345));
  PX_CHECK_OK(ctx, px_vtk_write(v, out(name)));
  px_vtk_free(v);
  free(x), free(y), free(g), free(u), free(w), free(f), free(third), free(fxy), free(id);
}

/* Points given interleaved (x, y pairs). */
static void write_points_aos(struct px_context *ctx) {
  struct px_vtk *v = NULL;
  double xy[2 * NPART];
  size_t i;
  for (i = 0; i < NPART; ++i) xy[2 * i] = px_x(i), xy[2 * i + 1] = px_y(i);
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_points_aos(v, PX_DTYPE_F64, NPART, 2, xy));
  PX_CHECK_OK(ctx, px_vtk_add_vertices(v));
  PX_CHECK_OK(ctx, px_vtk_write(v, out("points_aos.vtp")));
  px_vtk_free(v);
}

static void write_big(struct px_context *ctx) {
  struct px_vtk *v = NULL;
  double *x = malloc(NBIG * sizeof *x), *y = malloc(NBIG * sizeof *y);
  double *z = malloc(NBIG * sizeof *z);
  float *g = malloc(NBIG * sizeof *g), *u = malloc(NBIG * sizeof *u);
  float *w = malloc(NBIG * sizeof *w);
  size_t i;
  for (i = 0; i < NBIG; ++i) {
    x[i] = 0.5 * (double)i;
    y[i] = -0.25 * (double)i;
    z[i] = (double)(i % 1000);
    g[i] = (float)(i % 4096) * 0.25f;
    u[i] = (float)(i % 8192);
    w[i] = -(float)(i % 8192);
  }
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, NBIG, x, y, z));
  PX_CHECK_OK(ctx, px_vtk_add_vertices(v));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "Gamma", PX_DTYPE_F32, NBIG, g));
  PX_CHECK_OK(ctx,
              px_vtk_add_vector(v, PX_VTK_ASSOC_POINT, "velocity", PX_DTYPE_F32, NBIG, u, w, NULL));
  PX_CHECK_OK(ctx, px_vtk_write(v, out("particles_big.vtp")));
  px_vtk_free(v);
  free(x), free(y), free(z), free(g), free(u), free(w);
}

/* A closed circular body (NBODY points) plus an open 5-point line. */
static void write_body(struct px_context *ctx) {
  struct px_vtk *v = NULL;
  double x[NBODY + 5], y[NBODY + 5], pressure[2] = {1.5, -2.5}, energy[NBODY];
  int64_t wake[5] = {NBODY + 4, NBODY + 3, NBODY + 2, NBODY + 1, NBODY};
  size_t i;
  for (i = 0; i < NBODY; ++i) {
    double a = 2.0 * 3.14159265358979323846 * (double)i / NBODY;
    x[i] = 0.5 * cos(a);
    y[i] = 0.5 * sin(a);
    energy[i] = 0.5 * (double)i;
  }
  for (i = 0; i < 5; ++i) {
    x[NBODY + i] = 1.0 + 0.5 * (double)i;
    y[NBODY + i] = 0.0;
  }
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, NBODY + 5, x, y, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_polyline_range(v, 0, NBODY, 1));
  PX_CHECK_OK(ctx, px_vtk_add_polyline(v, 5, wake, 0));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_CELL, "pressure", PX_DTYPE_F64, 2, pressure));
  PX_CHECK_OK(ctx, px_vtk_write(v, out("body.vtp")));

  /* The same contour as one line cell per segment with a value per segment. */
  px_vtk_reset(v);
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, NBODY, x, y, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_segments(v, 0, NBODY, 1));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_CELL, "energy", PX_DTYPE_F64, NBODY, energy));
  PX_CHECK_OK(ctx, px_vtk_write(v, out("contour_segments.vtp")));

  /* A surface: the unit tetrahedron's 4 triangles (Polys) after one line
   * (cells: the line, then the triangles), a value per point and per cell. */
  px_vtk_reset(v);
  const double tx[4] = {0, 1, 0, 0}, ty[4] = {0, 0, 1, 0}, tz[4] = {0, 0, 0, 1};
  const double height[4] = {0, 0, 0, 1}, face[5] = {-1, 0, 1, 2, 3};
  const int64_t tri[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3}, edge[2] = {0, 3};
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 4, tx, ty, tz));
  PX_CHECK_OK(ctx, px_vtk_add_polyline(v, 2, edge, 0));
  PX_CHECK_OK(ctx, px_vtk_set_cells_uniform(v, 4, PX_VTK_CELL_TRIANGLE, 3, tri));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "height", PX_DTYPE_F64, 4, height));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_CELL, "face", PX_DTYPE_F64, 5, face));
  PX_CHECK_OK(ctx, px_vtk_write(v, out("surface.vtp")));
  /* hexahedra are no .vtp cells */
  px_vtk_reset(v);
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 4, tx, ty, tz));
  PX_CHECK_OK(ctx, px_vtk_set_cells_uniform(v, 1, PX_VTK_CELL_TETRA, 4, tri));
  PX_CHECK_STATUS(ctx, px_vtk_write(v, out("bad_surface.vtp")), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "other cells go into a .vtu") != NULL);
  px_vtk_free(v);
}

static void write_image(struct px_context *ctx, enum px_dtype dt, const char *name) {
  struct px_vtk *v = NULL;
  size_t dims[3] = {5, 4, 3};
  double origin[3] = {-1.0, 0.5, 2.0}, spacing[3] = {0.5, 0.25, 1.0};
  double phi[60], ui[60], uj[60], rho[24];
  float phif[60], uif[60], ujf[60], rhof[24];
  size_t i, j, k;
  int is32 = dt == PX_DTYPE_F32;
  for (k = 0; k < 3; ++k)
    for (j = 0; j < 4; ++j)
      for (i = 0; i < 5; ++i) {
        size_t p = i + 5 * j + 20 * k;
        phi[p] = (double)i + 10.0 * (double)j + 100.0 * (double)k;
        ui[p] = (double)i;
        uj[p] = (double)j;
        phif[p] = (float)phi[p], uif[p] = (float)ui[p], ujf[p] = (float)uj[p];
      }
  for (k = 0; k < 2; ++k)
    for (j = 0; j < 3; ++j)
      for (i = 0; i < 4; ++i) {
        size_t c = i + 4 * j + 12 * k;
        rho[c] = (double)i + 10.0 * (double)j + 100.0 * (double)k;
        rhof[c] = (float)rho[c];
      }
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_image(v, dims, origin, spacing));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "phi", dt, 60,
                                     is32 ? (const void *)phif : (const void *)phi));
  PX_CHECK_OK(ctx, px_vtk_add_vector(v, PX_VTK_ASSOC_POINT, "u", dt, 60,
                                     is32 ? (const void *)uif : (const void *)ui,
                                     is32 ? (const void *)ujf : (const void *)uj, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_CELL, "rho", dt, 24,
                                     is32 ? (const void *)rhof : (const void *)rho));
  px_vtk_set_time(v, 2.25, 9);
  PX_CHECK_OK(ctx, px_vtk_write(v, out(name)));
  px_vtk_free(v);
}

/* 2D image with cell data only (a lattice slice). */
static void write_image_2d(struct px_context *ctx) {
  struct px_vtk *v = NULL;
  size_t dims[3] = {6, 3, 1};
  double origin[3] = {0.0, 0.0, 0.0}, spacing[3] = {0.125, 0.125, 1.0};
  uint8_t solid[10];
  size_t c;
  for (c = 0; c < 10; ++c) solid[c] = (uint8_t)(c % 3 == 0);
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_image(v, dims, origin, spacing));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_CELL, "solid", PX_DTYPE_U8, 10, solid));
  PX_CHECK_OK(ctx, px_vtk_write(v, out("field2d.vti")));
  px_vtk_free(v);
}

/* 2 x 2 x 1 hexahedra on the integer grid 3 x 3 x 2. */
static void write_hex(struct px_context *ctx, enum px_dtype dt, const char *name) {
  struct px_vtk *v = NULL;
  double xd[18], yd[18], zd[18], T[18];
  float xf[18], yf[18], zf[18];
  int64_t conn[32];
  int32_t material[4] = {1, 2, 3, 4};
  double energy[4] = {0.5, 1.5, 2.5, 3.5};
  size_t i, j, k, c = 0;
  int is32 = dt == PX_DTYPE_F32;
  for (k = 0; k < 2; ++k)
    for (j = 0; j < 3; ++j)
      for (i = 0; i < 3; ++i) {
        size_t p = i + 3 * j + 9 * k;
        xd[p] = (double)i, yd[p] = (double)j, zd[p] = (double)k;
        xf[p] = (float)i, yf[p] = (float)j, zf[p] = (float)k;
        T[p] = xd[p] + yd[p] + zd[p];
      }
  for (j = 0; j < 2; ++j)
    for (i = 0; i < 2; ++i) {
      int64_t p0 = (int64_t)(i + 3 * j);
      /* VTK_HEXAHEDRON order: bottom face counter-clockwise, then top face. */
      int64_t ids[8] = {p0, p0 + 1, p0 + 4, p0 + 3, p0 + 9, p0 + 10, p0 + 13, p0 + 12};
      memcpy(conn + 8 * c, ids, sizeof ids);
      ++c;
    }
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  if (is32)
    PX_CHECK_OK(ctx, px_vtk_set_points(v, dt, 18, xf, yf, zf));
  else
    PX_CHECK_OK(ctx, px_vtk_set_points(v, dt, 18, xd, yd, zd));
  PX_CHECK_OK(ctx, px_vtk_set_cells_uniform(v, 4, PX_VTK_CELL_HEXAHEDRON, 8, conn));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_CELL, "material", PX_DTYPE_I32, 4, material));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_CELL, "energy", PX_DTYPE_F64, 4, energy));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "T", PX_DTYPE_F64, 18, T));
  PX_CHECK_OK(ctx, px_vtk_write(v, out(name)));

  /* Mixed explicit cells: a hexahedron, a quad, a line and a vertex. */
  {
    int64_t mconn[8 + 4 + 2 + 1] = {0, 1, 4, 3, 9, 10, 13, 12, 9, 10, 13, 12, 2, 5, 8};
    int64_t offsets[4] = {8, 12, 14, 15};
    uint8_t types[4] = {PX_VTK_CELL_HEXAHEDRON, PX_VTK_CELL_QUAD, PX_VTK_CELL_LINE,
                        PX_VTK_CELL_VERTEX};
    px_vtk_reset(v);
    PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 18, xd, yd, zd));
    PX_CHECK_OK(ctx, px_vtk_set_cells(v, 4, offsets, mconn, types));
    PX_CHECK_OK(ctx, px_vtk_write(v, out("mixed.vtu")));
  }
  px_vtk_free(v);
}

static void write_step(struct px_context *ctx, double t, long step, const char *name) {
  struct px_vtk *v = NULL;
  double x[3] = {0.0, 1.0, 2.0}, y[3] = {0.0, 0.0, 0.0};
  double tt[3];
  int i;
  for (i = 0; i < 3; ++i) tt[i] = t;
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 3, x, y, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_vertices(v));
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "t", PX_DTYPE_F64, 3, tt));
  px_vtk_set_time(v, t, step);
  PX_CHECK_OK(ctx, px_vtk_write(v, out(name)));
  px_vtk_free(v);
}

static void write_series(struct px_context *ctx) {
  struct px_vtk_series *s = NULL;
  write_step(ctx, 0.0, 0, "s_0.vtp");
  write_step(ctx, 0.5, 5, "s_1.vtp");
  write_step(ctx, 1.0, 10, "s_2.vtp");
  write_step(ctx, 0.75, 7, "s_3.vtp");
  PX_CHECK_OK(ctx, px_vtk_series_open(ctx, out("series.pvd"), &s));
  PX_CHECK(px_file_exists(out("series.pvd"))); /* valid (empty) from the start */
  PX_CHECK_OK(ctx, px_vtk_series_add(s, 0.0, "s_0.vtp"));
  PX_CHECK_OK(ctx, px_vtk_series_add(s, 0.5, "s_1.vtp"));
  PX_CHECK_OK(ctx, px_vtk_series_add(s, 1.0, "s_2.vtp"));
  PX_CHECK(px_vtk_series_count(s) == 3);
  px_vtk_series_close(s);
  /* A run resumed from t = 0.5: the entry at t = 1 is dropped, 0.75 added. */
  PX_CHECK_OK(ctx, px_vtk_series_open_resume(ctx, out("series.pvd"), 0.5, &s));
  PX_CHECK(px_vtk_series_count(s) == 2);
  PX_CHECK(px_vtk_series_time(s, 1) == 0.5);
  PX_CHECK(px_vtk_series_file(s, 1) && strcmp(px_vtk_series_file(s, 1), "s_1.vtp") == 0);
  PX_CHECK_OK(ctx, px_vtk_series_add(s, 0.75, "s_3.vtp"));
  PX_CHECK(px_vtk_series_count(s) == 3);
  px_vtk_series_close(s);

  /* Times survive the text round trip exactly; parts and odd names too. */
  PX_CHECK_OK(ctx, px_vtk_series_open(ctx, out("parts.pvd"), &s));
  PX_CHECK_OK(ctx, px_vtk_series_add_part(s, 0.1, 0, "a&b <1>.vtp"));
  PX_CHECK_OK(ctx, px_vtk_series_add_part(s, 0.1, 1, "body \"1\".vtp"));
  px_vtk_series_close(s);
  PX_CHECK_OK(ctx, px_vtk_series_open_resume(ctx, out("parts.pvd"), 1.0, &s));
  PX_CHECK(px_vtk_series_count(s) == 2);
  PX_CHECK(px_vtk_series_time(s, 0) == 0.1);
  PX_CHECK(px_vtk_series_file(s, 0) && strcmp(px_vtk_series_file(s, 0), "a&b <1>.vtp") == 0);
  PX_CHECK(px_vtk_series_file(s, 1) && strcmp(px_vtk_series_file(s, 1), "body \"1\".vtp") == 0);
  px_vtk_series_close(s);

  /* Resuming without a .pvd starts an empty one; a non-.pvd file is an error. */
  PX_CHECK_OK(ctx, px_vtk_series_open_resume(ctx, out("fresh.pvd"), 1.0, &s));
  PX_CHECK(px_vtk_series_count(s) == 0);
  px_vtk_series_close(s);
  PX_CHECK_OK(ctx, px_file_write_all(ctx, out("junk.pvd"), "hello\n", 6));
  s = NULL;
  PX_CHECK_STATUS(ctx, px_vtk_series_open_resume(ctx, out("junk.pvd"), 1.0, &s), PX_STATUS_FORMAT);
  PX_CHECK(s == NULL);
  PX_CHECK(strstr(px_context_message(ctx), "junk.pvd") != NULL);
}

static void test_builder_errors(struct px_context *ctx) {
  struct px_vtk *v = NULL;
  double x[4] = {0, 1, 2, 3}, y[4] = {0, 0, 0, 0}, g[3] = {1, 2, 3};
  int64_t bad[2] = {0, 7};
  size_t dims[3] = {2, 2, 1};
  double origin[3] = {0, 0, 0}, spacing[3] = {1, 1, 1};
  PX_CHECK_OK(ctx, px_vtk_create(ctx, &v));
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 4, x, y, NULL));
  PX_CHECK_STATUS(ctx, px_vtk_write(v, out("x.vtk")), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), ".vtp, .vti or .vtu") != NULL);
  /* A data array with the wrong length names the array and both counts. */
  PX_CHECK_OK(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "Gamma", PX_DTYPE_F64, 3, g));
  PX_CHECK_STATUS(ctx, px_vtk_write(v, out("bad.vtp")), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "'Gamma' has 3 tuples") != NULL);
  PX_CHECK(strstr(px_context_message(ctx), "4 points") != NULL);
  PX_CHECK(!px_file_exists(out("bad.vtp")));
  PX_CHECK_STATUS(ctx, px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, "Gamma", PX_DTYPE_F64, 4, g),
                  PX_STATUS_INVALID);
  px_vtk_reset(v);
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 4, x, y, NULL));
  PX_CHECK_OK(ctx, px_vtk_add_polyline(v, 2, bad, 0));
  PX_CHECK_STATUS(ctx, px_vtk_write(v, out("bad.vtp")), PX_STATUS_INVALID);
  PX_CHECK(strstr(px_context_message(ctx), "point id 7") != NULL);
  /* A .vti has no explicit points. */
  px_vtk_reset(v);
  PX_CHECK_OK(ctx, px_vtk_set_image(v, dims, origin, spacing));
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 4, x, y, NULL));
  PX_CHECK_STATUS(ctx, px_vtk_write(v, out("bad.vti")), PX_STATUS_INVALID);
  /* A .vtu needs cells. */
  px_vtk_reset(v);
  PX_CHECK_OK(ctx, px_vtk_set_points(v, PX_DTYPE_F64, 4, x, y, NULL));
  PX_CHECK_STATUS(ctx, px_vtk_write(v, out("bad.vtu")), PX_STATUS_INVALID);
  PX_CHECK_STATUS(ctx, px_vtk_set_points(v, PX_DTYPE_I32, 4, x, y, NULL), PX_STATUS_INVALID);
  px_vtk_free(v);
}

int main(int argc, char **argv) {
  struct px_context *ctx = NULL;
  snprintf(outdir, sizeof outdir, "%s", argc > 1 ? argv[1] : "vtk_out");
  px_context_create(&ctx);
  PX_CHECK_OK(ctx, px_file_mkdirs(ctx, outdir));
  write_particles(ctx, PX_DTYPE_F32, "particles_f32.vtp");
  write_particles(ctx, PX_DTYPE_F64, "particles_f64.vtp");
  write_points_aos(ctx);
  write_big(ctx);
  write_body(ctx);
  write_image(ctx, PX_DTYPE_F32, "field_f32.vti");
  write_image(ctx, PX_DTYPE_F64, "field_f64.vti");
  write_image_2d(ctx);
  write_hex(ctx, PX_DTYPE_F32, "hex_f32.vtu");
  write_hex(ctx, PX_DTYPE_F64, "hex_f64.vtu");
  write_series(ctx);
  test_builder_errors(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == 0);
  px_context_free(ctx);
  return px_test_report("test_io_vtk_write");
}
