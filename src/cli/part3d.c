/* partix part3d PART.yaml: a 3D part from its cross-sections.
 *
 *   case: rib_section.yaml    the 2D granular case (container, media, motion),
 *                             relative to this file; its contour `contour`
 *                             (a dxf shape) is replaced by each section
 *   mesh: rib.stl             the part's closed surface (STL or OBJ)
 *   units: 0.001              metres per mesh unit (default 1)
 *   normal: [0, 0, 1]         the sections' normal
 *   vibration: [1, 0, 0]      the vibration direction: the sections' x axis
 *   center: [0.08, 0.07]      [m] where the part's centre goes in the case
 *   sections: 7               K planes evenly spaced across the part, or a
 *                             list of positions n . p [m]
 *   contour: part             (default part)
 *   dir: out/rib              (default out/<file name>)
 *   set: {backend.threads: 1} overrides of every section's run
 *
 * The mesh is read, checked closed and manifold and cut into the sections'
 * contours (DIR/contours/section-K.dxf, DIR/sections.csv, DIR/sections.png);
 * the K runs go through partix sweep's machinery (DIR/sections/K, one
 * folder each, resumable: running the command again skips finished runs and
 * resumes interrupted ones); the runs' statistics are then mapped onto the
 * mesh (part3d_map.c). */
#include "cli/part3d.h"

#include <errno.h>
#include <libfyaml.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/sweep.h"
#include "partix/memory.h"
#include "io/mesh_view.h"
#include "partix/partix.h"

static const char *scalar(struct fy_node *n) {
  return n && fy_node_is_scalar(n) ? fy_node_get_scalar0(n) : NULL;
}

static int fail(const struct px_part3d *p, struct fy_node *n, const char *fmt, ...) PX_PRINTF(3, 4);
/* "FILE:LINE:COL: message" at node n (or its first item); returns 2. */
static int fail(const struct px_part3d *p, struct fy_node *n, const char *fmt, ...) {
  va_list ap;
  void *it = NULL;
  while (n && !fy_node_is_scalar(n)) {
    if (fy_node_is_mapping(n)) {
      struct fy_node_pair *q = fy_node_mapping_iterate(n, &it);
      n = q ? fy_node_pair_key(q) : NULL;
    } else {
      n = fy_node_sequence_iterate(n, &it);
    }
    it = NULL;
  }
  struct fy_token *tok = n ? fy_node_get_scalar_token(n) : NULL;
  const struct fy_mark *m = tok ? fy_token_start_mark(tok) : NULL;
  if (m)
    fprintf(stderr, "%s:%d:%d: ", p->file, m->line + 1, m->column + 1);
  else
    fprintf(stderr, "%s: ", p->file);
  va_start(ap, fmt);
  vfprintf(stderr, fmt, ap);
  va_end(ap);
  fputc('\n', stderr);
  return PX_CLI_EXIT_USAGE;
}

static int real(const char *s, double *x) {
  char *e;
  if (!s) return 0;
  errno = 0;
  *x = strtod(s, &e);
  return e != s && !*e && isfinite(*x);
}

/* A list of exactly n finite numbers. */
static int vector(const struct px_part3d *p, struct fy_node *root, const char *key, size_t n,
                  double *out, const char *what) {
  struct fy_node *v = fy_node_mapping_lookup_by_string(root, key, FY_NT);
  if (!v) return fail(p, root, "%s: required (%s)", key, what);
  if (!fy_node_is_sequence(v) || (size_t)fy_node_sequence_item_count(v) != n)
    return fail(p, v, "%s: a list of %zu numbers (%s)", key, n, what);
  for (size_t i = 0; i < n; ++i)
    if (!real(scalar(fy_node_sequence_get_by_index(v, (int)i)), &out[i]))
      return fail(p, fy_node_sequence_get_by_index(v, (int)i), "%s: component %zu is not a number",
                  key, i + 1);
  return 0;
}

