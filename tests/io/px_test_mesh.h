/* Closed triangle meshes of simple solids for the mesh tests, as triangle
 * soups (9 coordinates a triangle, counter-clockwise seen from outside),
 * and their STL (ASCII, binary) and OBJ texts. Vertices at multiples of 90
 * degrees are exact (cos = 0, +-1), so that planes through them hit them. */
#ifndef PX_TEST_MESH_H
#define PX_TEST_MESH_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define TM_PI 3.14159265358979323846

struct tm_soup {
  size_t nt, cap;
  double *p; /* 9 nt */
};

static inline void tm_tri(struct tm_soup *s, const double *a, const double *b, const double *c) {
  if (s->nt == s->cap) {
    s->cap = s->cap ? 2 * s->cap : 64;
    s->p = realloc(s->p, s->cap * 9 * sizeof(double));
    if (!s->p) abort();
  }
  memcpy(s->p + 9 * s->nt, a, 3 * sizeof(double));
  memcpy(s->p + 9 * s->nt + 3, b, 3 * sizeof(double));
  memcpy(s->p + 9 * s->nt + 6, c, 3 * sizeof(double));
  s->nt++;
}

/* a b c d counter-clockwise seen from outside: split along a-c. */
static inline void tm_quad(struct tm_soup *s, const double *a, const double *b, const double *c,
                           const double *d) {
  tm_tri(s, a, b, c);
  tm_tri(s, a, c, d);
}

static inline void tm_free(struct tm_soup *s) {
  free(s->p);
  memset(s, 0, sizeof *s);
}

static inline void tm_box(struct tm_soup *s, const double lo[3], const double hi[3]) {
  double v[8][3];
  for (int i = 0; i < 8; ++i) {
    v[i][0] = i & 1 ? hi[0] : lo[0];
    v[i][1] = i & 2 ? hi[1] : lo[1];
    v[i][2] = i & 4 ? hi[2] : lo[2];
  }
  tm_quad(s, v[0], v[2], v[3], v[1]); /* z = lo, normal -z */
  tm_quad(s, v[4], v[5], v[7], v[6]); /* z = hi */
  tm_quad(s, v[0], v[1], v[5], v[4]); /* y = lo */
  tm_quad(s, v[2], v[6], v[7], v[3]); /* y = hi */
  tm_quad(s, v[0], v[4], v[6], v[2]); /* x = lo */
  tm_quad(s, v[1], v[3], v[7], v[5]); /* x = hi */
}

/* cos and sin of 2 pi i / n, exact at multiples of 90 degrees. */
static inline void tm_cossin(int i, int n, double *c, double *s) {
  const int q = (int)(((long)i * 4) % n == 0 ? ((long)i * 4 / n) % 4 : -1);
  static const double C[4] = {1, 0, -1, 0}, S[4] = {0, 1, 0, -1};
  if (q >= 0) {
    *c = C[q];
    *s = S[q];
  } else {
    *c = cos(2 * TM_PI * i / n);
    *s = sin(2 * TM_PI * i / n);
  }
}

/* Prism of n sides inscribed in the cylinder of radius R about z, z in
 * [0, H], its sides in `rings` rows; caps fanned from their centres. */
static inline void tm_prism(struct tm_soup *s, double R, double H, int n, int rings) {
  const double cb[3] = {0, 0, 0}, ct[3] = {0, 0, H};
  for (int i = 0; i < n; ++i) {
    double c0, s0, c1, s1;
    tm_cossin(i, n, &c0, &s0);
    tm_cossin(i + 1, n, &c1, &s1);
    for (int j = 0; j < rings; ++j) {
      const double z0 = H * j / rings, z1 = j + 1 == rings ? H : H * (j + 1) / rings;
      const double b0[3] = {R * c0, R * s0, z0}, b1[3] = {R * c1, R * s1, z0};
      const double t0[3] = {R * c0, R * s0, z1}, t1[3] = {R * c1, R * s1, z1};
      tm_quad(s, b0, b1, t1, t0);
    }
    const double t0[3] = {R * c0, R * s0, H}, t1[3] = {R * c1, R * s1, H};
    const double b0[3] = {R * c0, R * s0, 0}, b1[3] = {R * c1, R * s1, 0};
    tm_tri(s, ct, t0, t1);
    tm_tri(s, cb, b1, b0);
  }
}

