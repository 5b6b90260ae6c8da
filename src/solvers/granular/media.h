/* Media discs: radius distributions and filling of the free region (inside
 * the container, outside the parts) without overlaps. */
#ifndef PX_GRAN_MEDIA_H
#define PX_GRAN_MEDIA_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "solvers/granular/geometry.h"

/* Lattice sites the lattice filling may test (each a point-in-region and a
 * distance query; PX_GRAN_N_MAX in geometry.h). */
#define PX_GRAN_SITES_MAX 1e8

enum px_gran_dist {
  PX_GRAN_DIST_UNIFORM = 0, /* radius uniform in [min, max] */
  PX_GRAN_DIST_NORMAL = 1,  /* normal(mean, sd) redrawn until within [min, max] */
  PX_GRAN_DIST_DISCRETE = 2 /* radii[k] with number fractions weights[k] */
};

struct px_gran_dist_spec {
  enum px_gran_dist kind;
  double min, max;       /* [m] bounds (all kinds) */
  double mean, sd;       /* normal [m] */
  size_t n;              /* discrete */
  const double *radii;   /* borrowed [m] */
  const double *weights; /* borrowed, > 0, any sum */
};

enum px_gran_fill {
  PX_GRAN_FILL_LATTICE = 0, /* hexagonal lattice of pitch 2 r_max (1 + gap), lowest sites first */
  PX_GRAN_FILL_RANDOM = 1   /* random sequential addition */
};

struct px_gran_fill_spec {
  enum px_gran_fill method;
  size_t count;         /* particles (0: from fraction) */
  double fraction;      /* disc area / free area (when count = 0) */
  double gap;           /* lattice: extra spacing relative to the diameter */
  double down[2];       /* unit vector "down" (gravity; 0: fill order by rows) */
  const double *window; /* optional [xmin, ymin, xmax, ymax] the centres must lie in */
  uint64_t seed;
};

/* Draw a radius. */
double px_gran_dist_draw(const struct px_gran_dist_spec *d, uint64_t rng[4]);
/* Mean disc area pi <r^2> of the distribution [m^2] (exact for uniform and
 * discrete, sampled for normal). */
double px_gran_dist_mean_area(const struct px_gran_dist_spec *d);
/* Largest radius the distribution can give. */
double px_gran_dist_rmax(const struct px_gran_dist_spec *d);
double px_gran_dist_rmin(const struct px_gran_dist_spec *d);

/* Area of the media region (container area minus parts plus holes) [m^2],
 * at zero displacement. */
double px_gran_geom_free_area(const struct px_gran_geom *g);

/* The number of discs px_gran_fill will place (fill->count, or from the
 * fraction), without placing them: for the memory check before the filling
 * allocates. PX_STATUS_CONFIG for a window that holds nothing, no disc, or
 * more than PX_GRAN_N_MAX. */
enum px_status px_gran_fill_count(struct px_context *ctx, const struct px_gran_geom *g,
                                  const double *frames, const struct px_gran_dist_spec *dist,
                                  const struct px_gran_fill_spec *fill, size_t *n);

/* Fill the media region of g (contours placed by `frames`) with discs:
 * *x, *y, *r (owned, px_mem) of *n discs. Fails with PX_STATUS_CONFIG when the
 * requested count does not fit, saying how many did. */
enum px_status px_gran_fill(struct px_context *ctx, const struct px_gran_geom *g,
                            const double *frames, const struct px_gran_dist_spec *dist,
                            const struct px_gran_fill_spec *fill, double **x, double **y,
                            double **r, size_t *n);

#endif
