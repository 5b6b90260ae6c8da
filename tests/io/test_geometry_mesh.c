/* Surface meshes (io/geometry/geo_mesh.h): the same box read from ASCII
 * STL, binary STL and OBJ (fan-triangulated quads) welds to 8 vertices and
 * 12 triangles, volume and area exact; an inward file is turned outward
 * (its sections close, counter-clockwise);
 * open, non-manifold and inconsistently oriented meshes are refused with
 * their offending edges; malformed files with FILE:LINE (or byte offset)
 * and the reason, never a crash. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "io/geometry/geo_mesh.h"
#include "partix/memory.h"
#include "px_test.h"
#include "px_test_mesh.h"

static int message_has(struct px_context *ctx, const char *text) {
  int ok = strstr(px_context_message(ctx), text) != NULL;
  if (!ok) fprintf(stderr, "message: %s\n  expected: %s\n", px_context_message(ctx), text);
  return ok;
}

static const double LO[3] = {0, 0, 0}, HI[3] = {2, 3, 5};

static void check_box(struct px_context *ctx, const char *name, const char *data, size_t len,
                      int obj, double tol) {
  struct px_geo_mesh m;
  double V, A, lo[3], hi[3];
  PX_CHECK_OK(ctx, px_geo_mesh_parse(ctx, name, data, len, obj, tol, &m));
  PX_CHECK_MSG(m.nv == 8 && m.nt == 12 && m.degenerate == 0, "%s: %zu vertices %zu triangles", name,
               m.nv, m.nt);
  PX_CHECK_OK(ctx, px_geo_mesh_check(ctx, &m));
  PX_CHECK(m.ne == 18 && m.flipped == 0);
  px_geo_mesh_measure(&m, &V, &A, lo, hi);
  PX_CHECK_NEAR(V, 30.0, 1e-12);
  PX_CHECK_NEAR(A, 62.0, 1e-12);
  PX_CHECK(lo[0] == 0 && lo[2] == 0 && hi[1] == 3 && hi[2] == 5);
  px_geo_mesh_free(ctx, &m);
  PX_CHECK(m.xyz == NULL && m.nt == 0);
}

static void test_box_in_three_formats(struct px_context *ctx) {
  struct tm_soup s = {0};
  size_t len;
  tm_box(&s, LO, HI);
  char *t = tm_stl_ascii(&s, &len);
  check_box(ctx, "box.stl", t, len, 0, 0);
  free(t);
  t = tm_stl_binary(&s, &len);
  check_box(ctx, "box_binary.stl", t, len, 0, 0);
  free(t);
  t = tm_obj(&s, &len);
  check_box(ctx, "box.obj", t, len, 1, 0);
  free(t);
  /* quads, fan-triangulated; comments, normals, groups ignored */
  const char *quads =
      "# box\nv 0 0 0\nv 2 0 0\nv 0 3 0\nv 2 3 0\nv 0 0 5\nv 2 0 5\nv 0 3 5\n"
      "v 2 3 5\nvn 0 0 1\ng sides\nf 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\n"
      "f 3 7 8 4\nf 1 5 7 3\nf 2//1 4//1 8//1 6//1\n";
  check_box(ctx, "quads.obj", quads, strlen(quads), 1, 0);
  tm_free(&s);
}

static void test_inward_file_turned_outward(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  size_t len;
  double V;
  tm_box(&s, LO, HI);
  for (size_t i = 0; i < s.nt; ++i) /* swap corners 2 and 3 */
    for (int k = 0; k < 3; ++k) {
      const double x = s.p[9 * i + 3 + (size_t)k];
      s.p[9 * i + 3 + (size_t)k] = s.p[9 * i + 6 + (size_t)k];
      s.p[9 * i + 6 + (size_t)k] = x;
    }
  char *t = tm_stl_ascii(&s, &len);
  PX_CHECK_OK(ctx, px_geo_mesh_parse(ctx, "inward.stl", t, len, 0, 0, &m));
  PX_CHECK_OK(ctx, px_geo_mesh_check(ctx, &m));
  px_geo_mesh_measure(&m, &V, NULL, NULL, NULL);
  PX_CHECK(m.flipped == 1);
  PX_CHECK_NEAR(V, 30.0, 1e-12);
  /* the edge table turned with the triangles: the sections close, the
   * outer boundary counter-clockwise (2 x 3 at every height) */
  {
    double u[3], v[3], n[3];
    const double nz[3] = {0, 0, 1}, ux[3] = {1, 0, 0};
    PX_CHECK_OK(ctx, px_geo_mesh_frame(ctx, nz, ux, u, v, n));
    for (int i = 1; i <= 4; ++i) {
      struct px_geo_polyline *loops = NULL;
      size_t nl = 0;
      PX_CHECK_OK(ctx, px_geo_mesh_slice(ctx, &m, u, v, n, i, &loops, &nl));
      PX_CHECK_MSG(nl == 1, "section at %d: %zu loops", i, nl);
      if (nl == 1) PX_CHECK_NEAR(px_geo_polyline_area(&loops[0]), 6.0, 1e-12);
      for (size_t l = 0; l < nl; ++l) px_geo_polyline_free(ctx, &loops[l]);
      px_mem_free(ctx, loops);
    }
  }
  px_geo_mesh_free(ctx, &m);
  free(t);
  tm_free(&s);
}

