/* Profiles (closed body contours) of the vortex solver: built-in shapes,
 * Selig .dat airfoil files and plain point lists; placement; and the checks
 * (finite numbers, closure, orientation, self-intersection, overlap between
 * bodies) that run before any time step.
 *
 * Convention used by the whole solver: a contour is a closed polygon of n
 * vertices listed COUNTER-CLOCKWISE (body on the left of the direction of
 * travel, flow on the right); panel k runs from vertex k to vertex k+1 (mod n),
 * its unit tangent tau_k points along the travel and its outward normal is
 * n_k = (tau_y, -tau_x). Lengths are in the case's length unit. */
#ifndef PX_VORTEX_PROFILE_H
#define PX_VORTEX_PROFILE_H

#include <stddef.h>

#include "partix/context.h"

/* One closed contour. */
struct px_vortex_contour {
  size_t n;         /* number of vertices = number of panels */
  double *x;        /* owned: n vertex abscissae */
  double *y;        /* owned: n vertex ordinates */
  int *line;        /* owned or NULL: 1-based source-file line of each vertex (file
                       input before re-panelling), for error messages */
  char source[256]; /* "circle", "naca 0012" or the file path: names the body in messages */
};

enum px_vortex_spacing {
  PX_VORTEX_SPACING_UNIFORM = 0, /* equal arc length */
  PX_VORTEX_SPACING_COSINE = 1   /* clustered at leading and trailing edges */
};

/* Smallest number of panels a body may have. */
#define PX_VORTEX_MIN_PANELS 8
/* Largest number of panels of one body: its panel matrix alone is 80 GB
 * (8 bytes x 100001^2, LU-factored in place), more than most machines hold;
 * the solver also refuses a case whose estimated memory exceeds the
 * machine's (vortex.c, vx_check_memory). A few hundred are usual. */
#define PX_VORTEX_MAX_PANELS 100000

/* Profile files come from elsewhere and are not trusted (docs/running.md,
 * "What partix trusts"): a file is read only if it is a regular file (not a
 * device, a pipe or a directory) of at most PX_VORTEX_FILE_MAX_BYTES bytes,
 * with lines of at most PX_VORTEX_FILE_MAX_LINE bytes, at most
 * PX_VORTEX_FILE_MAX_POINTS points and coordinates of magnitude at most
 * PX_VORTEX_FILE_MAX_COORD (the profile's own units: scale and position
 * place it). A file beyond a limit is refused with FILE:LINE and the limit.
 * Coordinates within +-1e9 keep every product of two (areas, crossings)
 * finite.
 * Typical airfoil files hold 60-400 points of about 25 bytes. */
#define PX_VORTEX_FILE_MAX_BYTES (16L * 1024 * 1024)
#define PX_VORTEX_FILE_MAX_LINE 1024
#define PX_VORTEX_FILE_MAX_POINTS                         \
  (PX_VORTEX_MAX_PANELS + 1) /* a closed list repeats its \
                                first point */
#define PX_VORTEX_FILE_MAX_COORD 1e9

void px_vortex_contour_free(struct px_context *ctx, struct px_vortex_contour *c);

/* The smallest of the bodies' mean panel lengths (perimeter / vertices): the
 * length L the automatic numerical parameters scale with. */
double px_vortex_mean_panel_length(const struct px_vortex_contour *b, size_t nb);

/* Built-in shapes, centred on the origin (NACA: leading edge at the origin,
 * chord 1 along +x). */
enum px_status px_vortex_profile_circle(struct px_context *ctx, double radius, size_t n,
                                        struct px_vortex_contour *out);
/* Semi-axes a (along x) and b (along y); vertices equally spaced in arc length. */
enum px_status px_vortex_profile_ellipse(struct px_context *ctx, double a, double b, size_t n,
                                         struct px_vortex_contour *out);
/* Flat plate of overall length `length` (ends included) and thickness
 * `thickness`, with semicircular ends; equal arc-length panels. */
enum px_status px_vortex_profile_plate(struct px_context *ctx, double length, double thickness,
                                       size_t n, struct px_vortex_contour *out);
/* NACA 4-digit "MPTT" with the closed trailing edge (coefficient -0.1036);
 * n even; cosine spacing in x. */
enum px_status px_vortex_profile_naca4(struct px_context *ctx, const char *digits, size_t n,
                                       struct px_vortex_contour *out);
/* Selig .dat airfoil: a title line, then "x y" from the trailing edge over the
 * upper surface to the leading edge and back along the lower surface. An open
 * trailing edge (gap <= 2% of the chord) is closed by one straight panel. The
 * points are interpolated by a cubic spline in arc length and re-panelled to
 * n panels with the given spacing. */
enum px_status px_vortex_profile_read_selig(struct px_context *ctx, const char *path, size_t n,
                                            enum px_vortex_spacing spacing,
                                            struct px_vortex_contour *out);
/* Plain list of "x y" lines ('#' comments allowed), explicitly closed (the
 * last point repeats the first). n == 0 keeps the points as vertices;
 * otherwise the polygon is re-sampled to n panels of equal arc length. */
enum px_status px_vortex_profile_read_points(struct px_context *ctx, const char *path, size_t n,
                                             struct px_vortex_contour *out);

/* Scale about the local origin, rotate clockwise by angle_deg (the angle of
 * attack for a free stream along +x), then translate by (x0, y0). */
void px_vortex_profile_place(struct px_vortex_contour *c, double x0, double y0, double scale,
                             double angle_deg);
/* The same placement of one point (x, y) of the profile's own frame (e.g. its
 * moment centre) into (*ox, *oy) [m]. */
void px_vortex_profile_place_point(double x, double y, double x0, double y0, double scale,
                                   double angle_deg, double *ox, double *oy);

/* Finite coordinates, enough panels, no zero-length panel, non-zero area,
 * counter-clockwise orientation (a clockwise contour is reversed in place and
 * *reversed set to 1), no self-intersection. Messages name the body and, for
 * file input, the lines involved; of several crossings the first pair of
 * panels (k, j), k < j, in lexicographic order. The crossing test visits only
 * panels whose boxes overlap (a tree of boxes over runs of consecutive
 * panels: O(n log n) for a smooth contour) and gives up, refusing the
 * contour, after PX_VORTEX_CHECK_BUDGET(n) segment and box tests (a contour
 * of very many panels packed closely over many turns, e.g. a tight spiral). */
enum px_status px_vortex_profile_check(struct px_context *ctx, struct px_vortex_contour *c,
                                       int *reversed);
/* Work limit of the crossing tests of contours of n panels in all (box and
 * segment tests, about 10 ns each): circles, ellipses, plates and NACA
 * sections of 1e5 panels at any angle need 30-45 per panel (measured
 * 2026-11-27), 10 times less than this limit. */
#define PX_VORTEX_CHECK_BUDGET(n) (1e7 + 400.0 * (double)(n))

/* Bodies must neither cross nor contain one another (the same tree of boxes
 * and work limit). */
enum px_status px_vortex_profile_check_pair(struct px_context *ctx,
                                            const struct px_vortex_contour *a,
                                            const struct px_vortex_contour *b);

/* Signed area (positive for counter-clockwise). */
double px_vortex_profile_area(const struct px_vortex_contour *c);
/* 1 if (x, y) lies inside the polygon (even-odd rule). */
int px_vortex_profile_contains(const struct px_vortex_contour *c, double x, double y);

#endif