static inline void tm_cylinder(struct tm_soup *s, double R, double H, int n) {
  tm_prism(s, R, H, n, 1);
}

/* Torus of major radius R about z and minor radius r, n x m quads. */
static inline void tm_torus(struct tm_soup *s, double R, double r, int n, int m) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < m; ++j) {
      double P[4][3];
      for (int k = 0; k < 4; ++k) {
        const int ii = i + (k == 1 || k == 2), jj = j + (k >= 2);
        double ct, st, cp, sp;
        tm_cossin(ii, n, &ct, &st);
        tm_cossin(jj, m, &cp, &sp);
        P[k][0] = (R + r * cp) * ct;
        P[k][1] = (R + r * cp) * st;
        P[k][2] = r * sp;
      }
      tm_quad(s, P[0], P[1], P[2], P[3]);
    }
}

/* Text of an ASCII STL (exact: %.17g); malloc'd, *len its length. */
static inline char *tm_stl_ascii(const struct tm_soup *s, size_t *len) {
  size_t cap = 200 + s->nt * 400;
  char *t = malloc(cap);
  size_t n = 0;
  if (!t) abort();
  n += (size_t)snprintf(t + n, cap - n, "solid test part\n");
  for (size_t i = 0; i < s->nt; ++i) {
    const double *p = s->p + 9 * i;
    n += (size_t)snprintf(t + n, cap - n, "  facet normal 0 0 0\n    outer loop\n");
    for (int k = 0; k < 3; ++k)
      n += (size_t)snprintf(t + n, cap - n, "      vertex %.17g %.17g %.17g\n", p[3 * k],
                            p[3 * k + 1], p[3 * k + 2]);
    n += (size_t)snprintf(t + n, cap - n, "    endloop\n  endfacet\n");
  }
  n += (size_t)snprintf(t + n, cap - n, "endsolid test part\n");
  *len = n;
  return t;
}

static inline void tm_put32(unsigned char *b, uint32_t u) {
  for (int k = 0; k < 4; ++k) b[k] = (unsigned char)(u >> (8 * k));
}

/* Bytes of a binary STL (float32 coordinates). */
static inline char *tm_stl_binary(const struct tm_soup *s, size_t *len) {
  *len = 84 + 50 * s->nt;
  unsigned char *b = calloc(*len, 1);
  if (!b) abort();
  memcpy(b, "binary STL written by the partix tests", 38);
  tm_put32(b + 80, (uint32_t)s->nt);
  for (size_t i = 0; i < s->nt; ++i)
    for (int k = 0; k < 9; ++k) {
      const float f = (float)s->p[9 * i + (size_t)k];
      uint32_t u;
      memcpy(&u, &f, 4);
      tm_put32(b + 84 + 50 * i + 12 + 4 * (size_t)k, u);
    }
  return (char *)b;
}

/* Text of an OBJ: one "v" per triangle corner (welding joins them), faces
 * with "i/t/n" and negative indices in turn. */
static inline char *tm_obj(const struct tm_soup *s, size_t *len) {
  size_t cap = 200 + s->nt * 300;
  char *t = malloc(cap);
  size_t n = 0;
  if (!t) abort();
  n += (size_t)snprintf(t + n, cap - n, "# test part\no part\n");
  for (size_t i = 0; i < s->nt; ++i) {
    const double *p = s->p + 9 * i;
    for (int k = 0; k < 3; ++k)
      n += (size_t)snprintf(t + n, cap - n, "v %.17g %.17g %.17g\n", p[3 * k], p[3 * k + 1],
                            p[3 * k + 2]);
    if (i % 2)
      n += (size_t)snprintf(t + n, cap - n, "f -3 -2 -1\n");
    else
      n += (size_t)snprintf(t + n, cap - n, "f %zu/1/1 %zu//2 %zu/3\n", 3 * i + 1, 3 * i + 2,
                            3 * i + 3);
  }
  *len = n;
  return t;
}

#endif
