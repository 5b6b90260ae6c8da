/* Reading a granular case into the run: contour pieces and shapes, contact
 * laws, the statistics keys, discs listed one by one (the bodies and their
 * motions: granular_bodies.c). Every failure names its key in the case
 * (px_case_fail). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/geometry/geo_dxf.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "solvers/granular/contact_kernel.h"
#include "solvers/granular/granular_case.h"
#include "solvers/granular/wall_kernel.h"

/* ------------------------------------------------------------------ helpers */

enum px_status px_gran_get_vec2(struct px_case *c, const char *base, const char *key, double v[2]) {
  char path[256];
  return px_case_get_vector(c, px_case_path_join(path, sizeof path, base, key), v, 2);
}

enum px_status px_gran_get_real(struct px_case *c, const char *base, const char *key, double *v) {
  char path[256];
  return px_case_get_real(c, px_case_path_join(path, sizeof path, base, key), v);
}

/* ------------------------------------------------------------------ geometry */

static enum px_status px_gran_piece(struct px_gran_run *r, const char *pp,
                                    struct px_geo_path *path) {
  struct px_case *c = r->c;
  struct px_geo_prim q;
  const char *type = NULL;
  char key[256];
  memset(&q, 0, sizeof q);
  PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, pp, "type"), &type));
  if (strcmp(type, "line") == 0) {
    double a[2], b[2];
    PX_TRY(px_gran_get_vec2(c, pp, "from", a));
    PX_TRY(px_gran_get_vec2(c, pp, "to", b));
    q.kind = PX_GEO_PRIM_LINE;
    q.p[0] = a[0], q.p[1] = a[1], q.p[2] = b[0], q.p[3] = b[1];
  } else if (strcmp(type, "arc") == 0) {
    double ctr[2], rad, a0, a1;
    PX_TRY(px_gran_get_vec2(c, pp, "center", ctr));
    PX_TRY(px_gran_get_real(c, pp, "radius", &rad));
    PX_TRY(px_gran_get_real(c, pp, "start", &a0));
    PX_TRY(px_gran_get_real(c, pp, "end", &a1));
    if (a0 == a1) return px_case_fail(c, pp, "start and end angles are equal");
    q.kind = PX_GEO_PRIM_ARC;
    q.p[0] = ctr[0], q.p[1] = ctr[1], q.p[2] = rad, q.p[3] = a0 * PX_GRAN_DEG,
    q.p[4] = a1 * PX_GRAN_DEG;
  } else if (strcmp(type, "ellipse_arc") == 0) {
    double ctr[2], ax[2], ang, a0, a1;
    PX_TRY(px_gran_get_vec2(c, pp, "center", ctr));
    PX_TRY(px_gran_get_vec2(c, pp, "axes", ax));
    PX_TRY(px_gran_get_real(c, pp, "angle", &ang));
    PX_TRY(px_gran_get_real(c, pp, "start", &a0));
    PX_TRY(px_gran_get_real(c, pp, "end", &a1));
    if (a0 == a1) return px_case_fail(c, pp, "start and end parameters are equal");
    q.kind = PX_GEO_PRIM_ELLIPSE;
    q.p[0] = ctr[0], q.p[1] = ctr[1], q.p[2] = ax[0], q.p[3] = ax[1], q.p[4] = ang * PX_GRAN_DEG;
    q.p[5] = a0 * PX_GRAN_DEG, q.p[6] = a1 * PX_GRAN_DEG;
  } else if (strcmp(type, "parabola") == 0) {
    double a[2], m[2], b[2];
    PX_TRY(px_gran_get_vec2(c, pp, "from", a));
    PX_TRY(px_gran_get_vec2(c, pp, "control", m));
    PX_TRY(px_gran_get_vec2(c, pp, "to", b));
    q.kind = PX_GEO_PRIM_BEZIER2;
    q.p[0] = a[0], q.p[1] = a[1], q.p[2] = m[0], q.p[3] = m[1], q.p[4] = b[0], q.p[5] = b[1];
  } else { /* polyline */
    size_t n, k;
    int smooth = 0;
    double *xy;
    enum px_status st = PX_STATUS_OK;
    PX_TRY(px_case_count(c, px_case_path_join(key, sizeof key, pp, "points"), &n));
    PX_TRY(px_case_get_bool(c, px_case_path_join(key, sizeof key, pp, "smooth"), &smooth));
    xy = px_mem_alloc(r->ctx, "granular geometry", 2 * n * sizeof *xy);
    if (!xy) return PX_STATUS_NOMEM;
    for (k = 0; k < n && st == PX_STATUS_OK; ++k) {
      char pk[512];
      if ((size_t)snprintf(pk, sizeof pk, "%.400s.points[%zu]", pp, k) >= sizeof pk) break;
      st = px_case_get_vector(c, pk, xy + 2 * k, 2);
    }
    if (st == PX_STATUS_OK) st = px_geo_path_add_points(r->ctx, path, xy, n, smooth);
    px_mem_free(r->ctx, xy);
    return st;
  }
  return px_geo_path_add(r->ctx, path, &q);
}

