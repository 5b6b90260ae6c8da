/* partix part3d, the sections' files and runs: each section's contour
 * resampled at the case's segment length and written as
 * DIR/contours/section-K.dxf, DIR/sections.csv and sections.png, the sweep
 * of the K section runs with each section's fingerprint, and the records
 * (DIR/sections/K.fingerprint) that decide whether a run's folder is
 * reused (part3d.c). */
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/part3d.h"
#include "cli/sweep.h"
#include "core/text.h"
#include "io/mesh_view.h"
#include "partix/partix.h"

/* The loop q resampled for the 2D case: its corners (a turn of more than
 * 25 degrees) kept, every stretch between two corners cut into pieces of
 * equal length close to h. A faceted curve keeps its shape (the points lie
 * on its facets) while the facets' own spacing, often much finer near an
 * edge, no longer sets the granular segments (a segment much shorter than
 * the others collects the same impacts per unit area over too small a length
 * to be meaningful). A loop that would get fewer than 3 points (shorter than
 * a few h) keeps its own vertices. Returns the number of points as a double
 * (for a loop far longer than h it may exceed any count, or be infinite or
 * NaN: compared with max before anything is allocated), -1 when out of
 * memory; when it is at most max and x is not NULL, *x, *y (malloc) get the
 * points. */
double px_part3d_resample(const struct px_geo_polyline *q, double h, double max, double **x,
                          double **y) {
  const size_t n = q->n;
  size_t *corner = malloc((n + 1) * sizeof *corner), nc = 0, m = 0;
  double total = 0;
  int own = 0; /* the loop's own vertices */
  if (x) *x = *y = NULL;
  if (!corner) return -1;
  for (size_t i = 0; i < n; ++i) {
    const size_t a = (i + n - 1) % n, b = (i + 1) % n;
    const double ux = q->x[i] - q->x[a], uy = q->y[i] - q->y[a];
    const double vx = q->x[b] - q->x[i], vy = q->y[b] - q->y[i];
    const double turn = fabs(atan2(ux * vy - uy * vx, ux * vx + uy * vy));
    if (turn > 25.0 * 3.14159265358979323846 / 180) corner[nc++] = i;
  }
  if (!nc) corner[nc++] = 0;
  /* pass 0 counts the points, pass 1 places them */
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) {
      if (!x || !(total <= max)) break;
      *x = malloc(((size_t)total + 1) * sizeof **x);
      *y = malloc(((size_t)total + 1) * sizeof **y);
      if (!*x || !*y) {
        free(*x);
        free(*y);
        *x = *y = NULL;
        total = -1;
        break;
      }
      if (own) {
        memcpy(*x, q->x, n * sizeof **x);
        memcpy(*y, q->y, n * sizeof **y);
        break;
      }
    }
    for (size_t j = 0; j < nc; ++j) {
      const size_t a = corner[j], b = corner[(j + 1) % nc];
      const size_t len = (b + n - a) % n ? (b + n - a) % n : n; /* edges in the stretch */
      double L = 0;
      for (size_t e = 0; e < len; ++e) {
        const size_t i = (a + e) % n, k = (i + 1) % n;
        L += hypot(q->x[k] - q->x[i], q->y[k] - q->y[i]);
      }
      const double pieces = L / h < 1.5 ? 1 : round(L / h);
      if (pass == 0) {
        total += pieces;
        continue;
      }
      /* walk the stretch, a point at every L / pieces of arc length */
      size_t e = 0;
      double s0 = 0; /* arc length at the start of edge e */
      for (size_t k = 0; k < (size_t)pieces; ++k) {
        const double s = L * (double)k / pieces;
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
    if (pass == 0 && total < 3) { /* too short for 3 points at h: its own vertices */
      own = 1;
      total = (double)n;
    }
  }
  free(corner);
  return total;
}

/* Where a section's DXF text goes: a file (or none) and the hash of it. */
struct sink {
  FILE *o;
  uint64_t h;
};

static void emit(struct sink *s, const char *fmt, ...) PX_PRINTF(2, 3);
static void emit(struct sink *s, const char *fmt, ...) {
  char buf[256];
  va_list ap;
  va_start(ap, fmt);
  const int n = vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  const size_t len = n < 0 ? 0 : (size_t)n < sizeof buf ? (size_t)n : sizeof buf - 1;
  s->h = px_text_fnv1a(s->h, buf, len);
  if (s->o) fwrite(buf, 1, len, s->o);
}

/* Section k's loops as DXF entities, placed in the case (outer boundaries
 * first: the contour's name goes to the first loop), to s: what
 * DIR/contours/section-K.dxf holds after its comment. */
