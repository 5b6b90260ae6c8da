/* The link law of lattice_kernel.h compiled in float (lt_link_f32.c: a unit
 * of its own, one PX_REAL per unit), for test_lattice_link.c. */
#ifndef LT_LINK_F32_H
#define LT_LINK_F32_H

/* lt_link in float of elements e1 (minus end) and e2 (plus end) along axis
 * a; lpar = h2 k cl kb dk cr, an element = u q v W (13 values, q as w x y
 * z), all rounded to float first. F [N] and G [N m] back in double. */
void lt_test_link_f32(const double lpar[6], int a, const double e1[13], const double e2[13],
                      double F[3], double G[3]);

#endif
