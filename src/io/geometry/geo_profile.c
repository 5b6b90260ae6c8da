/* Contours read from profile files: Selig airfoils, closed point lists, and
 * the spline re-panelling of an airfoil (geo_profile.h). */
#include "io/geometry/geo_profile.h"

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "partix/memory.h"

#define PX_GEO_PI 3.14159265358979323846

struct pts {
  size_t n, cap;
  double *x, *y;
  int *line;
};

static enum px_status pts_push(struct px_context *ctx, struct pts *p, double x, double y,
                               int line) {
  if (p->n == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 256;
    double *nx = px_mem_realloc(ctx, "geometry profile", p->x, cap * sizeof(double));
    if (!nx) return PX_STATUS_NOMEM;
    p->x = nx;
    double *ny = px_mem_realloc(ctx, "geometry profile", p->y, cap * sizeof(double));
    if (!ny) return PX_STATUS_NOMEM;
    p->y = ny;
    int *nl = px_mem_realloc(ctx, "geometry profile", p->line, cap * sizeof(int));
    if (!nl) return PX_STATUS_NOMEM;
    p->line = nl;
    p->cap = cap;
  }
  p->x[p->n] = x;
  p->y[p->n] = y;
  p->line[p->n] = line;
  p->n++;
  return PX_STATUS_OK;
}

static void pts_free(struct px_context *ctx, struct pts *p) {
  px_mem_free(ctx, p->x);
  px_mem_free(ctx, p->y);
  px_mem_free(ctx, p->line);
  memset(p, 0, sizeof *p);
}

/* Parse "x y" from s. Returns 2 on success, 0 for a blank/comment line, -1
 * when the line is not two numbers, -2 when a number is not finite, -3 when
 * one is beyond +-PX_GEO_PROFILE_MAX_COORD. */
static int parse_xy(const char *s, double *x, double *y) {
  while (*s && isspace((unsigned char)*s)) ++s;
  if (!*s || *s == '#') return 0;
  char *end;
  errno = 0;
  double a = strtod(s, &end);
  if (end == s) return -1;
  s = end;
  while (*s == ',' || isspace((unsigned char)*s)) ++s;
  double b = strtod(s, &end);
  if (end == s) return -1;
  s = end;
  while (*s && isspace((unsigned char)*s)) ++s;
  if (*s && *s != '#') return -1;
  *x = a;
  *y = b;
  if (!isfinite(a) || !isfinite(b)) return -2;
  if (fabs(a) > PX_GEO_PROFILE_MAX_COORD || fabs(b) > PX_GEO_PROFILE_MAX_COORD) return -3;
  return 2;
}

/* Open a profile file for reading: a regular file of at most
 * PX_GEO_PROFILE_MAX_BYTES. O_NONBLOCK: opening a FIFO without a writer
 * returns at once instead of waiting (it is then refused as not regular);
 * it does not change how a regular file reads. */
static enum px_status open_profile(struct px_context *ctx, const char *path, int max_points,
                                   FILE **out) {
  *out = NULL;
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0)
    return px_context_fail(ctx, PX_STATUS_IO, "%s: cannot open profile file: %s", path,
                           strerror(errno));
  struct stat sb;
  if (fstat(fd, &sb) != 0) {
    int err = errno;
    close(fd);
    return px_context_fail(ctx, PX_STATUS_IO, "%s: cannot stat profile file: %s", path,
                           strerror(err));
  }
  if (!S_ISREG(sb.st_mode)) {
    close(fd);
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: not a regular file (a %s); a profile is read from a plain text "
                           "file",
                           path,
                           S_ISDIR(sb.st_mode)    ? "directory"
                           : S_ISCHR(sb.st_mode)  ? "character device"
                           : S_ISBLK(sb.st_mode)  ? "block device"
                           : S_ISFIFO(sb.st_mode) ? "pipe"
                           : S_ISSOCK(sb.st_mode) ? "socket"
                                                  : "special file");
  }
  if (sb.st_size > PX_GEO_PROFILE_MAX_BYTES) {
    close(fd);
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: %lld bytes is more than a profile file may hold (%ld bytes, "
                           "%d points)",
                           path, (long long)sb.st_size, (long)PX_GEO_PROFILE_MAX_BYTES, max_points);
  }
  FILE *f = fdopen(fd, "r");
  if (!f) {
    int err = errno;
    close(fd);
    return px_context_fail(ctx, PX_STATUS_IO, "%s: cannot read profile file: %s", path,
                           strerror(err));
  }
  *out = f;
  return PX_STATUS_OK;
}