static enum px_status dxf_entities(struct px_part3d *p, struct px_context *ctx, size_t k,
                                   struct sink *s) {
  emit(s, "0\nSECTION\n2\nENTITIES\n");
  for (int outer = 1; outer >= 0; --outer)
    for (size_t l = 0; l < p->nloops[k]; ++l) {
      const struct px_geo_polyline *q = &p->loops[k][l];
      if ((px_geo_polyline_area(q) > 0) != outer) continue;
      double *x, *y;
      const double m = px_part3d_resample(q, p->spacing, PX_PART3D_MAX_POINTS, &x, &y);
      if (!x) /* cut() refused a section beyond the limit */
        return px_context_fail(ctx, m < 0 ? PX_STATUS_NOMEM : PX_STATUS_CONFIG,
                               "section %zu: %s (%.4g points)", k + 1,
                               m < 0 ? "out of memory resampling it" : "too many points", m);
      emit(s, "0\nLWPOLYLINE\n8\n0\n90\n%zu\n70\n1\n", (size_t)m);
      for (size_t i = 0; i < (size_t)m; ++i)
        emit(s, "10\n%.17g\n20\n%.17g\n", x[i] - p->cu + p->center[0], y[i] - p->cv + p->center[1]);
      free(x);
      free(y);
    }
  emit(s, "0\nENDSEC\n0\nEOF\n");
  return PX_STATUS_OK;
}

/* DIR/contours/section-K.dxf: a comment, then dxf_entities. */
static enum px_status write_dxf(struct px_part3d *p, struct px_context *ctx, size_t k,
                                const char *path) {
  struct px_file *f;
  PX_TRY(px_file_open(ctx, path, &f));
  struct sink s = {px_file_stream(f), PX_FNV1A_OFFSET};
  fprintf(s.o, "999\nsection %zu of %s at %.17g m along the normal\n", k + 1, p->mesh_path,
          p->offset[k]);
  const enum px_status st = dxf_entities(p, ctx, k, &s);
  if (st != PX_STATUS_OK) {
    px_file_abort(f);
    return st;
  }
  return px_file_commit(f);
}

/* DIR/sections.csv and DIR/sections.png (the part with its sections). */
enum px_status px_part3d_write_sections(struct px_part3d *p, struct px_context *ctx) {
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
 * the contour's dxf file replaced by DIR/contours/section-K.dxf; and each
 * section's fingerprint. Writes nothing. */
int px_part3d_make_sweep(struct px_part3d *p, struct px_context *ctx, struct px_sweep *s) {
  char cdir[4300], abs[8500], cwd[4096];
  snprintf(cdir, sizeof cdir, "%s/contours", p->dir);
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
  /* the fingerprints: the sections' case resolved (the same for all, the
   * dxf named without its folder: moving the study's folder changes no
   * run), then each section's contour */
  struct px_case *c = NULL;
  const char *ov[PX_PART3D_MAX_SET + 3];
  for (size_t i = 0; i < s->runs[0].noverrides; ++i) ov[i] = s->runs[0].overrides[i];
  char file[128];
  snprintf(file, sizeof file, "granular.contours[%d].shape.file=section.dxf", p->contour_index);
  ov[p->nset] = file;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_WARN);
  const enum px_status st = px_case_load(ctx, p->base, ov, s->runs[0].noverrides, &c);
  px_context_set_log_level(ctx, p->log_level);
  if (st != PX_STATUS_OK) {
    fprintf(stderr, "%s: %s\n", p->file, px_context_message(ctx));
    return PX_CLI_EXIT_USAGE;
  }
  const char *text = px_case_resolved_text(c);
  const uint64_t h0 = px_text_fnv1a(px_text_fnv1a(PX_FNV1A_OFFSET, text, strlen(text)), "", 1);
  px_case_free(c);
  for (size_t k = 0; k < p->nsec; ++k) {
    struct sink snk = {NULL, h0};
    if (dxf_entities(p, ctx, k, &snk) != PX_STATUS_OK) {
      fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
      return PX_CLI_EXIT_FAILURE;
    }
    p->fingerprint[k] = snk.h;
  }
  return 0;
}

/* DIR/contours/section-K.dxf of every section. */
int px_part3d_write_contours(struct px_part3d *p, struct px_context *ctx,
                             const struct px_sweep *s) {
  char cdir[4300];
  snprintf(cdir, sizeof cdir, "%s/contours", p->dir);
  if (px_file_mkdirs(ctx, cdir) != PX_STATUS_OK) {
    fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
    return PX_CLI_EXIT_FAILURE;
  }
  for (size_t k = 0; k < p->nsec; ++k) {
    /* the file the run reads: its override's value */
    const char *o = s->runs[k].overrides[p->nset];
    if (write_dxf(p, ctx, k, strchr(o, '=') + 1) != PX_STATUS_OK) {
      fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
      return PX_CLI_EXIT_FAILURE;
    }
  }
  return 0;
}

