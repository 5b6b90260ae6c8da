/* Body contours for the vortex solver (see vortex_profile.h). */
#include "solvers/vortex/vortex_profile.h"

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

#define VX_PI 3.14159265358979323846

static enum px_status contour_alloc(struct px_context *ctx, struct px_vortex_contour *c, size_t n,
                                    int with_lines) {
  c->n = n;
  c->x = px_mem_alloc(ctx, "vortex.profile", n * sizeof(double));
  c->y = px_mem_alloc(ctx, "vortex.profile", n * sizeof(double));
  c->line = with_lines ? px_mem_calloc(ctx, "vortex.profile", n, sizeof(int)) : NULL;
  if (!c->x || !c->y || (with_lines && !c->line)) {
    px_vortex_contour_free(ctx, c);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for a profile of %zu points", n);
  }
  return PX_STATUS_OK;
}

void px_vortex_contour_free(struct px_context *ctx, struct px_vortex_contour *c) {
  if (!c) return;
  px_mem_free(ctx, c->x);
  px_mem_free(ctx, c->y);
  px_mem_free(ctx, c->line);
  c->x = c->y = NULL;
  c->line = NULL;
  c->n = 0;
}

double px_vortex_mean_panel_length(const struct px_vortex_contour *b, size_t nb) {
  double lmin = INFINITY;
  for (size_t i = 0; i < nb; ++i) {
    double per = 0.0;
    for (size_t k = 0; k < b[i].n; ++k) {
      size_t j = (k + 1) % b[i].n;
      per += hypot(b[i].x[j] - b[i].x[k], b[i].y[j] - b[i].y[k]);
    }
    lmin = fmin(lmin, per / (double)b[i].n);
  }
  return lmin;
}

static enum px_status check_panels(struct px_context *ctx, size_t n, const char *what) {
  if (n < PX_VORTEX_MIN_PANELS)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: %zu panels is too few (at least %d are needed; a few hundred "
                           "are usual)",
                           what, n, PX_VORTEX_MIN_PANELS);
  if (n > PX_VORTEX_MAX_PANELS)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: %zu panels is too many (at most %d)", what,
                           n, PX_VORTEX_MAX_PANELS);
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_circle(struct px_context *ctx, double radius, size_t n,
                                        struct px_vortex_contour *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, "circle"));
  if (!(radius > 0.0) || !isfinite(radius))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "circle: radius must be > 0 (got %g)", radius);
  PX_TRY(contour_alloc(ctx, out, n, 0));
  for (size_t k = 0; k < n; ++k) {
    double th = 2.0 * VX_PI * (double)k / (double)n;
    out->x[k] = radius * cos(th);
    out->y[k] = radius * sin(th);
  }
  snprintf(out->source, sizeof out->source, "circle");
  return PX_STATUS_OK;
}

/* Place n vertices equally spaced in arc length on a closed parametric curve
 * sampled densely at m points (px[i], py[i]), i = 0..m-1 (closed: the curve
 * returns to sample 0). The first vertex is sample 0. */
static void resample_closed(size_t m, const double *px, const double *py, size_t n, double *x,
                            double *y) {
  /* cumulative length */
  double total = 0.0;
  for (size_t i = 0; i < m; ++i) {
    size_t j = (i + 1) % m;
    total += hypot(px[j] - px[i], py[j] - py[i]);
  }
  double acc = 0.0;
  size_t i = 0;
  double seg = hypot(px[1 % m] - px[0], py[1 % m] - py[0]);
  for (size_t k = 0; k < n; ++k) {
    double target = total * (double)k / (double)n;
    while (acc + seg < target && i + 1 < m) {
      acc += seg;
      ++i;
      size_t j = (i + 1) % m;
      seg = hypot(px[j] - px[i], py[j] - py[i]);
    }
    size_t j = (i + 1) % m;
    double f = seg > 0.0 ? (target - acc) / seg : 0.0;
    if (f < 0.0) f = 0.0;
    if (f > 1.0) f = 1.0;
    x[k] = px[i] + f * (px[j] - px[i]);
    y[k] = py[i] + f * (py[j] - py[i]);
  }
}