/* Largest extent of the contours together, in largest disc diameters:
 * beyond it the grids of the solver (neighbour cells, segment bins, the
 * lattice of the filling) would need more cells or rows than any run can
 * use, and a contour's units are surely wrong. */
#define PX_GRAN_SPAN_MAX 1e6

/* A geometry error (PX_STATUS_CONFIG, message in the context) as a case
 * error at `key`; the message's own "WHERE: " prefix is dropped when it
 * repeats the case location (`where`, a shape of the case file). */
static enum px_status px_gran_geom_fail(struct px_gran_run *r, const char *key, const char *where) {
  char msg[1024];
  const char *m = px_context_message(r->ctx);
  const size_t n = where ? strlen(where) : 0;
  if (n && strncmp(m, where, n) == 0 && m[n] == ':' && m[n + 1] == ' ') m += n + 2;
  snprintf(msg, sizeof msg, "%s", m);
  return px_case_fail(r->c, key, "%s", msg);
}

/* The shapes of a contour item. Each adds its path to r->geom at segment
 * length h [m]; *direct = 1 when a failure is the reading of the case, told
 * as it is, 0 when it is the geometry's, which the caller names by the
 * shape's place (px_gran_geom_fail). */

/* rectangle: min, max; polygon: points. */
static enum px_status px_gran_shape_polygon(struct px_gran_run *r, const char *sp, const char *type,
                                            struct px_geo_path *path, double h, const char *name,
                                            int body, enum px_gran_side sd, int *direct) {
  struct px_case *c = r->c;
  char key[256];
  enum px_status st = PX_STATUS_OK;
  double pts[8], *xy = pts;
  size_t n = 4, k;
  *direct = 1;
  if (type[0] == 'r') {
    double lo[2], hi[2];
    PX_TRY(px_gran_get_vec2(c, sp, "min", lo));
    PX_TRY(px_gran_get_vec2(c, sp, "max", hi));
    if (!(hi[0] > lo[0]) || !(hi[1] > lo[1]))
      return px_case_fail(c, sp, "max must exceed min in x and y");
    pts[0] = lo[0], pts[1] = lo[1], pts[2] = hi[0], pts[3] = lo[1];
    pts[4] = hi[0], pts[5] = hi[1], pts[6] = lo[0], pts[7] = hi[1];
  } else {
    PX_TRY(px_case_count(c, px_case_path_join(key, sizeof key, sp, "points"), &n));
    *direct = 0;
    xy = px_mem_alloc(r->ctx, "granular geometry", 2 * (n + 1) * sizeof *xy);
    if (!xy) return PX_STATUS_NOMEM;
    for (k = 0; k < n && st == PX_STATUS_OK; ++k) {
      char pk[400];
      snprintf(pk, sizeof pk, "%s.points[%zu]", sp, k);
      st = px_case_get_vector(c, pk, xy + 2 * k, 2);
    }
  }
  *direct = 0;
  for (k = 0; k < n && st == PX_STATUS_OK; ++k) {
    struct px_geo_prim q;
    memset(&q, 0, sizeof q);
    q.kind = PX_GEO_PRIM_LINE;
    q.p[0] = xy[2 * k], q.p[1] = xy[2 * k + 1];
    q.p[2] = xy[2 * ((k + 1) % n)], q.p[3] = xy[2 * ((k + 1) % n) + 1];
    if (q.p[0] == q.p[2] && q.p[1] == q.p[3]) continue; /* repeated corner */
    st = px_geo_path_add(r->ctx, path, &q);
  }
  if (xy != pts) px_mem_free(r->ctx, xy);
  if (st == PX_STATUS_OK)
    st = px_gran_geom_add_path(r->ctx, &r->geom, path, h, 1e-9, name, body, sd);
  return st;
}