/* 1 when the folder exists and holds anything: a run was made there. */
static int holds_run(const char *dir) {
  DIR *d = opendir(dir);
  struct dirent *e;
  int any = 0;
  while (d && !any && (e = readdir(d)) != NULL)
    any = strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
  if (d) closedir(d);
  return any;
}

/* The fingerprint recorded for section run `name` (DIR/sections/NAME.fingerprint)
 * into *h: 1, or 0 when there is none. */
static int recorded(const struct px_sweep *s, const char *name, uint64_t *h) {
  char path[4400];
  unsigned long long v = 0;
  snprintf(path, sizeof path, "%s/%s.fingerprint", s->dir, name);
  FILE *f = fopen(path, "r");
  const int ok = f && fscanf(f, "fnv1a64 %16llx", &v) == 1;
  if (f) fclose(f);
  *h = (uint64_t)v;
  return ok;
}

/* A section's folder that holds a run is reused (finished: skipped;
 * interrupted: resumed) only when the run was made for the same section:
 * its recorded fingerprint that of the section now. Otherwise (the file
 * was edited since: other sections, set: values, case or mesh; or the run
 * left no record) every such folder is named and the study refused, before
 * anything is written; nothing is removed. */
int px_part3d_check_reuse(const struct px_part3d *p, const struct px_sweep *s) {
  size_t stale = 0, other = 0;
  for (size_t k = 0; k < s->nruns; ++k) {
    char rundir[4400];
    uint64_t h;
    snprintf(rundir, sizeof rundir, "%s/%s", s->dir, s->runs[k].name);
    if (!holds_run(rundir)) continue;
    const int has = recorded(s, s->runs[k].name, &h);
    if (has && h == p->fingerprint[k]) continue;
    if (has) ++other;
    if (has)
      fprintf(stderr,
              "%s: %s holds a run made with other settings than section %zu has now (the part3d "
              "file, its case or its mesh changed since: the section's contour, case or set: "
              "values differ): it is not reused\n",
              p->file, rundir, k + 1);
    else
      fprintf(stderr,
              "%s: %s holds a run with no record of the settings it was made with (%s.fingerprint "
              "beside it): it is not reused\n",
              p->file, rundir, rundir);
    ++stale;
  }
  if (!stale) return 0;
  fprintf(stderr,
          "%s: nothing was run or removed. To run the study as the file says now, remove %s "
          "(or the whole %s), or give dir: another folder%s\n",
          p->file, stale == 1 ? "that folder" : "those folders", p->dir,
          other ? "; to go on with the earlier study, put the file back as it was" : "");
  return PX_CLI_EXIT_USAGE;
}

/* DIR/sections/K.fingerprint of each section whose run starts now (its
 * folder holds none; the others' records already match). */
int px_part3d_write_records(const struct px_part3d *p, struct px_context *ctx,
                            const struct px_sweep *s) {
  if (px_file_mkdirs(ctx, s->dir) != PX_STATUS_OK) {
    fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
    return PX_CLI_EXIT_FAILURE;
  }
  for (size_t k = 0; k < s->nruns; ++k) {
    char rundir[4400], path[4500];
    struct px_file *f;
    snprintf(rundir, sizeof rundir, "%s/%s", s->dir, s->runs[k].name);
    if (holds_run(rundir)) continue;
    snprintf(path, sizeof path, "%s/%s.fingerprint", s->dir, s->runs[k].name);
    if (px_file_open(ctx, path, &f) != PX_STATUS_OK) {
      fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
      return PX_CLI_EXIT_FAILURE;
    }
    fprintf(px_file_stream(f),
            "fnv1a64 %016llx\n"
            "# partix part3d %s, section %zu at %.17g m: the 64-bit FNV-1a of its case (%s\n"
            "# with the part3d overrides, resolved) and its contour (contours/section-%zu.dxf).\n"
            "# A rerun reuses %s/%s only while its section has this fingerprint.\n",
            (unsigned long long)p->fingerprint[k], p->file, k + 1, p->offset[k], p->base, k + 1,
            s->dir, s->runs[k].name);
    if (px_file_commit(f) != PX_STATUS_OK) {
      fprintf(stderr, "partix part3d: %s\n", px_context_message(ctx));
      return PX_CLI_EXIT_FAILURE;
    }
  }
  return 0;
}
