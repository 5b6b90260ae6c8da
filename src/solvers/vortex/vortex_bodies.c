/* The vortex solver's bodies (vortex_solver.h): each profile built from
 * the case, placed and checked, and the memory the case needs checked before
 * (and once the point files are read, again after) the bodies are built. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "solvers/solver.h"
#include "solvers/vortex/vortex_core.h"
#include "solvers/vortex/vortex_profile.h"
#include "solvers/vortex/vortex_solver.h"

/* A body's coordinates stay within +-VX_MAX_COORD [m], the bound on a
 * profile file's own coordinates (PX_GEO_PROFILE_MAX_COORD): far beyond any
 * flow the solver resolves, and it keeps the areas, circulations (v L) and
 * moments (Gamma r^2) of the run finite in double precision (a radius of
 * 1e300 m made the area overflow: "encloses no area"). */
#define VX_MAX_COORD 1e9

/* Refuse at `key` (value v) a body that reaches `reach` [m] from the origin,
 * beyond VX_MAX_COORD. */
static enum px_status vx_check_size(struct px_case *c, const char *key, double v, double reach) {
  if (fabs(reach) <= VX_MAX_COORD) return PX_STATUS_OK;
  return px_case_fail(c, key,
                      "%g takes the body %g m from the origin: a body's coordinates are "
                      "limited to +-%g m (as a profile file's), which keeps areas, "
                      "circulations and moments finite",
                      v, fabs(reach), VX_MAX_COORD);
}

/* The length `name` of body p ("vortex.bodies[0]") into *v [m], its key
 * path into q (q_size bytes), refused beyond VX_MAX_COORD. */
static enum px_status vx_body_length(struct px_case *c, const char *p, const char *name, char *q,
                                     size_t q_size, double *v) {
  snprintf(q, q_size, "%s.%s", p, name);
  PX_TRY(px_case_get_real(c, q, v));
  return vx_check_size(c, q, *v, *v);
}

/* Build body i from the case: shape, placement, checks. A failure is
 * reported at the body's key path with the profile module's message. */
static enum px_status build_body(struct vx_state *s, size_t i, struct px_vortex_contour *out,
                                 double ref[3]) {
  char p[160], q[200];
  struct px_case *c = s->c;
  snprintf(p, sizeof p, "vortex.bodies[%zu]", i);
  const char *type = NULL;
  snprintf(q, sizeof q, "%s.type", p);
  PX_TRY(px_case_get_string(c, q, &type));
  long panels = 0;
  snprintf(q, sizeof q, "%s.panels", p);
  PX_TRY(px_case_get_int(c, q, &panels));
  enum px_status st = PX_STATUS_OK;
  struct px_context *ctx = s->ctx;
  memset(out, 0, sizeof *out);
  if (strcmp(type, "circle") == 0) {
    double r;
    PX_TRY(vx_body_length(c, p, "radius", q, sizeof q, &r));
    st = px_vortex_profile_circle(ctx, r, (size_t)panels, out);
  } else if (strcmp(type, "ellipse") == 0) {
    double a, b;
    PX_TRY(vx_body_length(c, p, "a", q, sizeof q, &a));
    PX_TRY(vx_body_length(c, p, "b", q, sizeof q, &b));
    st = px_vortex_profile_ellipse(ctx, a, b, (size_t)panels, out);
  } else if (strcmp(type, "plate") == 0) {
    double l, t;
    PX_TRY(vx_body_length(c, p, "length", q, sizeof q, &l));
    PX_TRY(vx_body_length(c, p, "thickness", q, sizeof q, &t));
    st = px_vortex_profile_plate(ctx, l, t, (size_t)panels, out);
  } else if (strcmp(type, "naca") == 0) {
    const char *d;
    snprintf(q, sizeof q, "%s.digits", p);
    PX_TRY(px_case_get_string(c, q, &d));
    st = px_vortex_profile_naca4(ctx, d, (size_t)panels, out);
  } else {
    char path[4096];
    snprintf(q, sizeof q, "%s.file", p);
    if (px_case_input_path(c, q, path, sizeof path) != PX_STATUS_OK)
      return px_case_fail(c, q, "file name too long");
    if (strcmp(type, "selig") == 0) {
      int sp = 0;
      snprintf(q, sizeof q, "%s.spacing", p);
      PX_TRY(px_case_get_enum(c, q, &sp));
      st = px_vortex_profile_read_selig(
          ctx, path, (size_t)panels, sp == 0 ? PX_VORTEX_SPACING_COSINE : PX_VORTEX_SPACING_UNIFORM,
          out);
    } else {
      st = px_vortex_profile_read_points(ctx, path, (size_t)panels, out);
    }
  }
  if (st == PX_STATUS_OK) {
    double pos[2], scale, angle;
    snprintf(q, sizeof q, "%s.position", p);
    PX_TRY(px_case_get_vector(c, q, pos, 2));
    snprintf(q, sizeof q, "%s.scale", p);
    PX_TRY(px_case_get_real(c, q, &scale));
    snprintf(q, sizeof q, "%s.angle", p);
    PX_TRY(px_case_get_real(c, q, &angle));
    /* the profile's own extent (within VX_MAX_COORD: the sizes above, a
     * file's bound, a NACA's chord 1), scaled, and the offset */
    double own = 0.0;
    for (size_t k = 0; k < out->n; ++k) own = fmax(own, fmax(fabs(out->x[k]), fabs(out->y[k])));
    snprintf(q, sizeof q, "%s.scale", p);
    st = vx_check_size(c, q, scale, scale * own);
    snprintf(q, sizeof q, "%s.position", p);
    for (int d = 0; d < 2 && st == PX_STATUS_OK; ++d) st = vx_check_size(c, q, pos[d], pos[d]);
    if (st != PX_STATUS_OK) {
      px_vortex_contour_free(ctx, out);
      return st;
    }
    px_vortex_profile_place(out, pos[0], pos[1], scale, angle);
    int rev = 0;
    st = px_vortex_profile_check(ctx, out, &rev);
    snprintf(q, sizeof q, "%s.reference_length", p);
    PX_TRY(px_case_get_real(c, q, &ref[0]));
    /* the moment centre is a point of the profile's own frame, placed with
     * it: an angle-of-attack sweep keeps it on the same point of the body */
    double mc[2];
    snprintf(q, sizeof q, "%s.moment_center", p);
    PX_TRY(px_case_get_vector(c, q, mc, 2));
    px_vortex_profile_place_point(mc[0], mc[1], pos[0], pos[1], scale, angle, &ref[1], &ref[2]);
  }
  if (st == PX_STATUS_NOMEM || st == PX_STATUS_INTERNAL) return st;
  if (st != PX_STATUS_OK) {
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", px_context_message(ctx));
    px_vortex_contour_free(ctx, out);
    return px_case_fail(c, p, "%s", msg);
  }
  return PX_STATUS_OK;
}

