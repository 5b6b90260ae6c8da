/* Small helpers shared by the benchmarks: option lists, JSON output, and the
 * fields every JSON line carries to say what ran (threads used, load average,
 * machine, min/median/max of repetitions); bench/README.md lists them. */
#ifndef PX_BENCH_UTIL_H
#define PX_BENCH_UTIL_H

#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/partix.h"

/* Parse "a,b,c" of positive numbers into out (at most max); returns count. */
static inline int px_bench_list(const char *s, double *out, int max) {
  int n = 0;
  while (s && *s && n < max) {
    char *end;
    const double v = strtod(s, &end);
    if (end == s || !(v > 0)) break;
    out[n++] = v;
    s = *end == ',' ? end + 1 : end;
  }
  return n;
}

/* A JSON string value (quotes and backslashes escaped, control chars dropped). */
static inline void px_bench_json_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s) {
    if (*s == '"' || *s == '\\') fputc('\\', f);
    if ((unsigned char)*s >= 0x20) fputc(*s, f);
  }
  fputc('"', f);
}

/* 1-minute load average from /proc/loadavg (the machine may be shared: a
 * load above the free cores means the timings were disturbed); -1 if
 * unknown. */
static inline double px_bench_load1(void) {
  double l = -1;
  FILE *f = fopen("/proc/loadavg", "r");
  if (f) {
    if (fscanf(f, "%lf", &l) != 1) l = -1;
    fclose(f);
  }
  return l;
}

/* The cpu's model name from /proc/cpuinfo into buf ("unknown" if absent). */
static inline const char *px_bench_cpu_model(char *buf, size_t len) {
  FILE *f = fopen("/proc/cpuinfo", "r");
  char line[512];
  snprintf(buf, len, "unknown");
  if (!f) return buf;
  while (fgets(line, sizeof line, f))
    if (strncmp(line, "model name", 10) == 0) {
      const char *c = strchr(line, ':');
      if (c) {
        c += 1 + (c[1] == ' ');
        snprintf(buf, len, "%.*s", (int)strcspn(c, "\n"), c);
      }
      break;
    }
  fclose(f);
  return buf;
}

/* Threads an OpenMP team asked for `requested` (<= 0: the default) actually
 * gets, measured with omp_get_num_threads inside such a region: the runtime
 * may give fewer (OMP_THREAD_LIMIT, nested regions, dynamic adjustment). */
static inline int px_bench_threads_used(int requested) {
  int used = 0;
  if (requested > 0) {
#pragma omp parallel num_threads(requested)
    {
#pragma omp single
      used = omp_get_num_threads();
    }
  } else {
#pragma omp parallel
    {
#pragma omp single
      used = omp_get_num_threads();
    }
  }
  return used;
}

/* Min, median and max of v[0..n) (sorted in place); all 0 when n = 0. */
struct px_bench_stats {
  double min, median, max;
};

static inline int px_bench_cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static inline struct px_bench_stats px_bench_stats(double *v, size_t n) {
  struct px_bench_stats s = {0.0, 0.0, 0.0};
  if (n == 0) return s;
  qsort(v, n, sizeof *v, px_bench_cmp_double);
  s.min = v[0];
  s.max = v[n - 1];
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return s;
}

/* The fields that say where and how a line ran:
 * ,"threads_requested":R,"threads_used":U,"cpu_model":"...",
 * "load1_before":L0,"load1_after":L1 (no braces; append to an open object). */
static inline void px_bench_json_env(FILE *f, int requested, int used, double load_before,
                                     double load_after) {
  char model[256];
  fprintf(f, ",\"threads_requested\":%d,\"threads_used\":%d,\"cpu_model\":", requested, used);
  px_bench_json_string(f, px_bench_cpu_model(model, sizeof model));
  fprintf(f, ",\"load1_before\":%.2f,\"load1_after\":%.2f", load_before, load_after);
}

/* The memory bandwidth a STREAM triad a[i] = b[i] + q c[i] reaches on
 * `threads` threads (<= 0: the default team) over three arrays of n doubles
 * (pick 3 n 8 bytes well above the last-level cache), first touched by the
 * threads that use them; bytes/s counted as STREAM does (24 bytes per i: two
 * reads and a write; a write-allocate cache moves 32), best of reps runs
 * (the median is returned in *median when not NULL). 0 when out of memory. */
static inline double px_bench_triad(int threads, size_t n, int reps, double *median) {
  double *a = malloc(n * sizeof *a), *b = malloc(n * sizeof *b), *c = malloc(n * sizeof *c);
  double best = 0.0, rates[16];
  int r, nt = threads > 0 ? threads : omp_get_max_threads();
  long i, nl = (long)n;
  if (!a || !b || !c) {
    free(a), free(b), free(c);
    return 0.0;
  }
  if (reps > 16) reps = 16;
#pragma omp parallel for num_threads(nt) schedule(static)
  for (i = 0; i < nl; ++i) a[i] = 0.0, b[i] = 1.0 + (double)(i & 7), c[i] = 2.0;
  for (r = 0; r < reps; ++r) {
    const double q = 3.0 + r;
    double t0 = omp_get_wtime(), t;
#pragma omp parallel for num_threads(nt) schedule(static)
    for (i = 0; i < nl; ++i) a[i] = b[i] + q * c[i];
    t = omp_get_wtime() - t0;
    rates[r] = t > 0.0 ? 24.0 * (double)n / t : 0.0;
    if (rates[r] > best) best = rates[r];
  }
  if (median) *median = px_bench_stats(rates, (size_t)reps).median;
  if (a[nl / 2] < 0.0) best = 0.0; /* keeps the stores */
  free(a), free(b), free(c);
  return best;
}

#endif
