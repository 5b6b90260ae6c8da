/* Reading the bodies of a granular case (granular.bodies) into the run:
 * their motions (harmonic, or tables given as rows or read from a file)
 * and the check at the start of each motion that its walls do not jump
 * (warned, refused beyond the smallest disc radius). Every failure names
 * its key in the case (px_case_fail). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "partix/memory.h"
#include "solvers/granular/granular_case.h"

/* Largest motion table file [bytes] (10 million rows of four numbers). */
#define PX_GRAN_TABLE_BYTES (256.0 * 1024 * 1024)

static enum px_status px_gran_read_table_file(struct px_gran_run *r, const char *at,
                                              struct px_gran_motion *m) {
  char resolved[4096], line[1024];
  FILE *f;
  size_t cap = 0, lineno = 0;
  struct stat sb;
  if (px_case_input_path(r->c, at, resolved, sizeof resolved) != PX_STATUS_OK)
    return px_case_fail(r->c, at, "file name too long");
  f = fopen(resolved, "r");
  if (!f)
    return px_case_fail(r->c, at, "cannot open motion table '%s': %s", resolved, strerror(errno));
  /* a regular file of bounded size (a device or a pipe could be read
   * without end) */
  if (fstat(fileno(f), &sb) != 0 || !S_ISREG(sb.st_mode) ||
      (double)sb.st_size > PX_GRAN_TABLE_BYTES) {
    fclose(f);
    return px_case_fail(r->c, at, "motion table '%s': not a regular file of at most %.0f MiB",
                        resolved, PX_GRAN_TABLE_BYTES / 1048576.0);
  }
  while (fgets(line, sizeof line, f)) {
    double v[4] = {0, 0, 0, 0};
    char *p = line, *end;
    int k;
    ++lineno;
    while (*p == ' ' || *p == '\t') ++p;
    if (*p == '#' || *p == '\n' || *p == '\r' || *p == '\0' || (*p >= 'a' && *p <= 'z') ||
        (*p >= 'A' && *p <= 'Z'))
      continue; /* comments, blank lines, a header */
    for (k = 0; k < 4; ++k) {
      while (*p == ' ' || *p == '\t' || *p == ',' || *p == ';') ++p;
      if (*p == '\n' || *p == '\0' || *p == '\r') break;
      v[k] = strtod(p, &end);
      if (end == p || !isfinite(v[k])) {
        fclose(f);
        return px_case_fail(r->c, at, "%s:%zu: expected finite numbers t x y [rotation]", resolved,
                            lineno);
      }
      p = end;
    }
    if (k < 3) {
      fclose(f);
      return px_case_fail(r->c, at, "%s:%zu: expected at least t x y", resolved, lineno);
    }
    if (m->n == cap) {
      size_t nc = cap ? 2 * cap : 64;
      double *t = px_mem_realloc(r->ctx, "granular motion", m->t, nc * sizeof *t);
      double *x = t ? px_mem_realloc(r->ctx, "granular motion", m->x, nc * sizeof *x) : NULL;
      double *y = x ? px_mem_realloc(r->ctx, "granular motion", m->y, nc * sizeof *y) : NULL;
      double *rr = y ? px_mem_realloc(r->ctx, "granular motion", m->r, nc * sizeof *rr) : NULL;
      if (t) m->t = t;
      if (x) m->x = x;
      if (y) m->y = y;
      if (!rr) {
        fclose(f);
        return PX_STATUS_NOMEM;
      }
      m->r = rr;
      cap = nc;
    }
    m->t[m->n] = v[0], m->x[m->n] = v[1], m->y[m->n] = v[2], m->r[m->n] = v[3] * PX_GRAN_DEG;
    ++m->n;
  }
  fclose(f);
  return PX_STATUS_OK;
}

