/* partix part3d, the surface map: every section's per-segment statistics
 * (DIR/sections/K/segments_CONTOUR*.csv, at the segments' midpoints)
 * interpolated onto the mesh's vertices (io/geometry/geo_mesh_map.h), and
 * written as DIR/surface.vtp (ParaView), surface.csv, surface_energy.png and
 * surface_removal.png (three views each) and surface_summary.json. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/part3d.h"
#include "io/geometry/geo_mesh_map.h"
#include "partix/partix.h"

#define MAXQ 64 /* columns of a segments_*.csv */

/* The samples of one section, its loops the contour's files in order. */
struct sec_data {
  double *x, *y, *val; /* plane coordinates (unplaced) and n x nq values */
  double *len;         /* segment lengths [m] */
  size_t n, cap, nloops, start[65];
};

struct table {
  char name[MAXQ][96]; /* "energy_n_area [J/m^2]" */
  size_t nq;           /* quantities: the columns after s, x, y, nx, ny, length */
};

/* Splits a CSV line in place into at most max fields; their count. */
static size_t split(char *line, char **f, size_t max) {
  size_t n = 0;
  line[strcspn(line, "\r\n")] = 0;
  for (char *p = line; n < max;) {
    f[n++] = p;
    p = strchr(p, ',');
    if (!p) break;
    *p++ = 0;
  }
  return n;
}

static int grow(struct sec_data *d, size_t nq) {
  if (d->n < d->cap) return 0;
  const size_t cap = d->cap ? 2 * d->cap : 256;
  double *x = realloc(d->x, cap * sizeof *x), *y = x ? realloc(d->y, cap * sizeof *y) : NULL;
  if (x) d->x = x;
  if (y) d->y = y;
  double *v = y ? realloc(d->val, cap * nq * sizeof *v) : NULL;
  if (v) d->val = v;
  double *l = v ? realloc(d->len, cap * sizeof *l) : NULL;
  if (l) d->len = l;
  if (!l) return -1;
  d->cap = cap;
  return 0;
}

/* One segments_*.csv as a loop of d; 1 when there is no such file. The
 * first file read fixes the table's columns; later ones must have them. */
static int read_loop(const struct px_part3d *p, const char *path, struct table *t,
                     struct sec_data *d) {
  FILE *f = fopen(path, "r");
  char line[8192], *field[MAXQ + 8];
  if (!f) return 1;
  int ok = fgets(line, sizeof line, f) != NULL;
  size_t nf = ok ? split(line, field, MAXQ + 8) : 0;
  static const char *const geo[6] = {"s [m]", "x [m]", "y [m]", "nx [-]", "ny [-]", "length [m]"};
  for (size_t i = 0; ok && i < 6; ++i) ok = i < nf && strcmp(field[i], geo[i]) == 0;
  if (ok && !t->nq) {
    t->nq = nf - 6;
    for (size_t i = 6; i < nf; ++i) snprintf(t->name[i - 6], sizeof t->name[0], "%s", field[i]);
  }
  ok = ok && nf - 6 == t->nq;
  for (size_t i = 6; ok && i < nf; ++i) ok = strcmp(field[i], t->name[i - 6]) == 0;
  if (ok && d->nloops < 64) d->start[d->nloops] = d->n;
  while (ok && d->nloops < 64 && fgets(line, sizeof line, f)) {
    if (split(line, field, MAXQ + 8) != t->nq + 6 || grow(d, t->nq) != 0) {
      ok = 0;
      break;
    }
    /* placed case coordinates back to the section plane's */
    d->x[d->n] = strtod(field[1], NULL) - p->center[0] + p->cu;
    d->y[d->n] = strtod(field[2], NULL) - p->center[1] + p->cv;
    d->len[d->n] = strtod(field[5], NULL);
    for (size_t q = 0; q < t->nq; ++q) d->val[d->n * t->nq + q] = strtod(field[6 + q], NULL);
    d->n++;
  }
  fclose(f);
  if (!ok || d->nloops >= 64) {
    fprintf(stderr, "partix part3d: %s: not a granular segments table of this study\n", path);
    return -1;
  }
  if (d->n > d->start[d->nloops]) d->start[++d->nloops] = d->n;
  return 0;
}

