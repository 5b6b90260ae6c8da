/* The link law in float for test_lattice_link.c (lt_link_f32.h). */
#define PX_REAL float
#include "kernels/px_kernel.h"
#include "lt_link_f32.h"
#include "solvers/lattice/lattice_kernel.h"

static struct lt_el lt_test_el_f32(const double c[13]) {
  struct lt_el e;
  e.u = lt_v3_make((float)c[0], (float)c[1], (float)c[2]);
  e.q.w = (float)c[3];
  e.q.x = (float)c[4];
  e.q.y = (float)c[5];
  e.q.z = (float)c[6];
  e.v = lt_v3_make((float)c[7], (float)c[8], (float)c[9]);
  e.W = lt_v3_make((float)c[10], (float)c[11], (float)c[12]);
  return e;
}

void lt_test_link_f32(const double lpar[6], int a, const double e1[13], const double e2[13],
                      double F[3], double G[3]) {
  struct lt_lpar p;
  struct lt_el f1 = lt_test_el_f32(e1), f2 = lt_test_el_f32(e2);
  struct lt_lres r;
  p.h2 = (float)lpar[0];
  p.k = (float)lpar[1];
  p.cl = (float)lpar[2];
  p.kb = (float)lpar[3];
  p.dk = (float)lpar[4];
  p.cr = (float)lpar[5];
  r = lt_link(&p, a, f1, f2, lt_frame_col(f1.q, a), lt_frame_col(f2.q, a));
  F[0] = r.F.x, F[1] = r.F.y, F[2] = r.F.z;
  G[0] = r.G.x, G[1] = r.G.y, G[2] = r.G.z;
}