enum px_status px_gran_bodies(struct px_gran_run *r) {
  struct px_case *c = r->c;
  size_t n, b;
  PX_TRY(px_case_count(c, "granular.bodies", &n));
  r->bodies = px_mem_calloc(r->ctx, "granular bodies", n, sizeof *r->bodies);
  r->motions = px_mem_calloc(r->ctx, "granular bodies", n, sizeof *r->motions);
  if (!r->bodies || !r->motions) return PX_STATUS_NOMEM;
  r->nbodies = n;
  for (b = 0; b < n; ++b) {
    char bp[64], mp[96], key[160];
    const char *name, *type;
    struct px_gran_motion *m = &r->motions[b];
    size_t k;
    double start = -1;
    snprintf(bp, sizeof bp, "granular.bodies[%zu]", b);
    snprintf(mp, sizeof mp, "%s.motion", bp);
    px_gran_motion_init(m);
    PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, bp, "name"), &name));
    if (strlen(name) >= PX_GRAN_NAME_MAX)
      return px_case_fail(c, px_case_path_join(key, sizeof key, bp, "name"), "name too long");
    for (k = 0; k < b; ++k)
      if (strcmp(r->bodies[k].name, name) == 0)
        return px_case_fail(c, px_case_path_join(key, sizeof key, bp, "name"),
                            "a body named '%s' already exists", name);
    snprintf(r->bodies[b].name, sizeof r->bodies[b].name, "%s", name);
    PX_TRY(px_case_get_string(c, px_case_path_join(key, sizeof key, mp, "type"), &type));
    if (strcmp(type, "fixed") == 0) continue;
    PX_TRY(px_gran_get_vec2(c, mp, "pivot", m->pivot));
    PX_TRY(px_gran_get_real(c, mp, "start", &start));
    PX_TRY(px_gran_get_real(c, mp, "ramp", &m->ramp));
    m->start = start < 0 ? r->settle : start;
    if (strcmp(type, "harmonic") == 0) {
      double amp[2], ph[2], f, rot, rf, rph;
      m->kind = PX_GRAN_MOTION_HARMONIC;
      PX_TRY(px_gran_get_vec2(c, mp, "amplitude", amp));
      PX_TRY(px_gran_get_vec2(c, mp, "phase", ph));
      PX_TRY(px_gran_get_real(c, mp, "frequency", &f));
      PX_TRY(px_gran_get_real(c, mp, "rotation", &rot));
      PX_TRY(px_gran_get_real(c, mp, "rotation_frequency", &rf));
      PX_TRY(px_gran_get_real(c, mp, "rotation_phase", &rph));
      m->amp[0] = amp[0], m->amp[1] = amp[1], m->amp[2] = rot * PX_GRAN_DEG;
      m->freq[0] = m->freq[1] = f;
      m->freq[2] = rf > 0 ? rf : f;
      m->phase[0] = ph[0] * PX_GRAN_DEG, m->phase[1] = ph[1] * PX_GRAN_DEG;
      m->phase[2] = rph * PX_GRAN_DEG;
    } else { /* table */
      int periodic = 0;
      m->kind = PX_GRAN_MOTION_TABLE;
      PX_TRY(px_case_get_bool(c, px_case_path_join(key, sizeof key, mp, "periodic"), &periodic));
      m->periodic = periodic;
      if (px_case_has(c, px_case_path_join(key, sizeof key, mp, "file"))) {
        PX_TRY(px_gran_read_table_file(r, key, m));
      } else if (px_case_has(c, px_case_path_join(key, sizeof key, mp, "rows"))) {
        size_t nr;
        PX_TRY(px_case_count(c, key, &nr));
        m->t = px_mem_alloc(r->ctx, "granular motion", nr * sizeof(double));
        m->x = px_mem_alloc(r->ctx, "granular motion", nr * sizeof(double));
        m->y = px_mem_alloc(r->ctx, "granular motion", nr * sizeof(double));
        m->r = px_mem_alloc(r->ctx, "granular motion", nr * sizeof(double));
        if (!m->t || !m->x || !m->y || !m->r) return PX_STATUS_NOMEM;
        for (k = 0; k < nr; ++k) {
          char rk[200];
          size_t nc;
          double row[4] = {0, 0, 0, 0};
          snprintf(rk, sizeof rk, "%s.rows[%zu]", mp, k);
          PX_TRY(px_case_count(c, rk, &nc));
          if (nc < 3 || nc > 4)
            return px_case_fail(c, rk, "a row is [t, x, y] or [t, x, y, rotation]");
          PX_TRY(px_case_get_vector(c, rk, row, nc));
          m->t[k] = row[0], m->x[k] = row[1], m->y[k] = row[2], m->r[k] = row[3] * PX_GRAN_DEG;
        }
        m->n = nr;
      } else {
        return px_case_fail(c, mp, "a table motion needs `rows` or `file`");
      }
    }
    {
      enum px_status st = px_gran_motion_check(r->ctx, m, mp);
      if (st == PX_STATUS_CONFIG) {
        char msg[512];
        snprintf(msg, sizeof msg, "%s", px_context_message(r->ctx));
        return px_case_fail(c, mp, "%s", msg);
      }
      PX_TRY(st);
    }
  }
  return PX_STATUS_OK;
}