static int read_section(const struct px_part3d *p, size_t k, struct table *t, struct sec_data *d) {
  char path[4400];
  for (int l = 1; l <= 64; ++l) {
    if (l == 1)
      snprintf(path, sizeof path, "%s/sections/%zu/segments_%s.csv", p->dir, k + 1, p->contour);
    else
      snprintf(path, sizeof path, "%s/sections/%zu/segments_%s.%d.csv", p->dir, k + 1, p->contour,
               l);
    const int r = read_loop(p, path, t, d);
    if (r < 0) return -1;
    if (r > 0) break;
  }
  return 0;
}

static size_t column(const struct table *t, const char *prefix) {
  const size_t len = strlen(prefix);
  for (size_t q = 0; q < t->nq; ++q)
    if (strncmp(t->name[q], prefix, len) == 0 && t->name[q][len] == ' ') return q;
  return (size_t)-1;
}

/* surface.csv: x, y, z, the nearest section, then every quantity. */
static enum px_status write_csv(const struct px_part3d *p, struct px_context *ctx,
                                const struct table *t, const double *out, const int *near,
                                const double *removal) {
  const size_t nv = p->mesh.nv, nc = t->nq + 5;
  const char *names[MAXQ + 5];
  double *cols = malloc(nc * nv * sizeof *cols);
  const double *colp[MAXQ + 5];
  char path[4300];
  if (!cols) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for surface.csv");
  static const char *const first[5] = {"x [m]", "y [m]", "z [m]", "section [-]",
                                       "removal_depth [m]"};
  for (size_t c = 0; c < nc; ++c) {
    names[c] = c < 5 ? first[c] : t->name[c - 5];
    colp[c] = cols + c * nv;
    for (size_t i = 0; i < nv; ++i)
      cols[c * nv + i] = c < 3    ? p->mesh.xyz[3 * i + c]
                         : c == 3 ? near[i] + 1
                         : c == 4 ? removal[i]
                                  : out[i * t->nq + (c - 5)];
  }
  snprintf(path, sizeof path, "%s/surface.csv", p->dir);
  const enum px_status st = px_csv_write_table(ctx, path, nc, names, nv, colp, 10);
  free(cols);
  return st;
}

/* surface.vtp: the triangles with every quantity as point data (names
 * without their units), for ParaView (colour, Warp By Scalar). */
static enum px_status write_vtp(const struct px_part3d *p, struct px_context *ctx,
                                const struct table *t, const double *out, const int *near,
                                const double *removal) {
  const size_t nv = p->mesh.nv, nt = p->mesh.nt;
  struct px_vtk *v = NULL;
  int64_t *conn = malloc((3 * nt + 1) * sizeof *conn);
  double *col = malloc((t->nq + 2) * nv * sizeof *col);
  char path[4300];
  enum px_status st = conn && col ? px_vtk_create(ctx, &v) : PX_STATUS_NOMEM;
  for (size_t i = 0; st == PX_STATUS_OK && i < 3 * nt; ++i) conn[i] = (int64_t)p->mesh.tri[i];
  if (st == PX_STATUS_OK) st = px_vtk_set_points_aos(v, PX_DTYPE_F64, nv, 3, p->mesh.xyz);
  if (st == PX_STATUS_OK) st = px_vtk_set_cells_uniform(v, nt, PX_VTK_CELL_TRIANGLE, 3, conn);
  for (size_t q = 0; st == PX_STATUS_OK && q < t->nq + 2; ++q) {
    char name[96];
    double *c = col + q * nv;
    for (size_t i = 0; i < nv; ++i)
      c[i] = q == t->nq ? near[i] + 1 : q == t->nq + 1 ? removal[i] : out[i * t->nq + q];
    snprintf(name, sizeof name, "%s",
             q == t->nq       ? "section"
             : q == t->nq + 1 ? "removal_depth"
                              : t->name[q]);
    name[strcspn(name, " ")] = 0;
    st = px_vtk_add_scalar(v, PX_VTK_ASSOC_POINT, name, PX_DTYPE_F64, nv, c);
  }
  snprintf(path, sizeof path, "%s/surface.vtp", p->dir);
  if (st == PX_STATUS_OK) st = px_vtk_write(v, path);
  px_vtk_free(v);
  free(conn);
  free(col);
  if (st == PX_STATUS_NOMEM && !px_context_message(ctx)[0])
    px_context_fail(ctx, st, "out of memory for surface.vtp");
  return st;
}