static void test_weld_tolerance(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  size_t len;
  tm_box(&s, LO, HI);
  s.p[9 * (s.nt - 1)] += 1e-7; /* one corner of the last triangle off by 1e-7 */
  char *t = tm_stl_ascii(&s, &len);
  check_box(ctx, "near.stl", t, len, 0, 1e-6);
  PX_CHECK_OK(ctx, px_geo_mesh_parse(ctx, "near.stl", t, len, 0, 0, &m));
  PX_CHECK(m.nv == 9);
  PX_CHECK_STATUS(ctx, px_geo_mesh_check(ctx, &m), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "near.stl: the surface is not closed and manifold: 4 edges are"));
  PX_CHECK(message_has(ctx, "open: on one triangle only; triangles at line 79"));
  px_geo_mesh_free(ctx, &m);
  free(t);
  tm_free(&s);
}

/* A mesh that parses but fails the check, with `count` offending edges
 * and `why` in the message. */
static void check_refused(struct px_context *ctx, const struct tm_soup *s, const char *count,
                          const char *why) {
  struct px_geo_mesh m;
  size_t len;
  char *t = tm_stl_ascii(s, &len);
  PX_CHECK_OK(ctx, px_geo_mesh_parse(ctx, "bad.stl", t, len, 0, 0, &m));
  PX_CHECK_STATUS(ctx, px_geo_mesh_check(ctx, &m), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, count));
  PX_CHECK(message_has(ctx, why));
  px_geo_mesh_free(ctx, &m);
  free(t);
}

static void test_bad_surfaces_name_their_edges(struct px_context *ctx) {
  struct tm_soup s = {0};
  tm_box(&s, LO, HI);
  s.nt -= 2; /* no x = hi face: its 4 sides open, its diagonal gone */
  check_refused(ctx, &s, ": 4 edges are not shared", "edge (2, 3, 0) - (2, 0, 0): open");
  s.nt += 2;
  /* one triangle reversed: its 3 edges run along their neighbours' way */
  for (int k = 0; k < 3; ++k) {
    const double x = s.p[3 + k];
    s.p[3 + k] = s.p[6 + k];
    s.p[6 + k] = x;
  }
  check_refused(ctx, &s, ": 3 edges are not shared", "their orientations disagree");
  tm_free(&s);
  /* two boxes sharing the edge x = y = 1: four triangles on it */
  const double a0[3] = {0, 0, 0}, a1[3] = {1, 1, 1}, b0[3] = {1, 1, 0}, b1[3] = {2, 2, 1};
  tm_box(&s, a0, a1);
  tm_box(&s, b0, b1);
  check_refused(ctx, &s, ": 1 edge is not shared",
                "edge (1, 1, 0) - (1, 1, 1): not manifold: on more than two triangles; "
                "triangles at line");
  tm_free(&s);
}

static void refused(struct px_context *ctx, const char *name, const char *text, size_t len, int obj,
                    enum px_status status, const char *why) {
  struct px_geo_mesh m;
  PX_CHECK_STATUS(ctx, px_geo_mesh_parse(ctx, name, text, len, obj, 0, &m), status);
  PX_CHECK(message_has(ctx, why));
  PX_CHECK(m.xyz == NULL && m.tri == NULL && m.nt == 0);
}

#define FACET "facet normal 0 0 1\nouter loop\n"

