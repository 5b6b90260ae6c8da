/* Built-in closed shapes as polylines (geo_shape.h). */
#include "io/geometry/geo_shape.h"

#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "partix/memory.h"

#define PX_GEO_PI 3.14159265358979323846

static enum px_status px_geo_shape_vertices(struct px_context *ctx, size_t n, const char *what) {
  if (n < PX_GEO_SHAPE_MIN_VERTICES)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: %zu vertices is too few (at least %d)", what,
                           n, PX_GEO_SHAPE_MIN_VERTICES);
  return PX_STATUS_OK;
}

enum px_status px_geo_shape_circle(struct px_context *ctx, double radius, size_t n,
                                   struct px_geo_polyline *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(px_geo_shape_vertices(ctx, n, "circle"));
  if (!(radius > 0.0) || !isfinite(radius))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "circle: radius must be > 0 (got %g)", radius);
  PX_TRY(px_geo_polyline_alloc(ctx, out, n, 0));
  for (size_t k = 0; k < n; ++k) {
    double th = 2.0 * PX_GEO_PI * (double)k / (double)n;
    out->x[k] = radius * cos(th);
    out->y[k] = radius * sin(th);
  }
  snprintf(out->source, sizeof out->source, "circle");
  return PX_STATUS_OK;
}

enum px_status px_geo_shape_ellipse(struct px_context *ctx, double a, double b, size_t n,
                                    struct px_geo_polyline *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(px_geo_shape_vertices(ctx, n, "ellipse"));
  if (!(a > 0.0) || !(b > 0.0) || !isfinite(a) || !isfinite(b))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "ellipse: semi-axes must be > 0 (got a = %g, b = %g)", a, b);
  size_t m = 64 * n;
  if (n > SIZE_MAX / (128 * sizeof(double)))
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for an ellipse");
  double *px = px_mem_alloc(ctx, "geometry shape", 2 * m * sizeof(double));
  if (!px) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for an ellipse");
  double *py = px + m;
  for (size_t i = 0; i < m; ++i) {
    double t = 2.0 * PX_GEO_PI * (double)i / (double)m;
    px[i] = a * cos(t);
    py[i] = b * sin(t);
  }
  enum px_status st = px_geo_polyline_alloc(ctx, out, n, 0);
  if (st == PX_STATUS_OK) px_geo_polyline_resample(m, px, py, n, out->x, out->y);
  px_mem_free(ctx, px);
  snprintf(out->source, sizeof out->source, "ellipse");
  return st;
}

/* Point at arc length s (0 <= s < perimeter) on a stadium: straight sides of
 * half-length a at y = +-h, semicircular ends of radius h centred at (+-a, 0),
 * starting at (a + h, 0) and running counter-clockwise. */
static void px_geo_stadium_point(double a, double h, double s, double *x, double *y) {
  double q = 0.5 * PX_GEO_PI * h; /* quarter arc */
  double side = 2.0 * a;
  if (s < q) {
    double th = s / h;
    *x = a + h * cos(th);
    *y = h * sin(th);
    return;
  }
  s -= q;
  if (s < side) {
    *x = a - s;
    *y = h;
    return;
  }
  s -= side;
  if (s < 2.0 * q) {
    double th = 0.5 * PX_GEO_PI + s / h;
    *x = -a + h * cos(th);
    *y = h * sin(th);
    return;
  }
  s -= 2.0 * q;
  if (s < side) {
    *x = -a + s;
    *y = -h;
    return;
  }
  s -= side;
  double th = 1.5 * PX_GEO_PI + s / h;
  *x = a + h * cos(th);
  *y = h * sin(th);
}