/* One line of f into buf (size PX_GEO_PROFILE_MAX_LINE + 1, NUL-terminated,
 * without its newline), counting the bytes read into *total. Returns 1 for a
 * line, 0 at the end of the file, -1 for a line longer than
 * PX_GEO_PROFILE_MAX_LINE, -2 for a NUL byte in the line, -3 when the file
 * grew past PX_GEO_PROFILE_MAX_BYTES while being read. */
static int read_line(FILE *f, char *buf, long *total) {
  size_t len = 0;
  int c, nul = 0;
  while ((c = getc_unlocked(f)) != EOF) { /* f is this reader's own stream */
    if (++*total > PX_GEO_PROFILE_MAX_BYTES) return -3;
    if (c == '\n') break;
    if (c == '\0') nul = 1;
    if (len >= PX_GEO_PROFILE_MAX_LINE) return -1;
    buf[len++] = (char)c;
  }
  buf[len] = '\0';
  if (c == EOF && len == 0) return 0;
  return nul ? -2 : 1;
}

/* Read the points of a file. allow_title: the first non-blank line may be a
 * title (Selig). */
static enum px_status read_points(struct px_context *ctx, const char *path, int allow_title,
                                  int max_points, struct pts *p) {
  FILE *f = NULL;
  PX_TRY(open_profile(ctx, path, max_points, &f));
  char buf[PX_GEO_PROFILE_MAX_LINE + 1];
  int line = 0, first = 1;
  long total = 0;
  enum px_status st = PX_STATUS_OK;
  for (;;) {
    int got = read_line(f, buf, &total);
    if (got == 0) break;
    ++line;
    if (got == -1) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: line longer than %d bytes (a profile line is \"x y\")", path,
                           line, PX_GEO_PROFILE_MAX_LINE);
      break;
    }
    if (got == -2) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG, "%s:%d: NUL byte in the line: not a text file",
                           path, line);
      break;
    }
    if (got == -3) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: the file grew past %ld bytes while being read (the most a "
                           "profile file may hold)",
                           path, line, (long)PX_GEO_PROFILE_MAX_BYTES);
      break;
    }
    double x = 0.0, y = 0.0;
    int r = parse_xy(buf, &x, &y);
    if (r == 0) continue;
    if (r == -1 && first && allow_title) {
      first = 0; /* the title */
      continue;
    }
    first = 0;
    if (r == -1) {
      size_t l = strlen(buf);
      while (l && isspace((unsigned char)buf[l - 1])) buf[--l] = '\0';
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: expected two numbers \"x y\" on this line, found \"%.60s\"",
                           path, line, buf);
      break;
    }
    if (r == -2) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: coordinate is not a finite number (x = %g, y = %g)", path, line,
                           x, y);
      break;
    }
    if (r == -3) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: coordinate beyond +-%g (x = %g, y = %g): a profile is given in "
                           "its own units and placed with scale and position",
                           path, line, PX_GEO_PROFILE_MAX_COORD, x, y);
      break;
    }
    if (p->n >= (size_t)(max_points > 0 ? max_points : 0)) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: more than %d points (the most a profile file may hold)", path,
                           line, max_points);
      break;
    }
    if (pts_push(ctx, p, x, y, line) != PX_STATUS_OK) {
      st = px_context_fail(ctx, PX_STATUS_NOMEM, "%s: out of memory reading the profile", path);
      break;
    }
  }
  if (st == PX_STATUS_OK && ferror(f))
    st = px_context_fail(ctx, PX_STATUS_IO, "%s: read error", path);
  fclose(f);
  if (st != PX_STATUS_OK) pts_free(ctx, p);
  return st;
}