/* circle: center, radius; ellipse: center, axes, angle [deg]. */
static enum px_status px_gran_shape_ellipse(struct px_gran_run *r, const char *sp, const char *type,
                                            struct px_geo_path *path, double h, const char *name,
                                            int body, enum px_gran_side sd, int *direct) {
  struct px_case *c = r->c;
  enum px_status st = PX_STATUS_OK;
  struct px_geo_prim q;
  double ctr[2], ax[2] = {0, 0}, ang = 0;
  *direct = 1;
  memset(&q, 0, sizeof q);
  PX_TRY(px_gran_get_vec2(c, sp, "center", ctr));
  if (type[0] == 'c') {
    PX_TRY(px_gran_get_real(c, sp, "radius", &ax[0]));
    ax[1] = ax[0];
  } else {
    PX_TRY(px_gran_get_vec2(c, sp, "axes", ax));
    PX_TRY(px_gran_get_real(c, sp, "angle", &ang));
  }
  *direct = 0;
  q.kind = PX_GEO_PRIM_ELLIPSE;
  q.p[0] = ctr[0], q.p[1] = ctr[1], q.p[2] = ax[0], q.p[3] = ax[1], q.p[4] = ang * PX_GRAN_DEG;
  q.p[5] = 0, q.p[6] = 2 * PX_GRAN_PI;
  if (type[0] == 'c') { /* a circle is exact as an arc */
    q.kind = PX_GEO_PRIM_ARC;
    q.p[2] = ax[0], q.p[3] = 0, q.p[4] = 2 * PX_GRAN_PI;
  }
  st = px_geo_path_add(r->ctx, path, &q);
  if (st == PX_STATUS_OK)
    st = px_gran_geom_add_path(r->ctx, &r->geom, path, h, 1e-9, name, body, sd);
  return st;
}

/* path: pieces (lines, arcs, ...) joined end to end. */
static enum px_status px_gran_shape_path(struct px_gran_run *r, const char *sp,
                                         struct px_geo_path *path, double h, const char *name,
                                         int body, enum px_gran_side sd, int *direct) {
  struct px_case *c = r->c;
  char key[256];
  enum px_status st = PX_STATUS_OK;
  size_t n, k;
  *direct = 1;
  PX_TRY(px_case_count(c, px_case_path_join(key, sizeof key, sp, "pieces"), &n));
  *direct = 0;
  for (k = 0; k < n && st == PX_STATUS_OK; ++k) {
    char pk[400];
    snprintf(pk, sizeof pk, "%s.pieces[%zu]", sp, k);
    st = px_gran_piece(r, pk, path);
  }
  if (st == PX_STATUS_OK) {
    /* pieces must join within a tiny fraction of the segment length */
    st = px_gran_geom_add_path(r->ctx, &r->geom, path, h, 1e-6 * h, name, body, sd);
  }
  return st;
}

/* The DXF reader's message on too many entities names the segments this
 * solver takes as its own limit. */
_Static_assert(PX_GEO_DXF_PIECES_MAX == PX_GRAN_SEG_MAX,
               "a DXF entity becomes at least one boundary segment");

/* dxf: the closed loops of a DXF file (one contour each), scaled and
 * shifted; on a failure of the file path is freed. */