/* The jump of body b's walls at the start of its motion (its onset: d, v
 * [m, m/s], phi, w [rad, rad/s], px_gran_motion_onset): the largest
 * displacement *dj [m] and speed *vj [m/s] of the corners of its contours'
 * boxes (the displacement of a rigid motion is affine in the point, so its
 * largest size over a contour is at most that over the box around it).
 * Returns 0 when no contour moves with the body. */
static int px_gran_body_jump(const struct px_gran_run *r, size_t b, const double d[2],
                             const double v[2], double phi, double w, double *dj, double *vj,
                             double *reach) {
  const struct px_gran_motion *m = &r->motions[b];
  const double co = cos(phi), si = sin(phi);
  size_t c;
  int any = 0;
  *dj = *vj = *reach = 0;
  for (c = 0; c < r->geom.ncontours; ++c) {
    const struct px_gran_contour *C = &r->geom.contours[c];
    int k;
    if (C->body != (int)b) continue;
    any = 1;
    for (k = 0; k < 4; ++k) {
      const double px = (k & 1 ? C->xmax : C->xmin) - m->pivot[0];
      const double py = (k & 2 ? C->ymax : C->ymin) - m->pivot[1];
      const double rx = co * px - si * py, ry = si * px + co * py; /* rotated arm */
      *dj = fmax(*dj, hypot(d[0] + rx - px, d[1] + ry - py));
      *vj = fmax(*vj, hypot(v[0] - w * ry, v[1] + w * rx));
      *reach = fmax(*reach, hypot(px, py));
    }
  }
  return any;
}

enum px_status px_gran_motion_jumps(struct px_gran_run *r, double rmin) {
  struct px_case *c = r->c;
  size_t b;
  for (b = 0; b < r->nbodies; ++b) {
    const struct px_gran_motion *m = &r->motions[b];
    double dj, vj, reach, vpeak, d[2], v[2], phi, w;
    char key[160], hint[96] = "";
    if (m->kind == PX_GRAN_MOTION_FIXED || m->ramp > 0) continue;
    px_gran_motion_onset(m, d, v, &phi, &w);
    if (!px_gran_body_jump(r, b, d, v, phi, w, &dj, &vj, &reach)) continue;
    /* the rounding of sin and cos at a phase of 90 or 180 deg is no jump */
    vpeak = px_gran_motion_max_speed(m, reach);
    if (!(dj > 1e-9 * rmin) && !(vj > 1e-9 * vpeak)) continue;
    /* the key that sets the jump */
    if (m->kind == PX_GRAN_MOTION_TABLE) {
      snprintf(key, sizeof key, "granular.bodies[%zu].motion.file", b);
      if (!px_case_has(c, key)) snprintf(key, sizeof key, "granular.bodies[%zu].motion.rows", b);
    } else {
      snprintf(key, sizeof key, "granular.bodies[%zu].motion.%s", b,
               d[0] == 0 && d[1] == 0 && phi != 0 ? "rotation_phase" : "phase");
      if (m->freq[0] > 0)
        snprintf(hint, sizeof hint, " (e.g. ramp: %.3g, two periods)", 2 / m->freq[0]);
    }
    /* A wall that jumps by more than the smallest disc radius puts the
     * centre of such a disc resting against it (the filling places discs
     * touching the walls, a settled bed rests on them) behind the wall in
     * one step: the disc passes through, is lost from the container, and
     * the run goes on without it (or stops at the "passed through" check).
     * A smaller jump only overlaps discs with the wall by less than their
     * radius, which the contact law pushes back out (violently: warned) */
    if (dj > rmin)
      return px_case_fail(c, key,
                          "with no ramp, the walls of body '%s' start the motion (t = %g s) "
                          "displaced by %g m and moving at %g m/s instead of from rest: they "
                          "jump there in one step, by more than the smallest disc radius %g m, "
                          "so discs against a wall could be pushed through it; set "
                          "granular.bodies[%zu].motion.ramp%s to fade the motion in",
                          r->bodies[b].name, m->start, dj, vj, rmin, b, hint);
    px_log(r->ctx, PX_LOG_LEVEL_WARN,
           "%s: with no ramp, the walls of body '%s' start the motion (t = %g s) displaced "
           "by %g m and moving at %g m/s instead of from rest: they jump there in one step, "
           "throwing the media; set granular.bodies[%zu].motion.ramp%s to fade the motion in",
           key, r->bodies[b].name, m->start, dj, vj, b, hint);
  }
  return PX_STATUS_OK;
}