static enum px_status picture(const struct px_part3d *p, struct px_context *ctx,
                              const double *value, const char *label, const char *what,
                              const char *file) {
  struct px_mesh_view view;
  char title[512], path[4300];
  memset(&view, 0, sizeof view);
  px_part3d_views(p, 1, &view);
  view.mesh = &p->mesh;
  view.value = value;
  view.label = label;
  view.map = PX_COLORMAP_INFERNO;
  const char *b = strrchr(p->mesh_path, '/') ? strrchr(p->mesh_path, '/') + 1 : p->mesh_path;
  snprintf(title, sizeof title, "%.200s: %s, from %zu sections", b, what, p->nsec);
  view.title = title;
  snprintf(path, sizeof path, "%s/%s", p->dir, file);
  return px_mesh_view_png(ctx, &view, path);
}

/* The extreme vertices of a quantity, as a JSON member. */
static void extremes(FILE *o, const struct px_part3d *p, const char *name, const char *unit,
                     const double *val, size_t stride, const int *near) {
  size_t hi = 0, lo = 0;
  for (size_t i = 1; i < p->mesh.nv; ++i) {
    if (val[i * stride] > val[hi * stride]) hi = i;
    if (val[i * stride] < val[lo * stride]) lo = i;
  }
  fprintf(o, "  \"%s\": {\"unit\": \"%s\",\n", name, unit);
  for (int k = 0; k < 2; ++k) {
    const size_t i = k ? lo : hi;
    const double *x = p->mesh.xyz + 3 * i;
    fprintf(o,
            "    \"%s\": {\"value\": %.6g, \"vertex\": %zu, \"at\": [%.6g, %.6g, %.6g], "
            "\"section\": %d}%s\n",
            k ? "coldest" : "hottest", val[i * stride], i, x[0], x[1], x[2], near[i] + 1,
            k ? "" : ",");
  }
  fprintf(o, "  },\n");
}

/* surface_summary.json: hottest and coldest vertices, and the spread of the
 * sections' mean specific impact energy (length-weighted over segments). */
static enum px_status write_summary(const struct px_part3d *p, struct px_context *ctx,
                                    const struct table *t, const struct sec_data *d,
                                    const int *finished, const double *out, const int *near,
                                    const double *removal, size_t qe) {
  struct px_file *f;
  char path[4300];
  double mean[PX_PART3D_MAX_SECTIONS], lo = HUGE_VAL, hi = -HUGE_VAL, sum = 0;
  size_t used = 0;
  snprintf(path, sizeof path, "%s/surface_summary.json", p->dir);
  PX_TRY(px_file_open(ctx, path, &f));
  FILE *o = px_file_stream(f);
  fprintf(o, "{\n  \"mesh\": \"%s\", \"sections\": %zu,\n", p->mesh_path, p->nsec);
  extremes(o, p, "energy_n_area", "J/m^2", out + qe, t->nq, near);
  extremes(o, p, "removal_depth", "m", removal, 1, near);
  fprintf(o, "  \"section_mean_energy_n_area\": [");
  for (size_t k = 0; k < p->nsec; ++k) {
    double w = 0, s = 0;
    for (size_t i = 0; finished[k] && i < d[k].n; ++i) {
      w += d[k].len[i];
      s += d[k].len[i] * d[k].val[i * t->nq + qe];
    }
    mean[k] = w > 0 ? s / w : NAN;
    fprintf(o, "%s%.6g", k ? ", " : "", isfinite(mean[k]) ? mean[k] : -1.0);
    if (isfinite(mean[k])) {
      lo = fmin(lo, mean[k]);
      hi = fmax(hi, mean[k]);
      sum += mean[k];
      ++used;
    }
  }
  const double avg = used ? sum / (double)used : 0;
  fprintf(o,
          "],\n  \"section_spread\": {\"min\": %.6g, \"max\": %.6g, \"mean\": %.6g, "
          "\"range_over_mean\": %.6g}\n}\n",
          used ? lo : 0, used ? hi : 0, avg, avg > 0 ? (hi - lo) / avg : 0);
  printf(
      "surface map from %zu of %zu sections: specific impact energy per section %.4g to %.4g "
      "J/m^2 (spread %.0f%% of the mean)\n",
      used, p->nsec, used ? lo : 0, used ? hi : 0, avg > 0 ? 100 * (hi - lo) / avg : 0);
  return px_file_commit(f);
}