static enum px_status px_gran_shape_dxf(struct px_gran_run *r, const char *sp,
                                        struct px_geo_path *path, double h, const char *name,
                                        int body, enum px_gran_side sd, int *direct) {
  struct px_case *c = r->c;
  char key[256];
  enum px_status st = PX_STATUS_OK;
  const char *layer = NULL;
  double scale = 1, off[2] = {0, 0}, tol = 1e-6;
  char resolved[4096];
  struct px_geo_path *paths = NULL;
  size_t np = 0, k;
  *direct = 1;
  if (px_case_input_path(c, px_case_path_join(key, sizeof key, sp, "file"), resolved,
                         sizeof resolved) != PX_STATUS_OK)
    return px_case_fail(c, key, "file name too long");
  PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, sp, "layer"), &layer));
  PX_TRY(px_gran_get_real(c, sp, "scale", &scale));
  PX_TRY(px_gran_get_vec2(c, sp, "offset", off));
  PX_TRY(px_gran_get_real(c, sp, "tolerance", &tol));
  st = px_geo_dxf_read(r->ctx, resolved, layer, scale, off[0], off[1], tol * scale, &paths, &np);
  if (st == PX_STATUS_OK && np > PX_GRAN_CONTOURS_MAX)
    st = px_context_fail(r->ctx, PX_STATUS_CONFIG,
                         "%s: %zu closed loops: more than the %d contours the solver takes",
                         resolved, np, PX_GRAN_CONTOURS_MAX);
  if (st != PX_STATUS_OK) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(r->ctx));
    px_geo_path_free(r->ctx, path);
    for (k = 0; k < np; ++k) px_geo_path_free(r->ctx, &paths[k]);
    px_mem_free(r->ctx, paths);
    if (st == PX_STATUS_NOMEM) return st;
    return px_case_fail(c, px_case_path_join(key, sizeof key, sp, "file"), "%s", msg);
  }
  *direct = 0;
  for (k = 0; k < np; ++k) {
    char nm[PX_GRAN_NAME_MAX];
    if (k == 0)
      snprintf(nm, sizeof nm, "%s", name);
    else
      snprintf(nm, sizeof nm, "%s.%zu", name, k + 1);
    if (st == PX_STATUS_OK)
      st = px_gran_geom_add_path(r->ctx, &r->geom, &paths[k], h, tol * scale, nm, body, sd);
    px_geo_path_free(r->ctx, &paths[k]);
  }
  px_mem_free(r->ctx, paths);
  return st;
}

/* 1 when contour names a and b are equal, or equal once every character
 * other than a letter or digit is read as '_' (as the summary.json keys
 * write them, px_gran_summary_part). */
static int px_gran_names_clash(const char *a, const char *b) {
  for (;; ++a, ++b) {
    const int wa = (*a >= 'a' && *a <= 'z') || (*a >= 'A' && *a <= 'Z') || (*a >= '0' && *a <= '9');
    const int wb = (*b >= 'a' && *b <= 'z') || (*b >= 'A' && *b <= 'Z') || (*b >= '0' && *b <= '9');
    if (!*a || !*b) return !*a && !*b;
    if (wa != wb || (wa && *a != *b)) return 0;
  }
}

/* Add the contour(s) of contour item `cp` (key path) to the geometry.
 * box: the contours' box so far [xmin, ymin, xmax, ymax] [m], grown by these;
 * their extent must stay within PX_GRAN_SPAN_MAX diameters (2 rmax [m]). */