static void test_malformed_files_name_their_line(struct px_context *ctx) {
  const char *t;
  t = "solid a\n" FACET "vertex 0 0 0\nvertex 1 0 nan\n";
  refused(ctx, "a.stl", t, strlen(t), 0, PX_STATUS_FORMAT, "a.stl:5: 'nan' is not a coordinate");
  t = "solid a\n" FACET "vertex 0 0 0\nvertex 1 0 0\nendloop\nendfacet\nendsolid\n";
  refused(ctx, "a.stl", t, strlen(t), 0, PX_STATUS_FORMAT,
          "a.stl:6: expected vertex 3 of 3 of a facet, found 'endloop'");
  t = "solid a\n" FACET "vertex 0 0 0\nvertex 1 0\n";
  refused(ctx, "a.stl", t, strlen(t), 0, PX_STATUS_FORMAT,
          "a.stl:5: a vertex needs 3 coordinates, found 2");
  t = "solid a\n" FACET "vertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
  refused(ctx, "a.stl", t, strlen(t), 0, PX_STATUS_FORMAT, "the file ends without endsolid");
  t = "solid a\nfacet normal 0 0 1\nouter\n";
  refused(ctx, "a.stl", t, strlen(t), 0, PX_STATUS_FORMAT, "a.stl:3: the file ends inside");
  t = "solid a\nfacet normal 0 0 1e999\n";
  refused(ctx, "a.stl", t, strlen(t), 0, PX_STATUS_FORMAT,
          "a.stl:2: expected a normal component in a facet, found '1e999'");
  t = "solid a\nfacets\n";
  refused(ctx, "a.stl", t, strlen(t), 0, PX_STATUS_FORMAT,
          "a.stl:2: expected facet or endsolid, found 'facets'");
  refused(ctx, "e.stl", "", 0, 0, PX_STATUS_FORMAT, "e.stl: not an STL file: 0 bytes");
  /* a binary STL truncated by 10 bytes, and one with a NaN */
  {
    struct tm_soup s = {0};
    size_t len;
    tm_box(&s, LO, HI);
    char *b = tm_stl_binary(&s, &len);
    refused(ctx, "cut.stl", b, len - 10, 0, PX_STATUS_FORMAT,
            "cut.stl: not an STL file: not ASCII (no 'solid' at the start), and as binary its "
            "header (byte 80) counts 12 triangles, 684 bytes, but the file has 674");
    const unsigned char nan32[4] = {0, 0, 0xc0, 0x7f}; /* a quiet NaN, little-endian */
    memcpy(b + 84 + 50 * 3 + 12 + 4 * 4, nan32, 4);    /* triangle 4, vertex 2, y */
    refused(ctx, "nan.stl", b, len, 0, PX_STATUS_FORMAT,
            "nan.stl: byte 262 (triangle 4, vertex 2): coordinate nan is not");
    free(b);
    tm_free(&s);
  }
  t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n";
  refused(ctx, "a.obj", t, strlen(t), 1, PX_STATUS_FORMAT,
          "a.obj:4: face corner '4' is not the index of a vertex read so far (1 to 3");
  t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 -3 -4\n";
  refused(ctx, "a.obj", t, strlen(t), 1, PX_STATUS_FORMAT, "a.obj:4: face corner '-4'");
  t = "v 0 0 0\nv 1 0 0\nf 1 2\n";
  refused(ctx, "a.obj", t, strlen(t), 1, PX_STATUS_FORMAT,
          "a.obj:3: a face needs 3 corners at least, found 2");
  t = "v 0 0 0\nv 1 x 0\n";
  refused(ctx, "a.obj", t, strlen(t), 1, PX_STATUS_FORMAT, "a.obj:2: 'x' is not a coordinate");
  t = "v 0 0 0\nv 1 0 0\nv 1 2e9 0\n";
  refused(ctx, "a.obj", t, strlen(t), 1, PX_STATUS_FORMAT, "a.obj:3: '2e9' is not a coordinate");
  t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 2\n";
  refused(ctx, "a.obj", t, strlen(t), 1, PX_STATUS_FORMAT, "no triangle left after welding");
  t = "# nothing\n";
  refused(ctx, "n.obj", t, strlen(t), 1, PX_STATUS_FORMAT, "n.obj: no face ('f' line)");
  /* a token longer than any number: cut, refused by its start */
  char longtok[200] = "v 0 0 ";
  memset(longtok + 6, '1', 150);
  refused(ctx, "l.obj", longtok, strlen(longtok), 1, PX_STATUS_FORMAT, "l.obj:1: '1111");
}

static void test_files(struct px_context *ctx) {
  struct tm_soup s = {0};
  struct px_geo_mesh m;
  size_t len;
  tm_box(&s, LO, HI);
  char *t = tm_stl_binary(&s, &len);
  FILE *f = fopen("box.STL", "wb");
  if (f) {
    fwrite(t, 1, len, f);
    fclose(f);
  }
  PX_CHECK_OK(ctx, px_geo_mesh_read(ctx, "box.STL", 0, &m));
  PX_CHECK(m.nt == 12 && m.nv == 8 && m.binary == 1 && strcmp(m.source, "box.STL") == 0);
  px_geo_mesh_free(ctx, &m);
  free(t);
  tm_free(&s);
  PX_CHECK_STATUS(ctx, px_geo_mesh_read(ctx, "box.ply", 0, &m), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "box.ply: a part's surface is read from a .stl or .obj file"));
  PX_CHECK_STATUS(ctx, px_geo_mesh_read(ctx, "missing.stl", 0, &m), PX_STATUS_IO);
  PX_CHECK(message_has(ctx, "missing.stl: cannot open mesh file"));
  mkdir("adir.stl", 0700);
  PX_CHECK_STATUS(ctx, px_geo_mesh_read(ctx, "adir.stl", 0, &m), PX_STATUS_CONFIG);
  PX_CHECK(message_has(ctx, "adir.stl: not a regular file"));
  PX_CHECK_STATUS(ctx, px_geo_mesh_parse(ctx, "x.stl", "", 0, 0, -1, &m), PX_STATUS_INVALID);
}

int main(void) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
  const size_t held = px_mem_current(ctx, NULL);
  test_box_in_three_formats(ctx);
  test_inward_file_turned_outward(ctx);
  test_weld_tolerance(ctx);
  test_bad_surfaces_name_their_edges(ctx);
  test_malformed_files_name_their_line(ctx);
  test_files(ctx);
  PX_CHECK(px_mem_current(ctx, NULL) == held); /* nothing left allocated */
  px_context_free(ctx);
  return px_test_report("test_geometry_mesh");
}
