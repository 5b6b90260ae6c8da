/* partix part3d PART.yaml: a 3D part from its cross-sections.
 *
 *   case: rib_section.yaml    the 2D granular case (container, media, motion),
 *                             relative to this file; its contour `contour`
 *                             (a dxf shape) is replaced by each section
 *   mesh: rib.stl             the part's closed surface (STL or OBJ)
 *   units: 0.001              metres per mesh unit (default 1; 1e-9 to 1e3)
 *   normal: [0, 0, 1]         the sections' normal
 *   vibration: [1, 0, 0]      the vibration direction: the sections' x axis
 *   center: [0.08, 0.07]      [m] where the part's centre goes in the case
 *   sections: 7               K planes evenly spaced across the part, or a
 *                             list of offsets n . p [m]
 *   contour: part             (default part)
 *   dir: out/rib              (default out/<file name>)
 *   set: {backend.threads: 1} overrides of every section's run
 *
 * The mesh is read, checked closed and manifold (turned outward when it
 * faces inward) and cut into the sections' contours; each section must fit
 * in the case's container (part3d_fit.c) with at most PX_PART3D_MAX_POINTS
 * points (DIR/contours/section-K.dxf, DIR/sections.csv, DIR/sections.png:
 * part3d_sections.c);
 * the K runs go through partix sweep's machinery (DIR/sections/K, one
 * folder each, resumable: running the command again skips finished runs and
 * resumes interrupted ones, each only while its recorded fingerprint,
 * DIR/sections/K.fingerprint, is its section's now); the runs' statistics
 * are then mapped onto the mesh (part3d_map.c). */
#include "cli/part3d.h"

#include <errno.h>
#include <libfyaml.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/sweep.h"
#include "io/geometry/geo_dxf.h"
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

/* The node of a top-level key of the part3d file, or the file's root when
 * it is not given (fail() then points at the file's first key). */