enum px_status px_vortex_profile_ellipse(struct px_context *ctx, double a, double b, size_t n,
                                         struct px_vortex_contour *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, "ellipse"));
  if (!(a > 0.0) || !(b > 0.0) || !isfinite(a) || !isfinite(b))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "ellipse: semi-axes must be > 0 (got a = %g, b = %g)", a, b);
  size_t m = 64 * n;
  double *px = px_mem_alloc(ctx, "vortex.profile", 2 * m * sizeof(double));
  if (!px) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory for an ellipse");
  double *py = px + m;
  for (size_t i = 0; i < m; ++i) {
    double t = 2.0 * VX_PI * (double)i / (double)m;
    px[i] = a * cos(t);
    py[i] = b * sin(t);
  }
  enum px_status st = contour_alloc(ctx, out, n, 0);
  if (st == PX_STATUS_OK) resample_closed(m, px, py, n, out->x, out->y);
  px_mem_free(ctx, px);
  snprintf(out->source, sizeof out->source, "ellipse");
  return st;
}

/* Point at arc length s (0 <= s < perimeter) on a stadium: straight sides of
 * half-length a at y = +-h, semicircular ends of radius h centred at (+-a, 0),
 * starting at (a + h, 0) and running counter-clockwise. */
static void stadium_point(double a, double h, double s, double *x, double *y) {
  double q = 0.5 * VX_PI * h; /* quarter arc */
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
    double th = 0.5 * VX_PI + s / h;
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
  double th = 1.5 * VX_PI + s / h;
  *x = a + h * cos(th);
  *y = h * sin(th);
}

enum px_status px_vortex_profile_plate(struct px_context *ctx, double length, double thickness,
                                       size_t n, struct px_vortex_contour *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, "plate"));
  if (!(thickness > 0.0) || !(length > thickness) || !isfinite(length))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "plate: need 0 < thickness < length (got length %g, thickness %g)",
                           length, thickness);
  double h = 0.5 * thickness, a = 0.5 * length - h;
  double per = 4.0 * a + 2.0 * VX_PI * h;
  PX_TRY(contour_alloc(ctx, out, n, 0));
  for (size_t k = 0; k < n; ++k)
    stadium_point(a, h, per * (double)k / (double)n, &out->x[k], &out->y[k]);
  snprintf(out->source, sizeof out->source, "plate %g x %g", length, thickness);
  return PX_STATUS_OK;
}

/* NACA 4-digit section (Abbott & von Doenhoff, Theory of Wing Sections, 1959,
 * sec. 6.4), closed trailing edge: the last thickness coefficient is -0.1036
 * instead of -0.1015 so that y_t(1) = 0. */
static void naca4_point(double m, double p, double t, double xc, int upper, double *x, double *y) {
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

enum px_status px_vortex_profile_naca4(struct px_context *ctx, const char *digits, size_t n,
                                       struct px_vortex_contour *out) {
  memset(out, 0, sizeof *out);
  int ok = digits && strlen(digits) == 4;
  for (int i = 0; ok && i < 4; ++i) ok = isdigit((unsigned char)digits[i]) != 0;
  if (!ok)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "naca: expected 4 digits such as \"0012\" or \"2412\" (got \"%s\")",
                           digits ? digits : "");
  PX_TRY(check_panels(ctx, n, "naca"));
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
  PX_TRY(contour_alloc(ctx, out, n, 0));
  size_t nh = n / 2, k = 0;
  /* trailing edge -> upper surface -> leading edge -> lower surface */
  for (size_t j = nh;; --j) {
    double xc = 0.5 * (1.0 - cos(VX_PI * (double)j / (double)nh));
    naca4_point(m, p, t, xc, 1, &out->x[k], &out->y[k]);
    ++k;
    if (j == 0) break;
  }
  for (size_t j = 1; j < nh; ++j) {
    double xc = 0.5 * (1.0 - cos(VX_PI * (double)j / (double)nh));
    naca4_point(m, p, t, xc, 0, &out->x[k], &out->y[k]);
    ++k;
  }
  snprintf(out->source, sizeof out->source, "naca %s", digits);
  return PX_STATUS_OK;
}