/* A file named relative to the part3d file. */
static int path_key(struct px_part3d *p, struct fy_node *root, const char *key, char *out,
                    size_t size) {
  struct fy_node *n = fy_node_mapping_lookup_by_string(root, key, FY_NT);
  const char *c = scalar(n);
  const char *slash = strrchr(p->file, '/');
  if (!c || !c[0]) return fail(p, n ? n : root, "%s: a file name is required", key);
  if (c[0] == '/' || !slash)
    snprintf(out, size, "%s", c);
  else
    snprintf(out, size, "%.*s%s", (int)(slash - p->file + 1), p->file, c);
  if (!px_file_exists(out)) return fail(p, n, "%s: no file '%s'", key, out);
  return 0;
}

static int load_sections(struct px_part3d *p, struct fy_node *root) {
  struct fy_node *n = fy_node_mapping_lookup_by_string(root, "sections", FY_NT);
  double x;
  if (!n) return fail(p, root, "sections: required (a count, or a list of positions [m])");
  if (fy_node_is_scalar(n)) {
    if (!real(scalar(n), &x) || x != floor(x) || x < 1 || x > PX_PART3D_MAX_SECTIONS)
      return fail(p, n, "sections: a count from 1 to %d, or a list of positions [m]",
                  PX_PART3D_MAX_SECTIONS);
    p->nsec = (size_t)x;
    for (size_t k = 0; k < p->nsec; ++k) p->offset[k] = NAN; /* spread over the part later */
    return 0;
  }
  const int m = fy_node_is_sequence(n) ? fy_node_sequence_item_count(n) : 0;
  if (m < 1 || m > PX_PART3D_MAX_SECTIONS)
    return fail(p, n, "sections: a count, or a list of 1 to %d positions [m]",
                PX_PART3D_MAX_SECTIONS);
  for (int k = 0; k < m; ++k) {
    struct fy_node *it = fy_node_sequence_get_by_index(n, k);
    if (!real(scalar(it), &p->offset[k]) || (k && !(p->offset[k] > p->offset[k - 1])))
      return fail(p, it, "sections: positions are increasing numbers [m]");
  }
  p->nsec = (size_t)m;
  return 0;
}

static int load_options(struct px_part3d *p, struct fy_node *root) {
  static const char *const known[] = {"case",    "mesh",      "units",  "weld",
                                      "normal",  "vibration", "center", "sections",
                                      "contour", "dir",       "set"};
  struct fy_node_pair *q;
  void *it = NULL;
  while ((q = fy_node_mapping_iterate(root, &it)) != NULL) {
    const char *key = scalar(fy_node_pair_key(q));
    size_t k = 0;
    while (k < sizeof known / sizeof *known && !(key && strcmp(key, known[k]) == 0)) ++k;
    if (k == sizeof known / sizeof *known)
      return fail(p, fy_node_pair_key(q),
                  "unknown key '%s' (a part3d file has case, mesh, units, weld, normal, "
                  "vibration, center, sections, contour, dir, set)",
                  key ? key : "?");
  }
  struct fy_node *n = fy_node_mapping_lookup_by_string(root, "units", FY_NT);
  p->units = 1;
  if (n && (!real(scalar(n), &p->units) || !(p->units > 0)))
    return fail(p, n, "units: metres per mesh unit, > 0 (0.001 for millimetres)");
  n = fy_node_mapping_lookup_by_string(root, "weld", FY_NT);
  if (n && (!real(scalar(n), &p->weld) || !(p->weld >= 0)))
    return fail(p, n, "weld: a distance >= 0 [mesh units]");
  n = fy_node_mapping_lookup_by_string(root, "contour", FY_NT);
  p->contour = n ? scalar(n) : "part";
  if (!p->contour || !p->contour[0]) return fail(p, n, "contour: the name of a contour");
  n = fy_node_mapping_lookup_by_string(root, "dir", FY_NT);
  if (n && !(scalar(n) && scalar(n)[0])) return fail(p, n, "dir: a folder name");
  if (n) {
    snprintf(p->dir, sizeof p->dir, "%s", scalar(n));
  } else {
    const char *b = strrchr(p->file, '/') ? strrchr(p->file, '/') + 1 : p->file;
    snprintf(p->dir, sizeof p->dir, "out/%.*s", (int)strcspn(b, "."), b);
  }
  n = fy_node_mapping_lookup_by_string(root, "set", FY_NT);
  if (n && !fy_node_is_mapping(n)) return fail(p, n, "set: a map of case keys to values");
  for (it = NULL; n && (q = fy_node_mapping_iterate(n, &it)) != NULL;) {
    if (p->nset == PX_PART3D_MAX_SET) return fail(p, q ? fy_node_pair_key(q) : n, "set: too many");
    p->set_key[p->nset] = scalar(fy_node_pair_key(q));
    p->set_value[p->nset] = scalar(fy_node_pair_value(q));
    if (!p->set_key[p->nset] || !p->set_value[p->nset])
      return fail(p, fy_node_pair_value(q), "set: each value is a single value");
    ++p->nset;
  }
  return 0;
}