static struct fy_node *key_node(const struct px_part3d *p, const char *key) {
  struct fy_node *root = fy_document_root(p->doc);
  struct fy_node *n = root ? fy_node_mapping_lookup_by_string(root, key, FY_NT) : NULL;
  return n ? n : root;
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
  if (!n) return fail(p, root, "sections: required (a count, or a list of offsets n . p [m])");
  if (fy_node_is_scalar(n)) {
    if (!real(scalar(n), &x) || x != floor(x) || x < 1 || x > PX_PART3D_MAX_SECTIONS)
      return fail(p, n, "sections: a count from 1 to %d, or a list of offsets n . p [m]",
                  PX_PART3D_MAX_SECTIONS);
    p->nsec = (size_t)x;
    for (size_t k = 0; k < p->nsec; ++k) p->offset[k] = NAN; /* spread over the part later */
    return 0;
  }
  const int m = fy_node_is_sequence(n) ? fy_node_sequence_item_count(n) : 0;
  if (m < 1 || m > PX_PART3D_MAX_SECTIONS)
    return fail(p, n, "sections: a count, or a list of 1 to %d offsets n . p [m]",
                PX_PART3D_MAX_SECTIONS);
  for (int k = 0; k < m; ++k) {
    struct fy_node *it = fy_node_sequence_get_by_index(n, k);
    if (!real(scalar(it), &p->offset[k]) || (k && !(p->offset[k] > p->offset[k - 1])))
      return fail(p, it, "sections: offsets n . p are increasing numbers [m]");
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
  if (n && (!real(scalar(n), &p->units) ||
            !(p->units >= PX_PART3D_UNITS_MIN && p->units <= PX_PART3D_UNITS_MAX)))
    return fail(p, n,
                "units: '%s' is not metres per mesh unit from %g (a mesh in nanometres) to %g "
                "(in kilometres): 0.001 for millimetres, 0.0254 for inches",
                scalar(n) ? scalar(n) : "?", PX_PART3D_UNITS_MIN, PX_PART3D_UNITS_MAX);
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
  /* the contours a section must lie in (the container) */
  if (!code) code = px_part3d_regions(p, ctx, c);
  px_case_free(c);
  return code;
}

/* "units: ..." at the units key, or at the mesh key when units is not
 * given, saying so. */
static const char *units_said(const struct px_part3d *p, struct fy_node **n) {
  struct fy_node *root = fy_document_root(p->doc);
  *n = fy_node_mapping_lookup_by_string(root, "units", FY_NT);
  if (*n) return "units";
  *n = key_node(p, "mesh");
  return "units (not given: 1 m per mesh unit)";
}

/* Every section fits in the 2D case: inside a contour of the case that may
 * hold media (the container: a part outside it, or larger than it, would
 * "finish" without a single impact), and with at most PX_PART3D_MAX_POINTS
 * contour points at the case's segment length. lo, hi: the part's bounding
 * box [m]. */
static int check_sections(struct px_part3d *p, const double lo[3], const double hi[3]) {
  struct fy_node *un;
  const char *units = units_said(p, &un);
  for (size_t k = 0; k < p->nsec; ++k) {
    double a[2] = {HUGE_VAL, HUGE_VAL}, b[2] = {-HUGE_VAL, -HUGE_VAL}; /* placed [m] */
    for (size_t l = 0; l < p->nloops[k]; ++l)
      for (size_t i = 0; i < p->loops[k][l].n; ++i) {
        const double x = p->loops[k][l].x[i] - p->cu + p->center[0];
        const double y = p->loops[k][l].y[i] - p->cv + p->center[1];
        a[0] = fmin(a[0], x), b[0] = fmax(b[0], x);
        a[1] = fmin(a[1], y), b[1] = fmax(b[1], y);
      }
    if (p->part_inside || !p->nregions || px_part3d_container(p, k)) continue;
    /* the container named: the largest of the regions */
    const struct px_part3d_region *r = &p->regions[0];
    for (size_t i = 1; i < p->nregions; ++i)
      if ((p->regions[i].hi[0] - p->regions[i].lo[0]) *
              (p->regions[i].hi[1] - p->regions[i].lo[1]) >
          (r->hi[0] - r->lo[0]) * (r->hi[1] - r->lo[1]))
        r = &p->regions[i];
    if (b[0] - a[0] > r->hi[0] - r->lo[0] || b[1] - a[1] > r->hi[1] - r->lo[1])
      return fail(p, un,
                  "%s: section %zu (at %g m) is %.4g m x %.4g m in the 2D case, larger than its "
                  "container '%s' (%.4g m x %.4g m): at %g m per mesh unit the part measures "
                  "%.4g m x %.4g m x %.4g m; give units the metres of one mesh unit (0.001 for "
                  "millimetres)",
                  units, k + 1, p->offset[k], b[0] - a[0], b[1] - a[1], r->name,
                  r->hi[0] - r->lo[0], r->hi[1] - r->lo[1], p->units, hi[0] - lo[0], hi[1] - lo[1],
                  hi[2] - lo[2]);
    return fail(p, key_node(p, "center"),
                "center: section %zu (at %g m) spans x %.4g to %.4g m, y %.4g to %.4g m in the 2D "
                "case: not inside its container '%s' (x %.4g to %.4g m, y %.4g to %.4g m), so no "
                "media would reach it; center [%g, %g] puts the part's centre there, choose one "
                "where the whole part fits in the container",
                k + 1, p->offset[k], a[0], b[0], a[1], b[1], r->name, r->lo[0], r->hi[0], r->lo[1],
                r->hi[1], p->center[0], p->center[1]);
  }
  for (size_t k = 0; k < p->nsec; ++k) {
    double points = 0, around = 0;
    for (size_t l = 0; l < p->nloops[k]; ++l) {
      const double m = px_part3d_resample(&p->loops[k][l], p->spacing, 0, NULL, NULL);
      if (m < 0) {
        fprintf(stderr, "partix part3d: out of memory resampling section %zu\n", k + 1);
        return PX_CLI_EXIT_FAILURE;
      }
      points += m;
      around += px_geo_polyline_perimeter(&p->loops[k][l]);
    }
    if (points <= PX_PART3D_MAX_POINTS) continue;
    /* in its container, the part is of a sane size: the segments are too short */
    const int fits = !p->part_inside && p->nregions;
    size_t i = 0;
    while (i < p->nset && strcmp(p->set_key[i], "granular.segment_length") != 0) ++i;
    return fail(p,
                !fits         ? un
                : i < p->nset ? key_node(p, "set")
                              : key_node(p, "case"),
                "%s: section %zu (at %g m): its contour, %.4g m around, would take %.4g points "
                "at the 2D case's segment length %g m: more than the %d a section may have "
                "(each starts a boundary segment of the 2D case, and the granular solver takes "
                "at most %d; the contour's file alone would be some %.3g MB); check %s",
                !fits         ? units
                : i < p->nset ? "set"
                              : "case",
                k + 1, p->offset[k], around, points, p->spacing, PX_PART3D_MAX_POINTS,
                PX_PART3D_MAX_POINTS, 50e-6 * points,
                !fits ? "units (the metres of one mesh unit) and the case's "
                        "granular.segment_length (by default its smallest disc radius)"
                      : "the case's granular.segment_length (by default its smallest disc radius)");
  }
  return 0;
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
  for (int i = 0; i < 3; ++i)
    if (!(isfinite(lo[i]) && isfinite(hi[i])))
      return fail(p, key_node(p, "units"),
                  "units: %g m per mesh unit makes the part's coordinates overflow", p->units);
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
  return check_sections(p, lo, hi);
bad:
  fprintf(stderr, "%s: %s\n", p->file, px_context_message(ctx));
  return PX_CLI_EXIT_USAGE;
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
      "A section's run is reused only while the file defines the section as it did\n"
      "(DIR/sections/K.fingerprint); after an edit the study is refused, naming the\n"
      "folders to remove (partix removes none).\n"
      "--dry-run cuts and checks the sections and lists the runs, running nothing.\n"
      "The part3d file (docs/part3d.md):\n\n"
      "  case: CASE.yaml          the 2D case; its contour CONTOUR (a dxf shape) is replaced\n"
      "  mesh: PART.stl           the part's surface (.stl ASCII or binary, .obj)\n"
      "  units: 0.001             metres per mesh unit (default 1; 1e-9 to 1e3)\n"
      "  normal: [0, 0, 1]        the sections' normal\n"
      "  vibration: [1, 0, 0]     the vibration direction: the sections' x axis\n"
      "  center: [X, Y]           [m] where the part's centre goes in the 2D case\n"
      "  sections: K              K planes evenly spaced, or a list of offsets [m]\n"
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
  px_part3d_regions_free(p);
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
  if (!code) code = px_part3d_make_sweep(&p, ctx, &s);
  /* nothing written before here: a study refused leaves the folder as it was */
  if (!code) code = px_part3d_check_reuse(&p, &s);
  if (!code && !dry) {
    if (px_file_mkdirs(ctx, p.dir) != PX_STATUS_OK ||
        px_part3d_write_sections(&p, ctx) != PX_STATUS_OK) {
      fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
      code = PX_CLI_EXIT_FAILURE;
    }
    if (!code) code = px_part3d_write_contours(&p, ctx, &s);
  }
  if (!code && dry) {
    for (size_t r = 0; r < s.nruns; ++r) {
      printf("%s/%s:", s.dir, s.runs[r].name);
      for (size_t k = 0; k < s.runs[r].noverrides; ++k) printf(" --set %s", s.runs[r].overrides[k]);
      printf("\n");
    }
  } else if (!code) {
    code = px_sweep_check(&s, ctx);
    if (!code) code = px_part3d_write_records(&p, ctx, &s);
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