enum px_status px_gran_contour(struct px_gran_run *r, const char *cp, double h, double rmax,
                               double box[4]) {
  struct px_case *c = r->c;
  const char *name = NULL, *bodyname = NULL, *type = NULL;
  char key[256], sp[256];
  int side = 0, report = 1, body = -1;
  size_t b, first = r->geom.ncontours;
  enum px_gran_side sd;
  enum px_status st = PX_STATUS_OK;
  struct px_geo_path path;
  PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, cp, "name"), &name));
  PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, cp, "body"), &bodyname));
  PX_TRY(px_case_get_enum(c, px_case_path_join(key, sizeof key, cp, "side"), &side));
  PX_TRY(px_case_get_bool(c, px_case_path_join(key, sizeof key, cp, "report"), &report));
  for (b = 0; b < r->nbodies; ++b)
    if (strcmp(r->bodies[b].name, bodyname) == 0) body = (int)b;
  if (body < 0) {
    char list[512] = "";
    for (b = 0; b < r->nbodies; ++b) {
      strncat(list, b ? ", " : "", sizeof list - strlen(list) - 1);
      strncat(list, r->bodies[b].name, sizeof list - strlen(list) - 1);
    }
    return px_case_fail(c, px_case_path_join(key, sizeof key, cp, "body"),
                        "no body named '%s' (bodies: %s)", bodyname, list);
  }
  sd = side == 1 ? PX_GRAN_SIDE_INSIDE : side == 2 ? PX_GRAN_SIDE_OUTSIDE : PX_GRAN_SIDE_AUTO;
  px_case_path_join(sp, sizeof sp, cp, "shape");
  PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, sp, "type"), &type));
  {
    char where[600];
    snprintf(where, sizeof where, "%s: %s", px_case_file(c) ? px_case_file(c) : "case", sp);
    px_geo_path_init(&path, where);
  }
  {
    int direct = 1;
    if (strcmp(type, "rectangle") == 0 || strcmp(type, "polygon") == 0)
      st = px_gran_shape_polygon(r, sp, type, &path, h, name, body, sd, &direct);
    else if (strcmp(type, "circle") == 0 || strcmp(type, "ellipse") == 0)
      st = px_gran_shape_ellipse(r, sp, type, &path, h, name, body, sd, &direct);
    else if (strcmp(type, "path") == 0)
      st = px_gran_shape_path(r, sp, &path, h, name, body, sd, &direct);
    else
      st = px_gran_shape_dxf(r, sp, &path, h, name, body, sd, &direct);
    if (st != PX_STATUS_OK && direct) return st;
  }
  if (st == PX_STATUS_CONFIG) st = px_gran_geom_fail(r, sp, path.where);
  px_geo_path_free(r->ctx, &path);
  PX_TRY(st);
  /* a contour's name makes its file (segments_NAME.csv), its media.csv
   * columns and its summary.json keys (NAME.impacts, with '.' and '-' as
   * '_'): two names equal there would write over each other. Checked on the
   * names made (a DXF shape's further loops are NAME.2, NAME.3, ...) */
  for (b = first; b < r->geom.ncontours; ++b) {
    const char *nb = r->geom.contours[b].name;
    size_t d;
    for (d = 0; d < b; ++d) {
      const char *nd = r->geom.contours[d].name;
      if (!px_gran_names_clash(nd, nb)) continue;
      if (strcmp(nd, nb) == 0)
        return px_case_fail(c, px_case_path_join(key, sizeof key, cp, "name"),
                            "a contour named '%s' already exists%s: each contour writes its own "
                            "segments_NAME.csv, media.csv columns and summary.json entries, "
                            "which two of one name would overwrite",
                            nb, b > first ? " (a further loop of this DXF shape)" : "");
      return px_case_fail(c, px_case_path_join(key, sizeof key, cp, "name"),
                          "contour '%s'%s and contour '%s' give the same summary.json keys "
                          "('.' and '-' become '_' there): one would overwrite the other's",
                          nb, b > first ? " (a further loop of this DXF shape)" : "", nd);
    }
  }
  /* the extent of all contours so far, in disc diameters */
  for (b = first; b < r->geom.ncontours; ++b) {
    const struct px_gran_contour *C = &r->geom.contours[b];
    size_t k;
    for (k = C->first; k < C->first + C->count; ++k) {
      box[0] = fmin(box[0], r->geom.ax[k]), box[2] = fmax(box[2], r->geom.ax[k]);
      box[1] = fmin(box[1], r->geom.ay[k]), box[3] = fmax(box[3], r->geom.ay[k]);
    }
    if (!((box[2] - box[0]) / (2 * rmax) <= PX_GRAN_SPAN_MAX) ||
        !((box[3] - box[1]) / (2 * rmax) <= PX_GRAN_SPAN_MAX))
      return px_case_fail(c, sp,
                          "contour '%s' makes the contours span %.4g m x %.4g m: more than %.0e "
                          "diameters (%g m) of the largest disc; check the units of the shape",
                          C->name, box[2] - box[0], box[3] - box[1], PX_GRAN_SPAN_MAX, 2 * rmax);
  }
  {
    int *rep =
        px_mem_realloc(r->ctx, "granular geometry", r->report, r->geom.ncontours * sizeof *rep);
    if (!rep) return PX_STATUS_NOMEM;
    r->report = rep;
    for (b = first; b < r->geom.ncontours; ++b) rep[b] = report;
  }
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ laws */