static int load(struct px_part3d *p) {
  if (!px_file_exists(p->file)) {
    fprintf(stderr, "partix part3d: %s: no such file\n", p->file);
    return PX_CLI_EXIT_USAGE;
  }
  p->doc = fy_document_build_from_file(NULL, p->file);
  if (!p->doc) {
    fprintf(stderr, "%s: cannot read the part3d file: not valid YAML (see above)\n", p->file);
    return PX_CLI_EXIT_USAGE;
  }
  struct fy_node *root = fy_document_root(p->doc);
  if (!root || !fy_node_is_mapping(root))
    return fail(p, root, "a part3d file is a map (case, mesh, normal, vibration, ...)");
  int code = load_options(p, root);
  if (!code) code = path_key(p, root, "case", p->base, sizeof p->base);
  if (!code) code = path_key(p, root, "mesh", p->mesh_path, sizeof p->mesh_path);
  if (!code) code = vector(p, root, "normal", 3, p->normal, "the sections' normal");
  if (!code)
    code = vector(p, root, "vibration", 3, p->vibration,
                  "the vibration direction, the sections' x axis");
  if (!code)
    code =
        vector(p, root, "center", 2, p->center, "where the part's centre goes in the 2D case [m]");
  if (!code) code = load_sections(p, root);
  return code;
}

/* The base case's contour to replace: its index; a dxf shape. */
static int find_contour(struct px_part3d *p, struct px_context *ctx) {
  struct px_case *c = NULL;
  const char *ov[PX_PART3D_MAX_SET];
  char buf[PX_PART3D_MAX_SET][512];
  for (size_t k = 0; k < p->nset; ++k) {
    snprintf(buf[k], sizeof buf[k], "%s=%s", p->set_key[k], p->set_value[k]);
    ov[k] = buf[k];
  }
  /* quietly: the runs report their automatic settings themselves */
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  const enum px_status st = px_case_load(ctx, p->base, ov, p->nset, &c);
  px_context_set_log_level(ctx, p->log_level);
  if (st != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return PX_CLI_EXIT_USAGE;
  }
  const char *solver = px_case_solver(c), *name = NULL, *type = NULL;
  size_t n = 0, i;
  int code = 0;
  if (strcmp(solver, "granular") != 0 || px_case_count(c, "granular.contours", &n) != PX_STATUS_OK)
    n = 0;
  for (i = 0; i < n; ++i) {
    char key[128];
    snprintf(key, sizeof key, "granular.contours[%zu].name", i);
    if (px_case_get_string(c, key, &name) == PX_STATUS_OK && strcmp(name, p->contour) == 0) break;
  }
  if (i == n) {
    fprintf(stderr, "%s: %s: no granular contour named '%s' to replace by the sections\n", p->file,
            p->base, p->contour);
    code = PX_CLI_EXIT_USAGE;
  } else {
    char key[128];
    snprintf(key, sizeof key, "granular.contours[%zu].shape.type", i);
    if (px_case_get_string(c, key, &type) != PX_STATUS_OK || strcmp(type, "dxf") != 0) {
      fprintf(stderr,
              "%s: %s: contour '%s' is a %s; the sections replace a dxf shape (give it "
              "shape: {type: dxf, file: any.dxf})\n",
              p->file, p->base, p->contour, type ? type : "?");
      code = PX_CLI_EXIT_USAGE;
    }
    p->contour_index = (int)i;
  }
  /* the sections' point spacing: the case's boundary segment length (its
   * default, the smallest disc radius) */
  static const char *const len_keys[] = {
      "granular.segment_length", "granular.media.radius.min", "granular.media.radius.mean",
      "granular.media[0].radius.min", "granular.media[0].radius.mean"};
  p->spacing = 0;
  for (size_t k = 0; k < 5 && !(p->spacing > 0); ++k)
    if (px_case_has(c, len_keys[k]) &&
        px_case_get_real(c, len_keys[k], &p->spacing) != PX_STATUS_OK)
      p->spacing = 0;
  if (!(p->spacing > 0)) p->spacing = 0.001;
  px_case_free(c);
  return code;
}

