/* Reading a granular case into the run (granular_case.c, the bodies in
 * granular_bodies.c), for px_gran_create_run (granular.c). Every failure
 * names its key. */
#ifndef PX_GRAN_CASE_H
#define PX_GRAN_CASE_H

#include "solvers/granular/granular_run.h"

#define PX_GRAN_PI 3.14159265358979323846
#define PX_GRAN_DEG (PX_GRAN_PI / 180.0)

/* The 2-vector at key path base.key into v. */
enum px_status px_gran_get_vec2(struct px_case *c, const char *base, const char *key, double v[2]);
/* The real at key path base.key into *v. */
enum px_status px_gran_get_real(struct px_case *c, const char *base, const char *key, double *v);
/* Add the contour(s) of contour item `cp` (key path) to r->geom; h: the
 * segment length [m]. box: the contours' box so far [xmin, ymin, xmax,
 * ymax] [m], grown by these; their extent must stay within
 * PX_GRAN_SPAN_MAX diameters (2 rmax [m]). */
enum px_status px_gran_contour(struct px_gran_run *r, const char *cp, double h, double rmax,
                               double box[4]);
/* The bodies (granular.bodies) and their motions into r->bodies and
 * r->motions. */
enum px_status px_gran_bodies(struct px_gran_run *r);
/* Each motion without a ramp that starts with a jump (px_gran_motion_onset)
 * against the contours of its body (r->geom): warned, and refused when
 * the walls jump by more than rmin [m], the smallest disc radius. */
enum px_status px_gran_motion_jumps(struct px_gran_run *r, double rmin);
/* Contact law at key `base` (granular.contact, granular.wall_contact) into
 * *L; `inherit` (may be NULL) gives the values the case leaves out. */
enum px_status px_gran_law(struct px_gran_run *r, const char *base,
                           const struct px_gran_law_spec *inherit, struct px_gran_law_spec *L);
/* The key of a law's parameter into key[96]: granular.wall_contact.NAME
 * when `wall` and the wall law gives it, granular.contact.NAME otherwise
 * (the wall law inherits it). Returns key. */
const char *px_gran_law_key(const struct px_case *c, int wall, const char *name, char key[96]);
/* Statistics keys into the run. */
enum px_status px_gran_stats_config(struct px_gran_run *r);
/* A failure of the system's checks (CONFIG) becomes a case error at path. */
enum px_status px_gran_as_case(struct px_gran_run *r, enum px_status st, const char *path);
/* Discs placed one by one (granular.media.particles): rows [x, y, r] with
 * optional [vx, vy] and w. Owned arrays x, y, r (n) and v (3 n: vx, vy, w). */
enum px_status px_gran_read_particles(struct px_gran_run *r, double **x, double **y, double **rad,
                                      double **v, size_t *n);
/* Discs listed one by one must not overlap (checked on a grid, stopping at
 * the first overlap, naming its row). */
enum px_status px_gran_listed_overlaps(struct px_gran_run *r, const double *x, const double *y,
                                       const double *rad, size_t n);

#endif