enum px_status px_gran_law(struct px_gran_run *r, const char *base,
                           const struct px_gran_law_spec *inherit, struct px_gran_law_spec *L) {
  struct px_case *c = r->c;
  char key[160];
  int model = 0, tang = 0, clamp = 0;
  double rs = 2.25;
  if (inherit)
    *L = *inherit;
  else
    memset(L, 0, sizeof *L);
#define PX_GRAN_HAS(k) px_case_has(c, px_case_path_join(key, sizeof key, base, k))
  if (PX_GRAN_HAS("model")) {
    PX_TRY(px_case_get_enum(c, key, &model));
    L->normal = model == 1 ? PX_GRAN_NORMAL_HYSTERETIC : PX_GRAN_NORMAL_LINEAR;
  }
  if (PX_GRAN_HAS("kn")) PX_TRY(px_case_get_real(c, key, &L->kn));
  if (PX_GRAN_HAS("restitution")) PX_TRY(px_case_get_real(c, key, &L->e));
  if (PX_GRAN_HAS("k2")) PX_TRY(px_case_get_real(c, key, &L->k2));
  if (PX_GRAN_HAS("phi_f")) PX_TRY(px_case_get_real(c, key, &L->phif));
  if (PX_GRAN_HAS("damping")) PX_TRY(px_case_get_real(c, key, &L->damping));
  if (PX_GRAN_HAS("tangential")) {
    PX_TRY(px_case_get_enum(c, key, &tang));
    L->tangential = tang == 0   ? PX_GRAN_TANGENTIAL_SPRING
                    : tang == 1 ? PX_GRAN_TANGENTIAL_VISCOUS
                                : PX_GRAN_TANGENTIAL_NONE;
  }
  if (PX_GRAN_HAS("friction")) PX_TRY(px_case_get_real(c, key, &L->mu));
  if (PX_GRAN_HAS("kt_ratio")) PX_TRY(px_case_get_real(c, key, &L->kt_ratio));
  if (PX_GRAN_HAS("ct_ratio")) PX_TRY(px_case_get_real(c, key, &L->ct_ratio));
  if (PX_GRAN_HAS("viscous")) PX_TRY(px_case_get_real(c, key, &L->gt));
  if (PX_GRAN_HAS("rolling_friction")) PX_TRY(px_case_get_real(c, key, &L->mur));
  if (PX_GRAN_HAS("rolling_stiffness")) {
    PX_TRY(px_case_get_real(c, key, &rs));
    L->kr = rs * L->mur * L->mur;
  } else if (!inherit) {
    L->kr = rs * L->mur * L->mur;
  }
  if (PX_GRAN_HAS("no_attraction")) {
    PX_TRY(px_case_get_bool(c, key, &clamp));
    L->clamp = clamp;
  }
#undef PX_GRAN_HAS
  if (L->tangential == PX_GRAN_TANGENTIAL_VISCOUS && !(L->gt > 0) && L->mu > 0)
    return px_case_fail(c, base,
                        "tangential: viscous needs `viscous` > 0 (the coefficient "
                        "[N s/m] of the viscous friction)");
  if (L->normal == PX_GRAN_NORMAL_HYSTERETIC && L->k2 > 0 && L->k2 < L->kn)
    return px_case_fail(c, base,
                        "k2 = %g must be >= kn = %g (unloading is stiffer than "
                        "loading)",
                        L->k2, L->kn);
  return PX_STATUS_OK;
}

/* ------------------------------------------------------------------ create */

/* The key of a law's parameter into key[96]: granular.wall_contact.NAME
 * when `wall` and the wall law gives it, granular.contact.NAME otherwise
 * (the wall law inherits it). Returns key. */
const char *px_gran_law_key(const struct px_case *c, int wall, const char *name, char key[96]) {
  snprintf(key, 96, "granular.wall_contact.%.40s", name);
  if (wall && px_case_has(c, key)) return key;
  snprintf(key, 96, "granular.contact.%.40s", name);
  return key;
}