/* ---------------------------------------------------------------------------
 * File input */

struct pts {
  size_t n, cap;
  double *x, *y;
  int *line;
};

static enum px_status pts_push(struct px_context *ctx, struct pts *p, double x, double y,
                               int line) {
  if (p->n == p->cap) {
    size_t cap = p->cap ? 2 * p->cap : 256;
    double *nx = px_mem_realloc(ctx, "vortex.profile", p->x, cap * sizeof(double));
    if (!nx) return PX_STATUS_NOMEM;
    p->x = nx;
    double *ny = px_mem_realloc(ctx, "vortex.profile", p->y, cap * sizeof(double));
    if (!ny) return PX_STATUS_NOMEM;
    p->y = ny;
    int *nl = px_mem_realloc(ctx, "vortex.profile", p->line, cap * sizeof(int));
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
 * one is beyond +-PX_VORTEX_FILE_MAX_COORD. */
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
  if (fabs(a) > PX_VORTEX_FILE_MAX_COORD || fabs(b) > PX_VORTEX_FILE_MAX_COORD) return -3;
  return 2;
}

/* Open a profile file for reading: a regular file of at most
 * PX_VORTEX_FILE_MAX_BYTES. O_NONBLOCK: opening a FIFO without a writer
 * returns at once instead of waiting (it is then refused as not regular);
 * it does not change how a regular file reads. */
static enum px_status open_profile(struct px_context *ctx, const char *path, FILE **out) {
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
  if (sb.st_size > PX_VORTEX_FILE_MAX_BYTES) {
    close(fd);
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: %lld bytes is more than a profile file may hold (%ld bytes, "
                           "%d points)",
                           path, (long long)sb.st_size, (long)PX_VORTEX_FILE_MAX_BYTES,
                           PX_VORTEX_FILE_MAX_POINTS);
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

/* One line of f into buf (size PX_VORTEX_FILE_MAX_LINE + 1, NUL-terminated,
 * without its newline), counting the bytes read into *total. Returns 1 for a
 * line, 0 at the end of the file, -1 for a line longer than
 * PX_VORTEX_FILE_MAX_LINE, -2 for a NUL byte in the line, -3 when the file
 * grew past PX_VORTEX_FILE_MAX_BYTES while being read. */
static int read_line(FILE *f, char *buf, long *total) {
  size_t len = 0;
  int c, nul = 0;
  while ((c = getc_unlocked(f)) != EOF) { /* f is this reader's own stream */
    if (++*total > PX_VORTEX_FILE_MAX_BYTES) return -3;
    if (c == '\n') break;
    if (c == '\0') nul = 1;
    if (len >= PX_VORTEX_FILE_MAX_LINE) return -1;
    buf[len++] = (char)c;
  }
  buf[len] = '\0';
  if (c == EOF && len == 0) return 0;
  return nul ? -2 : 1;
}

/* Read the points of a file. allow_title: the first non-blank line may be a
 * title (Selig). */
static enum px_status read_points(struct px_context *ctx, const char *path, int allow_title,
                                  struct pts *p, char *title, size_t title_size) {
  FILE *f = NULL;
  PX_TRY(open_profile(ctx, path, &f));
  char buf[PX_VORTEX_FILE_MAX_LINE + 1];
  int line = 0, first = 1;
  long total = 0;
  enum px_status st = PX_STATUS_OK;
  if (title && title_size) title[0] = '\0';
  for (;;) {
    int got = read_line(f, buf, &total);
    if (got == 0) break;
    ++line;
    if (got == -1) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: line longer than %d bytes (a profile line is \"x y\")", path,
                           line, PX_VORTEX_FILE_MAX_LINE);
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
                           path, line, (long)PX_VORTEX_FILE_MAX_BYTES);
      break;
    }
    double x = 0.0, y = 0.0;
    int r = parse_xy(buf, &x, &y);
    if (r == 0) continue;
    if (r == -1 && first && allow_title) {
      first = 0;
      if (title && title_size) {
        snprintf(title, title_size, "%.200s", buf);
        size_t l = strlen(title);
        while (l && isspace((unsigned char)title[l - 1])) title[--l] = '\0';
      }
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
                           path, line, PX_VORTEX_FILE_MAX_COORD, x, y);
      break;
    }
    if (p->n >= PX_VORTEX_FILE_MAX_POINTS) {
      st = px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s:%d: more than %d points (the most a profile file may hold)", path,
                           line, PX_VORTEX_FILE_MAX_POINTS);
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

static double spacing_fraction(enum px_vortex_spacing sp, size_t j, size_t n) {
  double u = (double)j / (double)n;
  if (sp == PX_VORTEX_SPACING_COSINE) return 0.5 * (1.0 - cos(VX_PI * u));
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

static void pts_reverse(struct pts *p, size_t n) {
  for (size_t i = 0, j = n - 1; i < j; ++i, --j) {
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

/* Copy raw points into a contour carrying their lines (for checks with line
 * numbers). */
static enum px_status pts_to_contour(struct px_context *ctx, const struct pts *p, size_t n,
                                     const char *path, struct px_vortex_contour *c) {
  PX_TRY(contour_alloc(ctx, c, n, 1));
  memcpy(c->x, p->x, n * sizeof(double));
  memcpy(c->y, p->y, n * sizeof(double));
  memcpy(c->line, p->line, n * sizeof(int));
  snprintf(c->source, sizeof c->source, "%s", path);
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_read_selig(struct px_context *ctx, const char *path, size_t n,
                                            enum px_vortex_spacing spacing,
                                            struct px_vortex_contour *out) {
  memset(out, 0, sizeof *out);
  PX_TRY(check_panels(ctx, n, path));
  struct pts p = {0};
  char title[256];
  PX_TRY(read_points(ctx, path, 1, &p, title, sizeof title));
  enum px_status st = PX_STATUS_OK;
  struct px_vortex_contour raw = {0};
  double *work = NULL;
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
  int open_te = 0;
  size_t np = p.n;
  if (gap <= 1e-9 * chord) {
    np = p.n - 1; /* explicit closure: drop the repeated point */
  } else if (gap <= 0.02 * chord) {
    open_te = 1;
  } else {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%s: contour not closed: the last point (line %d) is %g from the first "
                         "(line %d), more than 2%% of the chord %g; a Selig file starts and ends "
                         "at the trailing edge",
                         path, p.line[p.n - 1], gap, p.line[0], chord);
    goto done;
  }
  /* a clockwise file (lower surface first) is reversed whole, so that the
   * chain still starts and ends at the trailing edge */
  if (pts_signed_area(&p, np) < 0.0) pts_reverse(&p, np);
  /* checks on the raw polygon, naming file lines */
  st = pts_to_contour(ctx, &p, np, path, &raw);
  if (st != PX_STATUS_OK) goto done;
  int reversed = 0;
  st = px_vortex_profile_check(ctx, &raw, &reversed);
  if (st != PX_STATUS_OK) goto done;
  /* spline through the (oriented) points, closing the loop at the TE: the
   * chain runs TE -> ... -> TE(end) and for a closed TE the last knot is the
   * first point again */
  size_t m = np + 1; /* knots */
  if (open_te) m = np;
  work = px_mem_alloc(ctx, "vortex.profile", 6 * m * sizeof(double));
  if (!work) {
    st = px_context_fail(ctx, PX_STATUS_NOMEM, "%s: out of memory", path);
    goto done;
  }
  double *tk = work, *xk = work + m, *yk = work + 2 * m, *d2x = work + 3 * m, *d2y = work + 4 * m,
         *w = work + 5 * m;
  for (size_t i = 0; i < m; ++i) {
    xk[i] = raw.x[i % np];
    yk[i] = raw.y[i % np];
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
  st = contour_alloc(ctx, out, n, 0);
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
  px_vortex_contour_free(ctx, &raw);
  pts_free(ctx, &p);
  if (st != PX_STATUS_OK) px_vortex_contour_free(ctx, out);
  return st;
}

enum px_status px_vortex_profile_read_points(struct px_context *ctx, const char *path, size_t n,
                                             struct px_vortex_contour *out) {
  memset(out, 0, sizeof *out);
  struct pts p = {0};
  PX_TRY(read_points(ctx, path, 0, &p, NULL, 0));
  enum px_status st = PX_STATUS_OK;
  struct px_vortex_contour raw = {0};
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
  st = pts_to_contour(ctx, &p, p.n - 1, path, &raw);
  if (st != PX_STATUS_OK) goto done;
  if (n == 0) {
    int reversed = 0;
    st = px_vortex_profile_check(ctx, &raw, &reversed);
    if (st != PX_STATUS_OK) goto done;
    *out = raw;
    memset(&raw, 0, sizeof raw);
    goto done;
  }
  st = check_panels(ctx, n, path);
  if (st != PX_STATUS_OK) goto done;
  int reversed = 0;
  st = px_vortex_profile_check(ctx, &raw, &reversed);
  if (st != PX_STATUS_OK) goto done;
  st = contour_alloc(ctx, out, n, 0);
  if (st != PX_STATUS_OK) goto done;
  resample_closed(raw.n, raw.x, raw.y, n, out->x, out->y);
  snprintf(out->source, sizeof out->source, "%s", path);
done:
  px_vortex_contour_free(ctx, &raw);
  pts_free(ctx, &p);
  if (st != PX_STATUS_OK) px_vortex_contour_free(ctx, out);
  return st;
}

void px_vortex_profile_place_point(double x, double y, double x0, double y0, double scale,
                                   double angle_deg, double *ox, double *oy) {
  double a = -angle_deg * VX_PI / 180.0; /* clockwise */
  double ca = cos(a), sa = sin(a), sx = scale * x, sy = scale * y;
  *ox = x0 + ca * sx - sa * sy;
  *oy = y0 + sa * sx + ca * sy;
}

void px_vortex_profile_place(struct px_vortex_contour *c, double x0, double y0, double scale,
                             double angle_deg) {
  for (size_t k = 0; k < c->n; ++k)
    px_vortex_profile_place_point(c->x[k], c->y[k], x0, y0, scale, angle_deg, &c->x[k], &c->y[k]);
}

double px_vortex_profile_area(const struct px_vortex_contour *c) {
  double s = 0.0;
  for (size_t k = 0; k < c->n; ++k) {
    size_t j = (k + 1) % c->n;
    s += c->x[k] * c->y[j] - c->x[j] * c->y[k];
  }
  return 0.5 * s;
}

int px_vortex_profile_contains(const struct px_vortex_contour *c, double x, double y) {
  int in = 0;
  for (size_t k = 0, j = c->n - 1; k < c->n; j = k++) {
    if ((c->y[k] > y) != (c->y[j] > y)) {
      double xc = c->x[k] + (y - c->y[k]) * (c->x[j] - c->x[k]) / (c->y[j] - c->y[k]);
      if (x < xc) in = !in;
    }
  }
  return in;
}

static double orient(double ax, double ay, double bx, double by, double cx, double cy) {
  return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
}

/* Closed segments [p1,p2] and [p3,p4] intersect (touching counts). */
static int segments_intersect(double x1, double y1, double x2, double y2, double x3, double y3,
                              double x4, double y4) {
  if (fmax(x1, x2) < fmin(x3, x4) || fmax(x3, x4) < fmin(x1, x2) || fmax(y1, y2) < fmin(y3, y4) ||
      fmax(y3, y4) < fmin(y1, y2))
    return 0;
  double d1 = orient(x3, y3, x4, y4, x1, y1), d2 = orient(x3, y3, x4, y4, x2, y2);
  double d3 = orient(x1, y1, x2, y2, x3, y3), d4 = orient(x1, y1, x2, y2, x4, y4);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0)))
    return 1;
  /* collinear or touching cases */
  if (d1 == 0.0 && fmin(x3, x4) <= x1 && x1 <= fmax(x3, x4) && fmin(y3, y4) <= y1 &&
      y1 <= fmax(y3, y4))
    return 1;
  if (d2 == 0.0 && fmin(x3, x4) <= x2 && x2 <= fmax(x3, x4) && fmin(y3, y4) <= y2 &&
      y2 <= fmax(y3, y4))
    return 1;
  if (d3 == 0.0 && fmin(x1, x2) <= x3 && x3 <= fmax(x1, x2) && fmin(y1, y2) <= y3 &&
      y3 <= fmax(y1, y2))
    return 1;
  if (d4 == 0.0 && fmin(x1, x2) <= x4 && x4 <= fmax(x1, x2) && fmin(y1, y2) <= y4 &&
      y4 <= fmax(y1, y2))
    return 1;
  return 0;
}

/* A tree of boxes over runs of consecutive panels of a contour (panel k:
 * vertex k -> vertex k+1 mod n): node 0 spans all panels, a node of more
 * than VX_SEG_LEAF panels has two children (consecutive, left first) that
 * split its range in halves; the crossing tests visit only the nodes whose
 * boxes overlap the panel tested. Leaves hold 4..8 panels, so there are at
 * most 2 (n / 4 + 1) nodes and the depth is below 64. */
#define VX_SEG_LEAF 8
struct seg_tree {
  size_t nnode;
  size_t *lo, *hi;               /* owned: panel range [lo, hi) of each node */
  size_t *left;                  /* owned: first child, 0 for a leaf */
  double *bx0, *by0, *bx1, *by1; /* owned: box of each node */
};

static void seg_tree_free(struct px_context *ctx, struct seg_tree *t) {
  px_mem_free(ctx, t->lo);
  px_mem_free(ctx, t->bx0);
  memset(t, 0, sizeof *t);
}

static enum px_status seg_tree_build(struct px_context *ctx, const struct px_vortex_contour *c,
                                     struct seg_tree *t) {
  const size_t n = c->n, cap = 2 * (n / 4 + 1) + 8;
  memset(t, 0, sizeof *t);
  t->lo = px_mem_alloc(ctx, "vortex.profile", 3 * cap * sizeof(size_t));
  t->bx0 = px_mem_alloc(ctx, "vortex.profile", 4 * cap * sizeof(double));
  if (!t->lo || !t->bx0) {
    seg_tree_free(ctx, t);
    return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory checking a contour of %zu panels",
                           n);
  }
  t->hi = t->lo + cap;
  t->left = t->lo + 2 * cap;
  t->by0 = t->bx0 + cap;
  t->bx1 = t->bx0 + 2 * cap;
  t->by1 = t->bx0 + 3 * cap;
  t->lo[0] = 0;
  t->hi[0] = n;
  size_t count = 1;
  for (size_t k = 0; k < count; ++k) {
    size_t lo = t->lo[k], hi = t->hi[k];
    t->left[k] = 0;
    if (hi - lo > VX_SEG_LEAF && count + 2 <= cap) {
      size_t mid = lo + (hi - lo) / 2;
      t->left[k] = count;
      t->lo[count] = lo;
      t->hi[count] = mid;
      t->lo[count + 1] = mid;
      t->hi[count + 1] = hi;
      count += 2;
    }
  }
  t->nnode = count;
  for (size_t k = count; k-- > 0;) {
    if (!t->left[k]) {
      double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
      for (size_t i = t->lo[k]; i < t->hi[k]; ++i) {
        size_t j = (i + 1) % n;
        x0 = fmin(x0, fmin(c->x[i], c->x[j]));
        x1 = fmax(x1, fmax(c->x[i], c->x[j]));
        y0 = fmin(y0, fmin(c->y[i], c->y[j]));
        y1 = fmax(y1, fmax(c->y[i], c->y[j]));
      }
      t->bx0[k] = x0;
      t->by0[k] = y0;
      t->bx1[k] = x1;
      t->by1[k] = y1;
    } else {
      size_t a = t->left[k], b = a + 1;
      t->bx0[k] = fmin(t->bx0[a], t->bx0[b]);
      t->by0[k] = fmin(t->by0[a], t->by0[b]);
      t->bx1[k] = fmax(t->bx1[a], t->bx1[b]);
      t->by1[k] = fmax(t->by1[a], t->by1[b]);
    }
  }
  return PX_STATUS_OK;
}

/* The smallest panel j >= jmin of contour c (tree t) other than `skip` whose
 * closed segment meets the segment (x1, y1) -> (x2, y2): its index, or
 * (size_t)-1 for none; (size_t)-2 when *budget (box and segment tests left)
 * runs out first. Boxes are compared as segments_intersect does (touching
 * counts), so no crossing it would find is pruned. */
static size_t seg_tree_first(const struct px_vortex_contour *c, const struct seg_tree *t, double x1,
                             double y1, double x2, double y2, size_t jmin, size_t skip,
                             double *budget) {
  const double qx0 = fmin(x1, x2), qx1 = fmax(x1, x2), qy0 = fmin(y1, y2), qy1 = fmax(y1, y2);
  size_t stack[160], top = 0;
  if (t->nnode == 0) return (size_t)-1;
  stack[top++] = 0;
  while (top) {
    size_t k = stack[--top];
    *budget -= 1.0;
    if (*budget < 0.0) return (size_t)-2;
    if (t->hi[k] <= jmin || t->bx1[k] < qx0 || qx1 < t->bx0[k] || t->by1[k] < qy0 ||
        qy1 < t->by0[k])
      continue;
    if (t->left[k]) {
      stack[top++] = t->left[k] + 1; /* right after left: the smallest j first */
      stack[top++] = t->left[k];
      continue;
    }
    for (size_t j = t->lo[k] > jmin ? t->lo[k] : jmin; j < t->hi[k]; ++j) {
      if (j == skip) continue;
      *budget -= 1.0;
      size_t j1 = (j + 1) % c->n;
      if (segments_intersect(x1, y1, x2, y2, c->x[j], c->y[j], c->x[j1], c->y[j1])) return j;
    }
    if (*budget < 0.0) return (size_t)-2;
  }
  return (size_t)-1;
}

/* "panel 12 (line 14 -> line 15)" or "panel 12 ((x, y) -> (x, y))" */
static void describe_panel(const struct px_vortex_contour *c, size_t k, char *buf, size_t size) {
  size_t j = (k + 1) % c->n;
  if (c->line)
    snprintf(buf, size, "the segment from line %d to line %d", c->line[k], c->line[j]);
  else
    snprintf(buf, size, "panel %zu ((%g, %g) -> (%g, %g))", k, c->x[k], c->y[k], c->x[j], c->y[j]);
}

static void reverse_contour(struct px_vortex_contour *c) {
  /* keep vertex 0 first: reverse vertices 1..n-1 */
  for (size_t i = 1, j = c->n - 1; i < j; ++i, --j) {
    double t = c->x[i];
    c->x[i] = c->x[j];
    c->x[j] = t;
    t = c->y[i];
    c->y[i] = c->y[j];
    c->y[j] = t;
    if (c->line) {
      int l = c->line[i];
      c->line[i] = c->line[j];
      c->line[j] = l;
    }
  }
}

enum px_status px_vortex_profile_check(struct px_context *ctx, struct px_vortex_contour *c,
                                       int *reversed) {
  *reversed = 0;
  const char *src = c->source[0] ? c->source : "profile";
  if (c->n < 3)
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: a contour needs at least 3 points (got %zu)",
                           src, c->n);
  for (size_t k = 0; k < c->n; ++k) {
    if (!isfinite(c->x[k]) || !isfinite(c->y[k])) {
      if (c->line)
        return px_context_fail(ctx, PX_STATUS_CONFIG, "%s:%d: coordinate is not finite", src,
                               c->line[k]);
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: vertex %zu has a non-finite coordinate (%g, %g)", src, k, c->x[k],
                             c->y[k]);
    }
  }
  double size = 0.0;
  for (size_t k = 1; k < c->n; ++k) size = fmax(size, hypot(c->x[k] - c->x[0], c->y[k] - c->y[0]));
  for (size_t k = 0; k < c->n; ++k) {
    size_t j = (k + 1) % c->n;
    if (hypot(c->x[j] - c->x[k], c->y[j] - c->y[k]) <= 1e-12 * size) {
      if (c->line)
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "%s:%d: point repeats the point of line %d (zero-length segment)",
                               src, c->line[j], c->line[k]);
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: vertices %zu and %zu coincide (zero-length panel)", src, k, j);
    }
  }
  /* self-intersection: folds of adjacent panels (a panel running straight
   * back along the previous one), then every pair of non-adjacent panels
   * whose boxes overlap (seg_tree) */
  size_t n = c->n;
  for (size_t k = 0; k < n; ++k) {
    size_t k1 = (k + 1) % n, k2 = (k + 2) % n;
    double ax = c->x[k1] - c->x[k], ay = c->y[k1] - c->y[k];
    double bx = c->x[k2] - c->x[k1], by = c->y[k2] - c->y[k1];
    double cr = ax * by - ay * bx, dt = ax * bx + ay * by;
    if (dt < 0.0 && fabs(cr) <= 1e-12 * hypot(ax, ay) * hypot(bx, by)) {
      char d1[160];
      describe_panel(c, k, d1, sizeof d1);
      return px_context_fail(ctx, PX_STATUS_CONFIG,
                             "%s: the contour folds back on itself at %s (self-intersection)", src,
                             d1);
    }
  }
  struct seg_tree t;
  PX_TRY(seg_tree_build(ctx, c, &t));
  double budget = PX_VORTEX_CHECK_BUDGET(n);
  size_t hit = (size_t)-1, k = 0;
  for (k = 0; k < n; ++k) {
    size_t k1 = (k + 1) % n;
    /* j > k + 1: not adjacent; panel n - 1 is adjacent to panel 0 through
       the closure */
    hit = seg_tree_first(c, &t, c->x[k], c->y[k], c->x[k1], c->y[k1], k + 2,
                         k == 0 ? n - 1 : (size_t)-1, &budget);
    if (hit != (size_t)-1) break;
  }
  seg_tree_free(ctx, &t);
  if (hit == (size_t)-2)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "%s: the self-intersection check of this contour of %zu panels gave up "
                           "after %.3g tests at panel %zu: too many of its panels lie close "
                           "together (a smooth contour needs 30-45 tests per panel)",
                           src, n, PX_VORTEX_CHECK_BUDGET(n), k);
  if (hit != (size_t)-1) {
    char d1[160], d2[160];
    describe_panel(c, k, d1, sizeof d1);
    describe_panel(c, hit, d2, sizeof d2);
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: self-intersecting contour: %s crosses %s",
                           src, d1, d2);
  }
  double area = px_vortex_profile_area(c);
  if (!(fabs(area) > 1e-12 * size * size))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: the contour encloses no area", src);
  if (area < 0.0) {
    reverse_contour(c);
    *reversed = 1;
  }
  return PX_STATUS_OK;
}