/* Natural cubic spline through (t[i], f[i]), i = 0..m-1: second derivatives
 * into d2 (work: m doubles). */
static void spline_build(size_t m, const double *t, const double *f, double *d2, double *work) {
  d2[0] = 0.0;
  work[0] = 0.0;
  for (size_t i = 1; i + 1 < m; ++i) {
    double sig = (t[i] - t[i - 1]) / (t[i + 1] - t[i - 1]);
    double pp = sig * d2[i - 1] + 2.0;
    d2[i] = (sig - 1.0) / pp;
    double dd = (f[i + 1] - f[i]) / (t[i + 1] - t[i]) - (f[i] - f[i - 1]) / (t[i] - t[i - 1]);
    work[i] = (6.0 * dd / (t[i + 1] - t[i - 1]) - sig * work[i - 1]) / pp;
  }
  d2[m - 1] = 0.0;
  for (size_t i = m - 1; i-- > 0;) d2[i] = d2[i] * d2[i + 1] + work[i];
}

static double spline_eval(size_t m, const double *t, const double *f, const double *d2, double u) {
  size_t lo = 0, hi = m - 1;
  while (hi - lo > 1) {
    size_t mid = (lo + hi) / 2;
    if (t[mid] > u)
      hi = mid;
    else
      lo = mid;
  }
  double h = t[hi] - t[lo];
  double a = (t[hi] - u) / h, b = (u - t[lo]) / h;
  return a * f[lo] + b * f[hi] +
         ((a * a * a - a) * d2[lo] + (b * b * b - b) * d2[hi]) * (h * h) / 6.0;
}

static double spacing_fraction(enum px_geo_spacing sp, size_t j, size_t n) {
  double u = (double)j / (double)n;
  if (sp == PX_GEO_SPACING_COSINE) return 0.5 * (1.0 - cos(PX_GEO_PI * u));
  return u;
}

static double pts_signed_area(const struct pts *p, size_t n) {
  double s = 0.0;
  for (size_t k = 0; k < n; ++k) {
    size_t j = (k + 1) % n;
    s += p->x[k] * p->y[j] - p->x[j] * p->y[k];
  }
  return 0.5 * s;
}

/* Reverse points first..n-1 in place. */
static void pts_reverse(struct pts *p, size_t first, size_t n) {
  for (size_t i = first, j = n - 1; i < j; ++i, --j) {
    double t = p->x[i];
    p->x[i] = p->x[j];
    p->x[j] = t;
    t = p->y[i];
    p->y[i] = p->y[j];
    p->y[j] = t;
    int l = p->line[i];
    p->line[i] = p->line[j];
    p->line[j] = l;
  }
}

/* The first n raw points as a polyline carrying their lines (for checks
 * with line numbers). */
static enum px_status pts_to_polyline(struct px_context *ctx, const struct pts *p, size_t n,
                                      const char *path, struct px_geo_polyline *c) {
  PX_TRY(px_geo_polyline_alloc(ctx, c, n, 1));
  memcpy(c->x, p->x, n * sizeof(double));
  memcpy(c->y, p->y, n * sizeof(double));
  memcpy(c->line, p->line, n * sizeof(int));
  snprintf(c->source, sizeof c->source, "%s", path);
  return PX_STATUS_OK;
}

