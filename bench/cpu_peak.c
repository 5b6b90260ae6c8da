/* The arithmetic a core of this machine sustains: independent chains of
 * vector multiplies and adds (as many of each, no FMA: the project builds
 * with contraction off, so its kernels issue separate multiplies and adds),
 * 64-byte vectors (16 floats, 8 doubles: AVX-512 with -march=native; split
 * by the compiler on narrower machines), on each of T threads at once. The
 * roof of a compute-bound kernel: docs/notes' lattice flop counts
 * (bench/lattice_flops.sh) are set against it.
 *
 * Usage: cpu_peak [THREADS] (default 1). One JSON line per precision:
 * gflops_per_core (min, median, max of 5 runs; flops counted as lanes x
 * operations) and vector_ops_per_s_per_core. */
#include "bench_util.h"

typedef float vf __attribute__((vector_size(64)));
typedef double vd __attribute__((vector_size(64)));

#define PEAK_ITERS 40000000L

/* 6 multiply and 6 add chains for PEAK_ITERS rounds; returns seconds and a
 * sum of the results in *sink (so that nothing is folded away). */
#define PEAK_KERNEL(NAME, V, T)                                               \
  static double NAME(T mul, T add, double *sink) {                            \
    V m = (V){0} + mul, c = (V){0} + add;                                     \
    V a0 = m + 1, a1 = m + 2, a2 = m + 3, a3 = m + 4, a4 = m + 5, a5 = m + 6; \
    V b0 = c + 1, b1 = c + 2, b2 = c + 3, b3 = c + 4, b4 = c + 5, b5 = c + 6; \
    double t0 = omp_get_wtime();                                              \
    for (long k = 0; k < PEAK_ITERS; ++k) {                                   \
      a0 *= m, a1 *= m, a2 *= m, a3 *= m, a4 *= m, a5 *= m;                   \
      b0 += c, b1 += c, b2 += c, b3 += c, b4 += c, b5 += c;                   \
    }                                                                         \
    double t = omp_get_wtime() - t0;                                          \
    V s = a0 + a1 + a2 + a3 + a4 + a5 + b0 + b1 + b2 + b3 + b4 + b5;          \
    *sink = 0;                                                                \
    for (size_t q = 0; q < sizeof(V) / sizeof(T); ++q) *sink += (double)s[q]; \
    return t;                                                                 \
  }
PEAK_KERNEL(peak_f32, vf, float)
PEAK_KERNEL(peak_f64, vd, double)

int main(int argc, char **argv) {
  int threads = argc > 1 ? atoi(argv[1]) : 1;
  if (threads < 1) {
    fprintf(stderr, "usage: cpu_peak [THREADS]\n");
    return 2;
  }
  /* the factors from the command line's length: not known to the compiler */
  const double mul = 1.0 - 1e-9 * (double)strlen(argv[0]), add = 1e-9 * (double)strlen(argv[0]);
  for (int p = 0; p < 2; ++p) {
    const int lanes = p ? 8 : 16;
    double rate[5], sink = 0;
    int used = 0;
    double load0 = px_bench_load1();
    for (int r = 0; r < 5; ++r) {
      double worst = 0;
#pragma omp parallel num_threads(threads) reduction(max : worst) reduction(+ : sink)
      {
        double s;
        double t = p ? peak_f64(mul, add, &s) : peak_f32((float)mul, (float)add, &s);
        worst = t > worst ? t : worst;
        sink += s;
#pragma omp single
        used = omp_get_num_threads();
      }
      rate[r] = 12.0 * (double)PEAK_ITERS / worst; /* vector ops/s of each core */
    }
    struct px_bench_stats st = px_bench_stats(rate, 5);
    printf(
        "{\"bench\":\"cpu_peak\",\"precision\":\"%s\",\"lanes\":%d,\"fma\":false,"
        "\"gflops_per_core\":%.1f,\"gflops_per_core_min\":%.1f,\"gflops_per_core_max\":%.1f,"
        "\"vector_ops_per_s_per_core\":%.4g,\"reps\":5,\"check\":%.3g",
        p ? "double" : "single", lanes, st.median * lanes * 1e-9, st.min * lanes * 1e-9,
        st.max * lanes * 1e-9, st.median, sink);
    px_bench_json_env(stdout, threads, used, load0, px_bench_load1());
    printf("}\n");
  }
  return 0;
}
