/* Prescribed rigid motion of a boundary body (container, part): harmonic
 * vibration x(t) = A_x sin(2 pi f_x tau + phi_x), y likewise, rotation
 * phi(t) = A_r sin(2 pi f_r tau + phi_r) about a pivot, or a table of
 * (t, x, y, rotation) interpolated by cubic Hermite (Catmull–Rom) splines so
 * that the wall velocity is continuous. tau = t - start; before `start` the
 * body rests; over `ramp` seconds the motion fades in with a half-cosine
 * envelope (no velocity jump when the vibration starts). */
#ifndef PX_GRAN_MOTION_H
#define PX_GRAN_MOTION_H

#include <stddef.h>

#include "partix/context.h"

enum px_gran_motion_kind {
  PX_GRAN_MOTION_FIXED = 0,
  PX_GRAN_MOTION_HARMONIC = 1,
  PX_GRAN_MOTION_TABLE = 2
};

struct px_gran_motion {
  enum px_gran_motion_kind kind;
  double pivot[2]; /* centre of rotation, body frame [m] */
  double start;    /* [s] */
  double ramp;     /* [s], 0 = none */
  /* harmonic: components x, y, rotation */
  double amp[3];   /* [m], [m], [rad] */
  double freq[3];  /* [Hz] */
  double phase[3]; /* [rad] */
  /* table (owned arrays of n rows): time [s], x, y [m], rotation [rad] */
  size_t n;
  double *t, *x, *y, *r;
  int periodic; /* repeat with period t[n-1] - t[0] (first row = last row) */
};

void px_gran_motion_init(struct px_gran_motion *m);
void px_gran_motion_free(struct px_context *ctx, struct px_gran_motion *m);
/* Check parameters (message names `where`). */
enum px_status px_gran_motion_check(struct px_context *ctx, const struct px_gran_motion *m,
                                    const char *where);
/* Displacement d [m], velocity v [m/s], rotation phi [rad] and angular
 * velocity w [rad/s] at time t. */
void px_gran_motion_eval(const struct px_gran_motion *m, double t, double d[2], double v[2],
                         double *phi, double *w);
/* What the body jumps to from rest at its start (the limit tau -> 0+ of
 * px_gran_motion_eval, which is at rest for tau <= 0): displacement d [m],
 * velocity v [m/s], rotation phi [rad], angular velocity w [rad/s]. All
 * zero with a ramp; without one, a harmonic motion of phase p starts at
 * A sin p moving at 2 pi f A cos p, a table at its first row with the
 * spline's first tangent. */
void px_gran_motion_onset(const struct px_gran_motion *m, double d[2], double v[2], double *phi,
                          double *w);
/* Largest speed of any point within `radius` of the pivot over one period
 * (sampled; used for the time-step check and the neighbour skin). */
double px_gran_motion_max_speed(const struct px_gran_motion *m, double radius);
/* Frame record (PX_GRAN_CTR_COUNT doubles) at time t. */
void px_gran_motion_frame(const struct px_gran_motion *m, double t, double *frame);

#endif