enum px_status px_geo_profile_read_selig(struct px_context *ctx, const char *path, int max_points,
                                         struct px_geo_polyline *out, int *open_te) {
  memset(out, 0, sizeof *out);
  *open_te = 0;
  struct pts p = {0};
  PX_TRY(read_points(ctx, path, 1, max_points, &p));
  enum px_status st = PX_STATUS_OK;
  if (p.n >= 2 && p.x[0] > 1.5 && p.y[0] > 1.5 && p.x[0] == floor(p.x[0]) &&
      p.y[0] == floor(p.y[0])) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%s:%d: \"%g %g\" looks like the point counts of a Lednicer-format file; "
                         "this reader expects the Selig format (trailing edge -> upper surface "
                         "-> leading edge -> lower surface -> trailing edge)",
                         path, p.line[0], p.x[0], p.y[0]);
    goto done;
  }
  if (p.n < 5) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG, "%s: only %zu points; an airfoil needs at least 5",
                         path, p.n);
    goto done;
  }
  /* chord: extent in x */
  double xmin = p.x[0], xmax = p.x[0];
  for (size_t i = 0; i < p.n; ++i) {
    if (p.x[i] < xmin) xmin = p.x[i];
    if (p.x[i] > xmax) xmax = p.x[i];
  }
  double chord = xmax - xmin;
  if (!(chord > 0.0)) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG, "%s: all points have the same x", path);
    goto done;
  }
  double gap = hypot(p.x[p.n - 1] - p.x[0], p.y[p.n - 1] - p.y[0]);
  size_t np = p.n;
  if (gap <= 1e-9 * chord) {
    np = p.n - 1; /* explicit closure: drop the repeated point */
  } else if (gap <= 0.02 * chord) {
    *open_te = 1;
  } else {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%s: contour not closed: the last point (line %d) is %g from the first "
                         "(line %d), more than 2%% of the chord %g; a Selig file starts and ends "
                         "at the trailing edge",
                         path, p.line[p.n - 1], gap, p.line[0], chord);
    goto done;
  }
  /* a clockwise file (lower surface first) is turned around so that the
   * chain still starts (and, open, ends) at the trailing edge: a closed
   * trailing edge keeps its point first and reverses the rest, as the
   * counter-clockwise file lists them (the repeated closing point was
   * dropped above); an open one swaps its two trailing-edge points with the
   * rest, reversed whole */
  if (pts_signed_area(&p, np) < 0.0) pts_reverse(&p, np < p.n ? 1 : 0, np);
  st = pts_to_polyline(ctx, &p, np, path, out);
done:
  pts_free(ctx, &p);
  if (st != PX_STATUS_OK) *open_te = 0;
  return st;
}

enum px_status px_geo_profile_read_points(struct px_context *ctx, const char *path, int max_points,
                                          struct px_geo_polyline *out) {
  memset(out, 0, sizeof *out);
  struct pts p = {0};
  PX_TRY(read_points(ctx, path, 0, max_points, &p));
  enum px_status st = PX_STATUS_OK;
  if (p.n < 4) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%s: only %zu points; a closed contour needs at least 3 distinct points "
                         "and the first repeated at the end",
                         path, p.n);
    goto done;
  }
  double size = 0.0;
  for (size_t i = 1; i < p.n; ++i) {
    double d = hypot(p.x[i] - p.x[0], p.y[i] - p.y[0]);
    if (d > size) size = d;
  }
  double gap = hypot(p.x[p.n - 1] - p.x[0], p.y[p.n - 1] - p.y[0]);
  if (gap > 1e-9 * size) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%s: contour not closed: the last point (line %d: %g %g) differs from "
                         "the first (line %d: %g %g); repeat the first point at the end to close "
                         "it",
                         path, p.line[p.n - 1], p.x[p.n - 1], p.y[p.n - 1], p.line[0], p.x[0],
                         p.y[0]);
    goto done;
  }
  st = pts_to_polyline(ctx, &p, p.n - 1, path, out);
done:
  pts_free(ctx, &p);
  return st;
}