/* Mesh in metres, checked; the frame; the sections (evenly spaced at the
 * middles of K equal slabs when counted) and their contours. */
static int cut(struct px_part3d *p, struct px_context *ctx) {
  double lo[3], hi[3], dmin = HUGE_VAL, dmax = -HUGE_VAL;
  if (px_geo_mesh_read(ctx, p->mesh_path, p->weld, &p->mesh) != PX_STATUS_OK) goto bad;
  px_geo_mesh_scale(&p->mesh, p->units);
  if (px_geo_mesh_check(ctx, &p->mesh) != PX_STATUS_OK) goto bad;
  if (px_geo_mesh_frame(ctx, p->normal, p->vibration, p->u, p->v, p->n) != PX_STATUS_OK) goto bad;
  px_geo_mesh_measure(&p->mesh, NULL, NULL, lo, hi);
  const double c[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  p->cu = p->u[0] * c[0] + p->u[1] * c[1] + p->u[2] * c[2];
  p->cv = p->v[0] * c[0] + p->v[1] * c[1] + p->v[2] * c[2];
  for (size_t i = 0; i < p->mesh.nv; ++i) {
    const double *x = p->mesh.xyz + 3 * i, d = p->n[0] * x[0] + p->n[1] * x[1] + p->n[2] * x[2];
    dmin = fmin(dmin, d);
    dmax = fmax(dmax, d);
  }
  for (size_t k = 0; k < p->nsec; ++k) {
    if (isnan(p->offset[k]))
      p->offset[k] = dmin + (dmax - dmin) * ((double)k + 0.5) / (double)p->nsec;
    if (px_geo_mesh_slice(ctx, &p->mesh, p->u, p->v, p->n, p->offset[k], &p->loops[k],
                          &p->nloops[k]) != PX_STATUS_OK)
      goto bad;
    if (!p->nloops[k]) {
      fprintf(stderr, "%s: section %zu at %g m misses the part (it spans %g to %g m along %s)\n",
              p->file, k + 1, p->offset[k], dmin, dmax, "the normal");
      return PX_CLI_EXIT_USAGE;
    }
  }
  return 0;
bad:
  fprintf(stderr, "%s: %s\n", p->file, px_context_message(ctx));
  return PX_CLI_EXIT_USAGE;
}

/* The loop q resampled for the 2D case: its corners (a turn of more than
 * 25 degrees) kept, every stretch between two corners cut into pieces of
 * equal length close to h. A faceted curve keeps its shape (the points lie
 * on its facets) while the facets' own spacing, often much finer near an
 * edge, no longer sets the granular segments (a segment much shorter than
 * the others collects the same impacts per unit area over too small a length
 * to be meaningful). *x, *y (malloc) get the points; their count, 0 when
 * out of memory. */
static size_t resample(const struct px_geo_polyline *q, double h, double **x, double **y) {
  const size_t n = q->n;
  size_t *corner = malloc(n * sizeof *corner), nc = 0, cap = 0, m = 0;
  *x = *y = NULL;
  for (size_t i = 0; corner && i < n; ++i) {
    const size_t a = (i + n - 1) % n, b = (i + 1) % n;
    const double ux = q->x[i] - q->x[a], uy = q->y[i] - q->y[a];
    const double vx = q->x[b] - q->x[i], vy = q->y[b] - q->y[i];
    const double turn = fabs(atan2(ux * vy - uy * vx, ux * vx + uy * vy));
    if (turn > 25.0 * 3.14159265358979323846 / 180) corner[nc++] = i;
  }
  if (corner && !nc) corner[nc++] = 0;
  for (size_t j = 0; corner && j < nc; ++j) {
    const size_t a = corner[j], b = corner[(j + 1) % nc];
    const size_t len = (b + n - a) % n ? (b + n - a) % n : n; /* edges in the stretch */
    double L = 0;
    for (size_t e = 0; e < len; ++e) {
      const size_t i = (a + e) % n, k = (i + 1) % n;
      L += hypot(q->x[k] - q->x[i], q->y[k] - q->y[i]);
    }
    const size_t pieces = L / h < 1.5 ? 1 : (size_t)lround(L / h);
    if (m + pieces > cap) {
      cap = 2 * (m + pieces);
      double *nx = realloc(*x, cap * sizeof *nx), *ny = nx ? realloc(*y, cap * sizeof *ny) : NULL;
      if (nx) *x = nx;
      if (ny) *y = ny;
      if (!ny) {
        m = 0;
        break;
      }
    }
    /* walk the stretch, a point at every L / pieces of arc length */
    size_t e = 0;
    double s0 = 0; /* arc length at the start of edge e */
    for (size_t k = 0; k < pieces; ++k) {
      const double s = L * (double)k / (double)pieces;
      double el = 0;
      for (;;) {
        const size_t i = (a + e) % n, i1 = (i + 1) % n;
        el = hypot(q->x[i1] - q->x[i], q->y[i1] - q->y[i]);
        if (s <= s0 + el || e + 1 == len) break;
        s0 += el;
        ++e;
      }
      const size_t i = (a + e) % n, i1 = (i + 1) % n;
      const double t = el > 0 ? fmin(1, (s - s0) / el) : 0;
      (*x)[m] = q->x[i] + t * (q->x[i1] - q->x[i]);
      (*y)[m++] = q->y[i] + t * (q->y[i1] - q->y[i]);
    }
  }
  free(corner);
  return m;
}

/* DIR/contours/section-K.dxf: the section's loops, placed in the case
 * (outer boundaries first: the contour's name goes to the first loop). */
static enum px_status write_dxf(struct px_part3d *p, struct px_context *ctx, size_t k,
                                const char *path) {
  struct px_file *f;
  PX_TRY(px_file_open(ctx, path, &f));
  FILE *o = px_file_stream(f);
  fprintf(o, "999\nsection %zu of %s at %.17g m along the normal\n0\nSECTION\n2\nENTITIES\n", k + 1,
          p->mesh_path, p->offset[k]);
  for (int outer = 1; outer >= 0; --outer)
    for (size_t l = 0; l < p->nloops[k]; ++l) {
      const struct px_geo_polyline *q = &p->loops[k][l];
      if ((px_geo_polyline_area(q) > 0) != outer) continue;
      double *x, *y;
      const size_t m = resample(q, p->spacing, &x, &y);
      if (m < 3) {
        free(x);
        free(y);
        px_file_abort(f);
        return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory resampling section %zu", k + 1);
      }
      fprintf(o, "0\nLWPOLYLINE\n8\n0\n90\n%zu\n70\n1\n", m);
      for (size_t i = 0; i < m; ++i)
        fprintf(o, "10\n%.17g\n20\n%.17g\n", x[i] - p->cu + p->center[0],
                y[i] - p->cv + p->center[1]);
      free(x);
      free(y);
    }
  fprintf(o, "0\nENDSEC\n0\nEOF\n");
  return px_file_commit(f);
}

/* DIR/sections.csv and DIR/sections.png (the part with its sections). */
static enum px_status write_sections(struct px_part3d *p, struct px_context *ctx) {
  char path[4300];
  double area[PX_PART3D_MAX_SECTIONS], perim[PX_PART3D_MAX_SECTIONS], num[PX_PART3D_MAX_SECTIONS],
      loops[PX_PART3D_MAX_SECTIONS];
  size_t np = 0, cap = 0;
  for (size_t k = 0; k < p->nsec; ++k) {
    area[k] = perim[k] = 0;
    num[k] = (double)(k + 1);
    loops[k] = (double)p->nloops[k];
    for (size_t l = 0; l < p->nloops[k]; ++l) {
      area[k] += px_geo_polyline_area(&p->loops[k][l]);
      perim[k] += px_geo_polyline_perimeter(&p->loops[k][l]);
    }
    cap += p->nloops[k];
  }
  const char *names[] = {"section [-]", "offset [m]", "loops [-]", "area [m^2]", "perimeter [m]"};
  const double *cols[] = {num, p->offset, loops, area, perim};
  snprintf(path, sizeof path, "%s/sections.csv", p->dir);
  PX_TRY(px_csv_write_table(ctx, path, 5, names, p->nsec, cols, 12));
  size_t *pn = calloc(cap + 1, sizeof *pn);
  double **xyz = calloc(cap + 1, sizeof *xyz);
  enum px_status st = pn && xyz ? PX_STATUS_OK : PX_STATUS_NOMEM;
  for (size_t k = 0; k < p->nsec && st == PX_STATUS_OK; ++k)
    for (size_t l = 0; l < p->nloops[k] && st == PX_STATUS_OK; ++l, ++np) {
      const struct px_geo_polyline *q = &p->loops[k][l];
      pn[np] = q->n;
      xyz[np] = malloc(3 * q->n * sizeof(double));
      if (!xyz[np]) st = PX_STATUS_NOMEM;
      for (size_t i = 0; st == PX_STATUS_OK && i < q->n; ++i)
        for (int c = 0; c < 3; ++c)
          xyz[np][3 * i + (size_t)c] =
              q->x[i] * p->u[c] + q->y[i] * p->v[c] + p->offset[k] * p->n[c];
    }
  if (st == PX_STATUS_OK) {
    struct px_mesh_view view;
    char title[256];
    memset(&view, 0, sizeof view);
    px_part3d_views(p, 0, &view);
    view.mesh = &p->mesh;
    const char *b = strrchr(p->mesh_path, '/') ? strrchr(p->mesh_path, '/') + 1 : p->mesh_path;
    snprintf(title, sizeof title, "%.200s: %zu sections", b, p->nsec);
    view.title = title;
    view.npoly = np;
    view.poly_n = pn;
    view.poly_xyz = (const double *const *)xyz;
    snprintf(path, sizeof path, "%s/sections.png", p->dir);
    st = px_mesh_view_png(ctx, &view, path);
  }
  for (size_t i = 0; xyz && i < np; ++i) free(xyz[i]);
  free(xyz);
  free(pn);
  if (st == PX_STATUS_NOMEM && !px_context_message(ctx)[0])
    px_context_fail(ctx, st, "out of memory drawing the sections");
  return st;
}

void px_part3d_views(const struct px_part3d *p, int surface, struct px_mesh_view *v) {
  /* the sections' outlines are seen along the normal; a map's first view
   * looks along the vibration instead (the end faces say little) */
  static const char *const names[4] = {"along the section normal", "across the sections", "oblique",
                                       "along the vibration"};
  for (int c = 0; c < 3; ++c) {
    v->dir[0][c] = surface ? p->u[c] : -p->n[c];
    v->up[0][c] = surface ? p->n[c] : p->v[c];
    v->dir[1][c] = -p->v[c];
    v->up[1][c] = p->n[c];
    v->dir[2][c] = -0.6 * p->u[c] - 0.9 * p->v[c] - 0.7 * p->n[c];
    v->up[2][c] = p->n[c];
  }
  v->view_name[0] = names[surface ? 3 : 0];
  v->view_name[1] = names[1];
  v->view_name[2] = names[2];
}

/* The sweep of the K section runs: DIR/sections/K, each the base case with
 * the contour's dxf file replaced by DIR/contours/section-K.dxf. */
static int make_sweep(struct px_part3d *p, struct px_context *ctx, struct px_sweep *s, int dry) {
  char cdir[4300], abs[8500], cwd[4096];
  snprintf(cdir, sizeof cdir, "%s/contours", p->dir);
  if (!dry && px_file_mkdirs(ctx, cdir) != PX_STATUS_OK) {
    fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
    return PX_CLI_EXIT_FAILURE;
  }
  /* absolute: the runs' cases read their dxf relative to the base case */
  if (cdir[0] != '/' && getcwd(cwd, sizeof cwd))
    snprintf(abs, sizeof abs, "%s/%s", cwd, cdir);
  else
    snprintf(abs, sizeof abs, "%s", cdir);
  s->file = p->file;
  snprintf(s->base, sizeof s->base, "%s", p->base);
  snprintf(s->dir, sizeof s->dir, "%.4000s/sections", p->dir);
  s->key[0] = "section";
  s->nkeys = 1;
  s->runs = calloc(p->nsec, sizeof *s->runs);
  if (!s->runs) return PX_CLI_EXIT_FAILURE;
  s->nruns = p->nsec;
  for (size_t k = 0; k < p->nsec; ++k) {
    struct px_sweep_run *r = &s->runs[k];
    char dxf[8600];
    snprintf(r->name, sizeof r->name, "%zu", k + 1);
    r->value[0] = r->name;
    snprintf(r->status, sizeof r->status, "not run");
    r->exit = -1;
    snprintf(dxf, sizeof dxf, "%s/section-%zu.dxf", abs, k + 1);
    if (!dry && write_dxf(p, ctx, k, dxf) != PX_STATUS_OK) {
      fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
      return PX_CLI_EXIT_FAILURE;
    }
    for (size_t i = 0; i < p->nset + 3; ++i) {
      char o[8800];
      const int c = p->contour_index;
      if (i < p->nset)
        snprintf(o, sizeof o, "%s=%s", p->set_key[i], p->set_value[i]);
      else if (i == p->nset)
        snprintf(o, sizeof o, "granular.contours[%d].shape.file=%s", c, dxf);
      else if (i == p->nset + 1)
        snprintf(o, sizeof o, "granular.contours[%d].shape.scale=1", c);
      else
        snprintf(o, sizeof o, "granular.contours[%d].shape.offset=[0, 0]", c);
      r->overrides[r->noverrides] = strdup(o);
      if (!r->overrides[r->noverrides++]) return PX_CLI_EXIT_FAILURE;
    }
  }
  return 0;
}

static void help(void) {
  printf(
      "usage: partix part3d PART.yaml [--jobs J] [--dry-run]\n\n"
      "Studies a 3D part through plane sections: reads its surface (STL or OBJ),\n"
      "checks it is closed and manifold, cuts it into sections, runs each section as\n"
      "a 2D granular case (DIR/sections/K, at most J at a time, as partix sweep does:\n"
      "running the command again skips finished sections and resumes interrupted\n"
      "ones), then maps the sections' statistics onto the part's surface\n"
      "(DIR/surface.vtp, surface.csv, surface_*.png, surface_summary.json).\n"
      "--dry-run cuts the sections and lists the runs without running them.\n"
      "The part3d file (docs/part3d.md):\n\n"
      "  case: CASE.yaml          the 2D case; its contour CONTOUR (a dxf shape) is replaced\n"
      "  mesh: PART.stl           the part's surface (.stl ASCII or binary, .obj)\n"
      "  units: 0.001             metres per mesh unit (default 1)\n"
      "  normal: [0, 0, 1]        the sections' normal\n"
      "  vibration: [1, 0, 0]     the vibration direction: the sections' x axis\n"
      "  center: [X, Y]           [m] where the part's centre goes in the 2D case\n"
      "  sections: K              K planes evenly spaced, or a list of positions [m]\n"
      "  contour: part            the contour the sections replace (default part)\n"
      "  dir: out/NAME            the study's folder (default out/<file name>)\n"
      "  set: {KEY: VALUE, ...}   overrides of every section's run\n"
      "  weld: 0                  join mesh vertices closer than this [mesh units]\n\n"
      "Exit status: 0 done, 1 a section's run failed, 2 the file, the mesh or the case\n"
      "is wrong, 130 interrupted (run it again to continue).\n");
}

static void part3d_free(struct px_part3d *p, struct px_context *ctx, struct px_sweep *s) {
  for (size_t k = 0; k < p->nsec; ++k) {
    for (size_t l = 0; l < p->nloops[k]; ++l) px_geo_polyline_free(ctx, &p->loops[k][l]);
    px_mem_free(ctx, p->loops[k]);
  }
  px_geo_mesh_free(ctx, &p->mesh);
  if (p->doc) fy_document_destroy(p->doc);
  for (size_t r = 0; r < s->nruns; ++r)
    for (size_t k = 0; k < s->runs[r].noverrides; ++k) free(s->runs[r].overrides[k]);
  free(s->runs);
}

static void print_sections(const struct px_part3d *p) {
  printf("%s: %zu vertices, %zu triangles, sections along (%g, %g, %g):\n", p->mesh_path,
         p->mesh.nv, p->mesh.nt, p->n[0], p->n[1], p->n[2]);
  for (size_t k = 0; k < p->nsec; ++k) {
    double a = 0;
    for (size_t l = 0; l < p->nloops[k]; ++l) a += px_geo_polyline_area(&p->loops[k][l]);
    printf("  section %zu at %.6g m: %zu loop%s, area %.6g m^2\n", k + 1, p->offset[k],
           p->nloops[k], p->nloops[k] == 1 ? "" : "s", a);
  }
}

int px_cli_part3d(struct px_cli *cli) {
  struct px_part3d p;
  struct px_sweep s;
  long jobs = 1;
  int dry = 0, code;
  if (px_cli_wants_help(cli)) {
    help();
    return PX_CLI_EXIT_OK;
  }
  memset(&p, 0, sizeof p);
  memset(&s, 0, sizeof s);
  for (int i = 0; i < cli->argc; ++i) {
    const char *a = cli->argv[i];
    if (strcmp(a, "--jobs") == 0 || strcmp(a, "-j") == 0) {
      char *end = NULL;
      jobs = i + 1 < cli->argc ? strtol(cli->argv[++i], &end, 10) : 0;
      if (!end || *end || jobs < 1 || jobs > PX_SWEEP_MAX_JOBS) {
        fprintf(stderr, "partix part3d: --jobs takes a number from 1 to %d\n", PX_SWEEP_MAX_JOBS);
        return PX_CLI_EXIT_USAGE;
      }
    } else if (strcmp(a, "--dry-run") == 0) {
      dry = 1;
    } else if (strcmp(a, "-q") == 0 || strcmp(a, "--quiet") == 0) {
      cli->log_level = PX_LOG_LEVEL_WARN;
    } else if (a[0] == '-' && a[1]) {
      fprintf(stderr, "partix part3d: unknown option '%s' (see partix part3d --help)\n", a);
      return PX_CLI_EXIT_USAGE;
    } else if (p.file) {
      fprintf(stderr, "partix part3d: one part3d file at a time\n");
      return PX_CLI_EXIT_USAGE;
    } else {
      p.file = a;
    }
  }
  if (!p.file) {
    fprintf(stderr, "partix part3d: no part3d file given (see partix part3d --help)\n");
    return PX_CLI_EXIT_USAGE;
  }
  if (px_cli_launch_ranks() > 1) {
    fprintf(stderr,
            "partix part3d: runs its sections as local processes (--jobs J), not under "
            "mpirun; nothing was written\n");
    return PX_CLI_EXIT_USAGE;
  }
  struct px_context *ctx = px_cli_context(cli);
  if (!ctx) return PX_CLI_EXIT_FAILURE;
  p.log_level = cli->log_level;
  code = load(&p);
  if (!code) code = find_contour(&p, ctx);
  if (!code) code = cut(&p, ctx);
  if (!code && cli->log_level >= PX_LOG_LEVEL_INFO) print_sections(&p);
  if (!code && !dry && px_file_mkdirs(ctx, p.dir) != PX_STATUS_OK) code = PX_CLI_EXIT_FAILURE;
  if (!code && !dry && write_sections(&p, ctx) != PX_STATUS_OK) code = PX_CLI_EXIT_FAILURE;
  if (code == PX_CLI_EXIT_FAILURE) fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
  if (!code) code = make_sweep(&p, ctx, &s, dry);
  if (!code && dry) {
    for (size_t r = 0; r < s.nruns; ++r) {
      printf("%s/%s:", s.dir, s.runs[r].name);
      for (size_t k = 0; k < s.runs[r].noverrides; ++k) printf(" --set %s", s.runs[r].overrides[k]);
      printf("\n");
    }
  } else if (!code) {
    code = px_sweep_check(&s, ctx);
    if (!code) code = px_sweep_execute(&s, cli, ctx, jobs);
    /* the map from the sections that finished, unless stopped by Ctrl-C */
    if (code != PX_CLI_EXIT_USAGE && !px_sweep_interrupted()) {
      int finished[PX_PART3D_MAX_SECTIONS];
      for (size_t k = 0; k < s.nruns; ++k) finished[k] = strcmp(s.runs[k].status, "finished") == 0;
      const int m = px_part3d_map(&p, ctx, finished);
      if (!code) code = m;
    }
  }
  part3d_free(&p, ctx, &s);
  px_context_free(ctx);
  return code;
}