enum px_status px_vortex_profile_check_pair(struct px_context *ctx,
                                            const struct px_vortex_contour *a,
                                            const struct px_vortex_contour *b) {
  struct seg_tree t;
  PX_TRY(seg_tree_build(ctx, b, &t));
  double budget = PX_VORTEX_CHECK_BUDGET(a->n + b->n);
  size_t hit = (size_t)-1, k = 0;
  for (k = 0; k < a->n; ++k) {
    size_t k1 = (k + 1) % a->n;
    hit = seg_tree_first(b, &t, a->x[k], a->y[k], a->x[k1], a->y[k1], 0, (size_t)-1, &budget);
    if (hit != (size_t)-1) break;
  }
  seg_tree_free(ctx, &t);
  if (hit == (size_t)-2)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "bodies %s and %s: the overlap check gave up after %.3g tests at "
                           "panel %zu of the first: too many of their panels lie close together",
                           a->source, b->source, PX_VORTEX_CHECK_BUDGET(a->n + b->n), k);
  if (hit != (size_t)-1)
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "bodies %s and %s overlap: panel %zu of the first crosses panel "
                           "%zu of the second",
                           a->source, b->source, k, hit);
  if (px_vortex_profile_contains(b, a->x[0], a->y[0]) ||
      px_vortex_profile_contains(a, b->x[0], b->y[0]))
    return px_context_fail(ctx, PX_STATUS_CONFIG,
                           "bodies %s and %s overlap: one lies inside the other", a->source,
                           b->source);
  return PX_STATUS_OK;
}