enum px_status px_geo_shape_plate(struct px_context *ctx, double length, double thickness, size_t n,
                                  struct px_geo_polyline *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(px_geo_shape_vertices(ctx, n, "plate"));
  if (!(thickness > 0.0) || !(length > thickness) || !isfinite(length))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "plate: need 0 < thickness < length (got length %g, thickness %g)",
                           length, thickness);
  double h = 0.5 * thickness, a = 0.5 * length - h;
  double per = 4.0 * a + 2.0 * PX_GEO_PI * h;
  PX_TRY(px_geo_polyline_alloc(ctx, out, n, 0));
  for (size_t k = 0; k < n; ++k)
    px_geo_stadium_point(a, h, per * (double)k / (double)n, &out->x[k], &out->y[k]);
  snprintf(out->source, sizeof out->source, "plate %g x %g", length, thickness);
  return PX_STATUS_OK;
}

/* NACA 4-digit section (Abbott & von Doenhoff, Theory of Wing Sections, 1959,
 * sec. 6.4), closed trailing edge: the last thickness coefficient is -0.1036
 * instead of -0.1015 so that y_t(1) = 0. */
static void px_geo_naca4_point(double m, double p, double t, double xc, int upper, double *x,
                               double *y) {
  double sx = sqrt(xc);
  double yt = 5.0 * t *
              (0.2969 * sx - 0.1260 * xc - 0.3516 * xc * xc + 0.2843 * xc * xc * xc -
               0.1036 * xc * xc * xc * xc);
  double yc = 0.0, dyc = 0.0;
  if (m > 0.0 && p > 0.0) {
    if (xc < p) {
      yc = m / (p * p) * (2.0 * p * xc - xc * xc);
      dyc = 2.0 * m / (p * p) * (p - xc);
    } else {
      yc = m / ((1.0 - p) * (1.0 - p)) * ((1.0 - 2.0 * p) + 2.0 * p * xc - xc * xc);
      dyc = 2.0 * m / ((1.0 - p) * (1.0 - p)) * (p - xc);
    }
  }
  double th = atan(dyc);
  if (upper) {
    *x = xc - yt * sin(th);
    *y = yc + yt * cos(th);
  } else {
    *x = xc + yt * sin(th);
    *y = yc - yt * cos(th);
  }
}

enum px_status px_geo_shape_naca4_digits(struct px_context *ctx, const char *digits) {
  int ok = digits && strlen(digits) == 4;
  for (int i = 0; ok && i < 4; ++i) ok = isdigit((unsigned char)digits[i]) != 0;
  if (!ok)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "naca: expected 4 digits such as \"0012\" or \"2412\" (got \"%s\")",
                           digits ? digits : "");
  return PX_STATUS_OK;
}

enum px_status px_geo_shape_naca4(struct px_context *ctx, const char *digits, size_t n,
                                  struct px_geo_polyline *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(px_geo_shape_naca4_digits(ctx, digits));
  PX_TRY(px_geo_shape_vertices(ctx, n, "naca"));
  if (n % 2)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "naca: the number of panels must be even (got %zu)", n);
  double m = (digits[0] - '0') / 100.0, p = (digits[1] - '0') / 10.0;
  double t = ((digits[2] - '0') * 10 + (digits[3] - '0')) / 100.0;
  if (t <= 0.0) return px_context_fail(ctx, PX_STATUS_CONFIG, "naca %s: zero thickness", digits);
  if ((m > 0.0) != (p > 0.0))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "naca %s: camber and its position must both be zero or both non-zero",
                           digits);
  PX_TRY(px_geo_polyline_alloc(ctx, out, n, 0));
  size_t nh = n / 2, k = 0;
  /* trailing edge -> upper surface -> leading edge -> lower surface */
  for (size_t j = nh;; --j) {
    double xc = 0.5 * (1.0 - cos(PX_GEO_PI * (double)j / (double)nh));
    px_geo_naca4_point(m, p, t, xc, 1, &out->x[k], &out->y[k]);
    ++k;
    if (j == 0) break;
  }
  for (size_t j = 1; j < nh; ++j) {
    double xc = 0.5 * (1.0 - cos(PX_GEO_PI * (double)j / (double)nh));
    px_geo_naca4_point(m, p, t, xc, 0, &out->x[k], &out->y[k]);
    ++k;
  }
  snprintf(out->source, sizeof out->source, "naca %s", digits);
  return PX_STATUS_OK;
}