/* Statistics keys into the run. */
enum px_status px_gran_stats_config(struct px_gran_run *r) {
  struct px_case *c = r->c;
  double start;
  int energy = 0, log = 0;
  long bins = 40;
  const char *pic = NULL;
  const char *fnames[2] = {"granular.statistics.hardening", "granular.statistics.residual_stress"};
  struct px_gran_fn *fns[2] = {&r->hardening, &r->residual};
  char *units[2] = {r->hard_unit, r->res_unit};
  int k;
  memset(&r->sspec, 0, sizeof r->sspec);
  PX_TRY(px_case_get_real(c, "granular.statistics.start", &start));
  r->sspec.start = start < 0 ? r->settle : start;
  PX_TRY(px_case_get_real(c, "granular.statistics.impact_velocity_min", &r->sspec.vmin));
  PX_TRY(px_case_get_real(c, "granular.statistics.archard.k", &r->sspec.archard_k));
  PX_TRY(px_case_get_real(c, "granular.statistics.archard.hardness", &r->sspec.hardness));
  PX_TRY(px_case_get_real(c, "granular.statistics.finnie.k", &r->sspec.finnie_k));
  PX_TRY(px_case_get_real(c, "granular.statistics.finnie.exponent", &r->sspec.finnie_n));
  PX_TRY(px_case_get_enum(c, "granular.statistics.energy", &energy));
  r->energy_total = energy == 1;
  PX_TRY(px_case_get_string(c, "granular.statistics.picture", &pic));
  snprintf(r->picture_quantity, sizeof r->picture_quantity, "%s", pic);
  PX_TRY(px_case_get_real(c, "granular.statistics.speed_max", &r->speed_max));
  PX_TRY(px_case_get_int(c, "granular.statistics.bins", &bins));
  r->bins = (int)bins;
  PX_TRY(px_case_get_bool(c, "granular.statistics.impact_log", &log));
  r->impact_log = log;
  for (k = 0; k < 2; ++k) {
    char key[160];
    const char *unit = NULL;
    const int has_e = px_case_has(c, px_case_path_join(key, sizeof key, fnames[k], "expression"));
    const int has_t = px_case_has(c, px_case_path_join(key, sizeof key, fnames[k], "table"));
    PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, fnames[k], "unit"), &unit));
    snprintf(units[k], 32, "%s", unit);
    if (has_e && has_t)
      return px_case_fail(c, fnames[k], "give either `expression` or `table`, not both");
    if (has_e) {
      const char *text;
      enum px_status st;
      PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, fnames[k], "expression"),
                                &text));
      st = px_gran_fn_compile(r->ctx, fns[k], text, "E");
      if (st != PX_STATUS_OK) {
        char msg[512];
        snprintf(msg, sizeof msg, "%s", px_context_message(r->ctx));
        return px_case_fail(c, key, "%s", msg);
      }
    } else if (has_t) {
      size_t n, i;
      double *tx, *ty;
      enum px_status st = PX_STATUS_OK;
      PX_TRY(px_case_count(c, px_case_path_join(key, sizeof key, fnames[k], "table"), &n));
      tx = px_mem_alloc(r->ctx, "granular table", (n + 1) * sizeof *tx);
      ty = px_mem_alloc(r->ctx, "granular table", (n + 1) * sizeof *ty);
      if (!tx || !ty) {
        px_mem_free(r->ctx, tx);
        px_mem_free(r->ctx, ty);
        return PX_STATUS_NOMEM;
      }
      for (i = 0; i < n && st == PX_STATUS_OK; ++i) {
        char rk[200];
        double row[2];
        snprintf(rk, sizeof rk, "%s.table[%zu]", fnames[k], i);
        st = px_case_get_vector(c, rk, row, 2);
        tx[i] = row[0], ty[i] = row[1];
      }
      if (st == PX_STATUS_OK) {
        st = px_gran_fn_table(r->ctx, fns[k], tx, ty, n);
        if (st == PX_STATUS_CONFIG) {
          char msg[512];
          snprintf(msg, sizeof msg, "%s", px_context_message(r->ctx));
          st = px_case_fail(c, key, "%s", msg);
        }
      }
      px_mem_free(r->ctx, tx);
      px_mem_free(r->ctx, ty);
      PX_TRY(st);
    }
  }
  return PX_STATUS_OK;
}

/* A failure of the system's checks (CONFIG) becomes a case error at path. */
enum px_status px_gran_as_case(struct px_gran_run *r, enum px_status st, const char *path) {
  if (st == PX_STATUS_CONFIG) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(r->ctx));
    return px_case_fail(r->c, path, "%s", msg);
  }
  return st;
}

/* Discs placed one by one (granular.media.particles): rows [x, y, r] with
 * optional [vx, vy] and w. Owned arrays x, y, r (n) and v (3 n: vx, vy, w). */
