/* cpu backend internals shared with kernel modules. */
#ifndef PX_CPU_IMPL_H
#define PX_CPU_IMPL_H

#include <stddef.h>

/* "<cpu model>, <threads> threads, <isa>" into buf. */
void px_cpu_describe(int threads, char *buf, size_t size);

/* Per-precision lincomb loops (lincomb_cpu.h, instantiated by
 * lincomb_cpu_f32.c and lincomb_cpu_f64.c): out[i] = sum_k c[k] in[k][i]. */
void px_cpu_lincomb_f32(int threads, size_t n, int nterms, const double *coeffs,
                        const float *const *in, float *out);
void px_cpu_lincomb_f64(int threads, size_t n, int nterms, const double *coeffs,
                        const double *const *in, double *out);

#endif