/* Memory of the case, estimated before anything is built [bytes] (owners:
 * vortex_panels.c, vortex_core.c, vortex_tree.c, the nbody sums):
 *  - the panel matrix, nsys = panels + bodies unknowns: 8 nsys^2 bytes,
 *    LU-factored in place, and a 4 nsys^2 single-precision copy with
 *    precision single (px_vortex_panels_factor), else its compressed copy
 *    (<= 4 nsys^2, and 2 nsys^2 of work: px_vortex_panels_compress);
 *  - per panel about 512 bytes (geometry, sheet, wall terms, the panel tree,
 *    the generation's work arrays), 1 kB more while an ellipse is built (64
 *    samples per panel);
 *  - per vortex about 512 bytes: the wake (10 doubles and an int, grown by
 *    half: 126), work arrays (40), the wake tree (70), the pair sums' buffers
 *    (60), the rk2 stage (72), the FMM's expansions (about 100); the wake's
 *    size is not known before the run, so the estimate holds the first
 *    step's newborn vortices, panels x vortex_per_panel: a lower bound;
 *  - per field-grid point about 160 bytes: positions, velocities and
 *    pressure (40), the pair sums' targets (48), the VTK arrays (72).
 * count[i]: the panels of body i; key[i]: the case key that sets them. */
#define VX_BYTES_PER_PANEL 512.0
#define VX_BYTES_PER_ELLIPSE_PANEL 1024.0
#define VX_BYTES_PER_VORTEX 512.0
#define VX_BYTES_PER_GRID_POINT 160.0
static enum px_status vx_check_memory(struct vx_state *s, size_t nb, const size_t *count,
                                      char (*key)[64], const int *ellipse) {
  struct px_case *c = s->c;
  long vpp = 1;
  PX_TRY(px_case_get_int(c, "vortex.vortex_per_panel", &vpp));
  double n = 0.0, build = 0.0;
  size_t big = 0;
  for (size_t i = 0; i < nb; ++i) {
    n += (double)count[i];
    if (ellipse[i]) build = fmax(build, VX_BYTES_PER_ELLIPSE_PANEL * (double)count[i]);
    if (count[i] > count[big]) big = i;
  }
  const double ns = n + (double)nb;
  const int single = px_sim_precision(s->sim) == PX_PRECISION_SINGLE;
  const double matrix = (single ? 12.0 : 14.0) * ns * ns + (single ? 8.0 : 4.0) * ns;
  const double body =
      matrix + VX_BYTES_PER_PANEL * n + build + VX_BYTES_PER_VORTEX * n * (double)vpp;
  char what[256];
  snprintf(what, sizeof what,
           "the %.0f x %.0f panel matrix of the bodies' %.0f panels%s, with the panels and the "
           "first step's vortices",
           ns, ns, n, single ? " (and its single-precision copy)" : " (and its compressed copy)");
  PX_TRY(px_sim_require_memory(s->sim, body, key[big], what));
  if (px_case_has(c, "vortex.fields.grid")) {
    double cells[2] = {0, 0};
    PX_TRY(px_case_get_vector(c, "vortex.fields.cells", cells, 2));
    const double grid = VX_BYTES_PER_GRID_POINT * cells[0] * cells[1];
    snprintf(what, sizeof what,
             "the %.0f x %.0f field grid (%.3g GB) besides the panel matrix, the panels and the "
             "first step's vortices (%.3g GB)",
             cells[0], cells[1], grid / 1e9, body / 1e9);
    PX_TRY(px_sim_require_memory(s->sim, body + grid, "vortex.fields.cells", what));
  }
  return PX_STATUS_OK;
}