enum px_status px_geo_profile_repanel_selig(struct px_context *ctx, const char *path,
                                            const double *x, const double *y, size_t np,
                                            int open_te, size_t n, enum px_geo_spacing spacing,
                                            struct px_geo_polyline *out) {
  memset(out, 0, sizeof *out);
  if (n < 4 || np < 3)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: %zu points re-panelled to %zu panels: at least 3 points and 4 "
                           "panels are needed",
                           path, np, n);
  for (size_t i = 0; i < np; ++i)
    if (x[i] == x[(i + 1) % np] && y[i] == y[(i + 1) % np])
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: points %zu and %zu coincide: no spline through them", path, i + 1,
                             (i + 1) % np + 1);
  enum px_status st = PX_STATUS_OK;
  /* spline through the (oriented) points, closing the loop at the TE: the
   * chain runs TE -> ... -> TE(end) and for a closed TE the last knot is the
   * first point again */
  size_t m = np + 1; /* knots */
  if (open_te) m = np;
  double *work = px_mem_alloc(ctx, "geometry profile", 6 * m * sizeof(double));
  if (!work) return px_context_fail(ctx, PX_STATUS_NOMEM, "%s: out of memory", path);
  double *tk = work, *xk = work + m, *yk = work + 2 * m, *d2x = work + 3 * m, *d2y = work + 4 * m,
         *w = work + 5 * m;
  for (size_t i = 0; i < m; ++i) {
    xk[i] = x[i % np];
    yk[i] = y[i % np];
    tk[i] = i ? tk[i - 1] + hypot(xk[i] - xk[i - 1], yk[i] - yk[i - 1]) : 0.0;
  }
  spline_build(m, tk, xk, d2x, w);
  spline_build(m, tk, yk, d2y, w);
  /* leading edge: minimum x of the spline near the minimum-x knot */
  size_t ile = 0;
  for (size_t i = 0; i < m; ++i)
    if (xk[i] < xk[ile]) ile = i;
  double lo = tk[ile ? ile - 1 : 0], hi = tk[ile + 1 < m ? ile + 1 : m - 1];
  for (int it = 0; it < 100; ++it) {
    double a = lo + (hi - lo) * 0.381966011250105, b = hi - (hi - lo) * 0.381966011250105;
    if (spline_eval(m, tk, xk, d2x, a) < spline_eval(m, tk, xk, d2x, b))
      hi = b;
    else
      lo = a;
  }
  double ule = 0.5 * (lo + hi), utot = tk[m - 1];
  if (!(ule > 0.0 && ule < utot)) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%s: the leading edge (minimum x) is at an end of the point list; a "
                         "Selig file starts and ends at the trailing edge",
                         path);
    goto done;
  }
  size_t ncurve = open_te ? n - 1 : n; /* panels along the spline */
  size_t nu = ncurve / 2, nl = ncurve - nu;
  st = px_geo_polyline_alloc(ctx, out, n, 0);
  if (st != PX_STATUS_OK) goto done;
  size_t k = 0;
  for (size_t j = 0; j < nu; ++j) {
    double u = ule * spacing_fraction(spacing, j, nu);
    out->x[k] = spline_eval(m, tk, xk, d2x, u);
    out->y[k] = spline_eval(m, tk, yk, d2y, u);
    ++k;
  }
  size_t jend = open_te ? nl + 1 : nl; /* open TE: the lower TE point is a vertex */
  for (size_t j = 0; j < jend; ++j) {
    double u = ule + (utot - ule) * spacing_fraction(spacing, j, nl);
    out->x[k] = spline_eval(m, tk, xk, d2x, u);
    out->y[k] = spline_eval(m, tk, yk, d2y, u);
    ++k;
  }
  snprintf(out->source, sizeof out->source, "%s", path);
  if (k != n) st = px_context_fail(ctx, PX_STATUS_INTERNAL, "%s: re-panelling miscounted", path);
done:
  px_mem_free(ctx, work);
  if (st != PX_STATUS_OK) px_geo_polyline_free(ctx, out);
  return st;
}
