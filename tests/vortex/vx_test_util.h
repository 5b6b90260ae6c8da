/* Helpers shared by the vortex solver tests: a simulation from case text
 * (through the run driver), a checkpoint section read back, a message check,
 * and the engine configuration (and a cpu engine) of the small cylinder
 * wakes the engine-level tests grow. */
#ifndef VX_TEST_UTIL_H
#define VX_TEST_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/memory.h"
#include "partix/sim.h"
#include "px_test.h"
#include "solvers/vortex/vortex_core.h"

/* Uniform in [0, 1) (64-bit LCG, top 53 bits). */
static inline double vx_test_urand(unsigned long long *s) {
  *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
  return (double)(*s >> 11) / 9007199254740992.0;
}

/* A simulation of the case text (named `name` in messages), progress off;
 * NULL (with the message printed) when the case or the setup fails. */
static inline struct px_sim *vx_test_sim(struct px_context *ctx, const char *name,
                                         const char *text) {
  struct px_case *c = NULL;
  if (px_case_load_string(ctx, name, text, strlen(text), NULL, 0, &c) != PX_STATUS_OK) {
    fprintf(stderr, "case: %s\n", px_context_message(ctx));
    return NULL;
  }
  struct px_sim *sim = NULL;
  /* each call is a new run: the folder of an earlier one (this test's, or
     the last test run's) is removed first, as a run refuses a folder that
     holds another run */
  px_test_fresh_case_dir(c);
  if (px_sim_create(ctx, c, PX_SIM_MODE_RUN, &sim) != PX_STATUS_OK) {
    fprintf(stderr, "sim: %s\n", px_context_message(ctx));
    return NULL;
  }
  px_sim_set_progress(sim, NULL, 0);
  return sim;
}

/* Section `name` of the checkpoint at `path` as doubles (px_mem, *n values),
 * or NULL. */
static inline double *vx_test_read_section(struct px_context *ctx, const char *path,
                                           const char *name, size_t *n) {
  struct px_checkpoint *ck = NULL;
  *n = 0;
  if (px_checkpoint_open(ctx, path, &ck) != PX_STATUS_OK) return NULL;
  enum px_dtype t;
  uint64_t cnt = 0;
  double *d = NULL;
  if (px_checkpoint_find(ck, name, &t, &cnt) == PX_STATUS_OK) {
    d = px_mem_alloc(ctx, "test", (cnt ? cnt : 1) * sizeof(double));
    if (d && px_checkpoint_read(ck, name, PX_DTYPE_F64, cnt, d) != PX_STATUS_OK) {
      px_mem_free(ctx, d);
      d = NULL;
    }
  }
  *n = (size_t)cnt;
  px_checkpoint_close(ck);
  return d;
}

/* Column `name` (a header of the CSV at `path`, e.g. "cx [-]") into out
 * (at most max values); returns the number of rows read, 0 when the file or
 * the column is missing. */
static inline size_t vx_test_csv_column(const char *path, const char *name, double *out,
                                        size_t max) {
  FILE *f = fopen(path, "r");
  char line[8192];
  size_t col = (size_t)-1, n = 0;
  if (!f) return 0;
  if (fgets(line, sizeof line, f)) {
    size_t c = 0;
    for (char *p = line; p;) {
      char *comma = strchr(p, ',');
      size_t len = comma ? (size_t)(comma - p) : strcspn(p, "\r\n");
      if (len == strlen(name) && strncmp(p, name, len) == 0) col = c;
      ++c;
      p = comma ? comma + 1 : NULL;
    }
  }
  while (col != (size_t)-1 && n < max && fgets(line, sizeof line, f)) {
    char *p = line;
    for (size_t c = 0; c < col && p; ++c) {
      p = strchr(p, ',');
      if (p) ++p;
    }
    if (!p) break;
    out[n++] = strtod(p, NULL);
  }
  fclose(f);
  return n;
}

/* The value of quantity `name` in a summary.json ("name": {"value": V, ...});
 * NaN when it is missing or null. */
static inline double vx_test_summary_value(const char *path, const char *name) {
  FILE *f = fopen(path, "r");
  char buf[1 << 16], key[128];
  size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
  if (f) fclose(f);
  buf[n] = '\0';
  snprintf(key, sizeof key, "\"%s\": {\"value\": ", name);
  const char *at = strstr(buf, key);
  if (!at) return NAN;
  at += strlen(key);
  if (strncmp(at, "true", 4) == 0) return 1.0;
  if (strncmp(at, "false", 5) == 0) return 0.0;
  char *end;
  double v = strtod(at, &end);
  return end == at ? NAN : v;
}

/* 1 if the context's message contains `what` (printed when it does not). */
static inline int vx_test_message_has(struct px_context *ctx, const char *what) {
  const char *m = px_context_message(ctx);
  int ok = strstr(m, what) != NULL;
  if (!ok) fprintf(stderr, "message \"%s\" lacks \"%s\"\n", m, what);
  return ok;
}

/* Engine configuration of a cylinder of diameter 1 in a unit free stream at
 * Re = 200 (nu 0.005, dt 0.02) with vortex core eps, collapse radius eps_col
 * and gamma_max 0.002, on `threads` threads; the rest at the defaults. */
static inline void vx_test_cylinder_config(struct px_vortex_config *cfg, double eps, double eps_col,
                                           int threads) {
  px_vortex_config_defaults(cfg);
  cfg->nu = 0.005;
  cfg->dt = 0.02;
  cfg->vinf[0] = 1.0;
  cfg->vref = 1.0;
  cfg->eps = eps;
  cfg->eps_col = eps_col;
  cfg->gamma_max = 0.002;
  cfg->threads = threads;
}

/* A cpu engine of cfg (vx_test_cylinder_config, adjusted by the caller) on
 * cfg->threads threads around a circle of radius 0.5 in `panels` panels:
 * the contour into *c and the backend into *be; NULL (a failed check
 * recorded) where one cannot be made. The caller frees all three. */
static inline struct px_vortex_engine *vx_test_cylinder_engine(struct px_context *ctx,
                                                               const struct px_vortex_config *cfg,
                                                               size_t panels,
                                                               struct px_vortex_contour *c,
                                                               struct px_backend **be) {
  struct px_vortex_engine *e = NULL;
  *be = NULL;
  PX_CHECK_OK(ctx, px_vortex_profile_circle(ctx, 0.5, panels, c));
  PX_CHECK_OK(ctx, px_backend_create(ctx, "cpu", 0, cfg->threads, be));
  if (*be) PX_CHECK_OK(ctx, px_vortex_engine_create(ctx, *be, cfg, c, 1, &e));
  return e;
}

#endif