/* vx_create's bodies: built into body[0..*nb_out) (room for PX_VORTEX_MAX_BODIES,
 * zeroed), each one's reference length and moment centre into cfg, the
 * case's memory checked, and no two bodies overlapping. On failure the
 * bodies are freed. */
enum px_status px_vortex_bodies_build(struct vx_state *s, struct px_vortex_config *cfg,
                                      struct px_vortex_contour *body, size_t *nb_out) {
  struct px_context *ctx = s->ctx;
  struct px_case *c = s->c;
  size_t nb = 0;
  PX_TRY(px_case_count(c, "vortex.bodies", &nb));
  if (nb > PX_VORTEX_MAX_BODIES)
    return px_case_fail(c, "vortex.bodies", "more than %d bodies", PX_VORTEX_MAX_BODIES);
  /* the memory the case needs, before any body is built: from the panel
   * counts the case gives, and again below once the files of point lists
   * kept as they are (panels: 0) have been read */
  size_t count[PX_VORTEX_MAX_BODIES];
  char count_key[PX_VORTEX_MAX_BODIES][64];
  int ellipse[PX_VORTEX_MAX_BODIES], counted = 1;
  for (size_t i = 0; i < nb; ++i) {
    char q[64];
    const char *type = NULL;
    long panels = 0;
    snprintf(q, sizeof q, "vortex.bodies[%zu].type", i);
    PX_TRY(px_case_get_string(c, q, &type));
    snprintf(count_key[i], sizeof count_key[i], "vortex.bodies[%zu].panels", i);
    PX_TRY(px_case_get_int(c, count_key[i], &panels));
    if (panels <= 0) { /* points kept as given: the file sets the count */
      snprintf(count_key[i], sizeof count_key[i], "vortex.bodies[%zu].file", i);
      counted = 0;
    }
    count[i] = panels > 0 ? (size_t)panels : 0;
    ellipse[i] = strcmp(type, "ellipse") == 0;
  }
  PX_TRY(vx_check_memory(s, nb, count, count_key, ellipse));
  enum px_status st = PX_STATUS_OK, worst = PX_STATUS_OK;
  for (size_t i = 0; i < nb; ++i) {
    double ref[3];
    st = build_body(s, i, &body[i], ref);
    if (st != PX_STATUS_OK) {
      if (st != PX_STATUS_CONFIG) goto done;
      worst = st;
      continue;
    }
    cfg->ref_length[i] = ref[0];
    cfg->moment_center[i][0] = ref[1];
    cfg->moment_center[i][1] = ref[2];
  }
  if (worst != PX_STATUS_OK) {
    st = worst;
    goto done;
  }
  if (!counted) {
    for (size_t i = 0; i < nb; ++i) count[i] = body[i].n;
    st = vx_check_memory(s, nb, count, count_key, ellipse);
    if (st != PX_STATUS_OK) goto done;
  }
  for (size_t i = 0; i < nb; ++i)
    for (size_t j = i + 1; j < nb; ++j)
      if (px_vortex_profile_check_pair(ctx, &body[i], &body[j]) != PX_STATUS_OK) {
        char msg[1024], p[64];
        snprintf(msg, sizeof msg, "%s", px_context_message(ctx));
        snprintf(p, sizeof p, "vortex.bodies[%zu]", j);
        st = px_case_fail(c, p, "%s", msg);
        goto done;
      }
  *nb_out = nb;
  return PX_STATUS_OK;
done:
  for (size_t i = 0; i < nb; ++i) px_vortex_contour_free(ctx, &body[i]);
  return st;
}