int px_part3d_map(struct px_part3d *p, struct px_context *ctx, const int *finished) {
  struct sec_data d[PX_PART3D_MAX_SECTIONS];
  struct px_geo_map_section sec[PX_PART3D_MAX_SECTIONS];
  struct table t;
  size_t ns = 0;
  int code = PX_CLI_EXIT_OK;
  memset(d, 0, sizeof d);
  memset(&t, 0, sizeof t);
  for (size_t k = 0; k < p->nsec && !code; ++k) {
    if (!finished[k]) continue;
    if (read_section(p, k, &t, &d[k]) != 0) code = PX_CLI_EXIT_FAILURE;
    if (!code && d[k].n && d[k].nloops) {
      sec[ns].offset = p->offset[k];
      sec[ns].n = d[k].n;
      sec[ns].x = d[k].x;
      sec[ns].y = d[k].y;
      sec[ns].nloops = d[k].nloops;
      sec[ns].loop_start = d[k].start;
      sec[ns++].value = d[k].val;
    }
  }
  const size_t qe = column(&t, "energy_n_area"), qa = column(&t, "archard_depth"),
               qf = column(&t, "finnie_depth");
  if (!code && (!ns || qe == (size_t)-1 || qa == (size_t)-1 || qf == (size_t)-1)) {
    fprintf(stderr, "partix part3d: no finished section to map (%s/sections)\n", p->dir);
    code = PX_CLI_EXIT_FAILURE;
  }
  double *out = code ? NULL : malloc((p->mesh.nv * t.nq + 1) * sizeof *out);
  double *removal = code ? NULL : malloc((p->mesh.nv + 1) * sizeof *removal);
  int *near = code ? NULL : malloc((p->mesh.nv + 1) * sizeof *near);
  if (!code && (!out || !removal || !near)) code = PX_CLI_EXIT_FAILURE;
  if (!code &&
      px_geo_mesh_map(ctx, &p->mesh, p->u, p->v, p->n, sec, ns, t.nq, out, near) != PX_STATUS_OK)
    code = PX_CLI_EXIT_FAILURE;
  if (!code) {
    /* near indexes the mapped sections: back to the study's numbering */
    size_t idx[PX_PART3D_MAX_SECTIONS], j = 0;
    for (size_t k = 0; k < p->nsec; ++k)
      if (finished[k] && d[k].n) idx[j++] = k;
    for (size_t i = 0; i < p->mesh.nv; ++i) {
      near[i] = (int)idx[near[i]];
      removal[i] = out[i * t.nq + qa] + out[i * t.nq + qf];
    }
    double *energy = malloc((p->mesh.nv + 1) * sizeof *energy);
    for (size_t i = 0; energy && i < p->mesh.nv; ++i) energy[i] = out[i * t.nq + qe];
    if (!energy || write_csv(p, ctx, &t, out, near, removal) != PX_STATUS_OK ||
        write_vtp(p, ctx, &t, out, near, removal) != PX_STATUS_OK ||
        picture(p, ctx, energy, "energy_n_area [J/m^2]", "specific normal impact energy",
                "surface_energy.png") != PX_STATUS_OK ||
        picture(p, ctx, removal, "removal depth, Archard + Finnie [m]", "removal depth",
                "surface_removal.png") != PX_STATUS_OK ||
        write_summary(p, ctx, &t, d, finished, out, near, removal, qe) != PX_STATUS_OK)
      code = PX_CLI_EXIT_FAILURE;
    free(energy);
    if (code) fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
  }
  for (size_t k = 0; k < p->nsec; ++k) {
    free(d[k].x);
    free(d[k].y);
    free(d[k].val);
    free(d[k].len);
  }
  free(out);
  free(removal);
  free(near);
  return code;
}