enum px_status px_gran_read_particles(struct px_gran_run *r, double **x, double **y, double **rad,
                                      double **v, size_t *n) {
  struct px_case *c = r->c;
  size_t k, np = 0;
  PX_TRY(px_case_count(c, "granular.media.particles", &np));
  *x = px_mem_alloc(r->ctx, "granular media", np * sizeof **x);
  *y = px_mem_alloc(r->ctx, "granular media", np * sizeof **y);
  *rad = px_mem_alloc(r->ctx, "granular media", np * sizeof **rad);
  *v = px_mem_calloc(r->ctx, "granular media", 3 * np, sizeof **v);
  if (!*x || !*y || !*rad || !*v) return PX_STATUS_NOMEM;
  for (k = 0; k < np; ++k) {
    char key[96];
    double row[6] = {0, 0, 0, 0, 0, 0};
    size_t nc = 0, j;
    snprintf(key, sizeof key, "granular.media.particles[%zu]", k);
    PX_TRY(px_case_count(c, key, &nc));
    PX_TRY(px_case_get_vector(c, key, row, nc));
    if (nc == 4)
      return px_case_fail(c, key,
                          "a particle is [x, y, r], [x, y, r, vx, vy] or "
                          "[x, y, r, vx, vy, w], not 4 numbers");
    for (j = 0; j < nc; ++j)
      if (!isfinite(row[j])) return px_case_fail(c, key, "value %zu is not finite", j + 1);
    if (!(row[2] > 0)) return px_case_fail(c, key, "radius %g: must be > 0", row[2]);
    if (!(fabs(row[0]) <= PX_GRAN_COORD_MAX) || !(fabs(row[1]) <= PX_GRAN_COORD_MAX) ||
        !(row[2] <= PX_GRAN_COORD_MAX))
      return px_case_fail(c, key, "position (%g, %g) or radius %g beyond %g m", row[0], row[1],
                          row[2], PX_GRAN_COORD_MAX);
    (*x)[k] = row[0], (*y)[k] = row[1], (*rad)[k] = row[2];
    (*v)[3 * k] = row[3], (*v)[3 * k + 1] = row[4], (*v)[3 * k + 2] = row[5];
  }
  *n = np;
  return PX_STATUS_OK;
}

/* Discs listed one by one must not overlap (tolerance as px_gran_sys_prepare,
 * which checks again): checked here on a grid of cells of the largest
 * diameter, stopping at the first overlap, so that discs piled on one spot
 * are refused at their row before the neighbour list would list every pair
 * of them. */
enum px_status px_gran_listed_overlaps(struct px_gran_run *r, const double *x, const double *y,
                                       const double *rad, size_t n) {
  double xmin = DBL_MAX, ymin = DBL_MAX, xmax = -DBL_MAX, ymax = -DBL_MAX, rmax = 0, h;
  size_t k, nx, ny;
  int32_t *head = NULL, *next = NULL;
  enum px_status st = PX_STATUS_OK;
  if (n < 2) return PX_STATUS_OK;
  for (k = 0; k < n; ++k) {
    xmin = fmin(xmin, x[k]), xmax = fmax(xmax, x[k]);
    ymin = fmin(ymin, y[k]), ymax = fmax(ymax, y[k]);
    rmax = fmax(rmax, rad[k]);
  }
  h = 2 * rmax;
  while (!(((xmax - xmin) / h + 1) * ((ymax - ymin) / h + 1) <= 4.0 * (double)n + 1024)) h *= 2;
  nx = (size_t)((xmax - xmin) / h) + 1;
  ny = (size_t)((ymax - ymin) / h) + 1;
  head = px_mem_alloc(r->ctx, "granular media", nx * ny * sizeof *head);
  next = px_mem_alloc(r->ctx, "granular media", n * sizeof *next);
  if (!head || !next) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  for (k = 0; k < nx * ny; ++k) head[k] = -1;
  for (k = 0; k < n && st == PX_STATUS_OK; ++k) {
    size_t i = (size_t)((x[k] - xmin) / h), j = (size_t)((y[k] - ymin) / h), a, b;
    if (i >= nx) i = nx - 1;
    if (j >= ny) j = ny - 1;
    for (b = j ? j - 1 : 0; b <= j + 1 && b < ny && st == PX_STATUS_OK; ++b)
      for (a = i ? i - 1 : 0; a <= i + 1 && a < nx && st == PX_STATUS_OK; ++a) {
        int32_t q;
        for (q = head[b * nx + a]; q >= 0; q = next[q]) {
          const double d = hypot(x[k] - x[q], y[k] - y[q]);
          if (d < (rad[k] + rad[q]) * (1 - 1e-6)) {
            char key[96];
            snprintf(key, sizeof key, "granular.media.particles[%zu]", k);
            st = px_case_fail(r->c, key,
                              "particles %d at (%g, %g) and %zu at (%g, %g) overlap by %g m at "
                              "the start (radii %g and %g)",
                              (int)q, x[q], y[q], k, x[k], y[k], rad[k] + rad[q] - d, rad[q],
                              rad[k]);
            break;
          }
        }
      }
    next[k] = head[j * nx + i];
    head[j * nx + i] = (int32_t)k;
  }
done:
  px_mem_free(r->ctx, head);
  px_mem_free(r->ctx, next);
  return st;
}
