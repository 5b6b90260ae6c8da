/* Forging checkpoints in tests: every section of a checkpoint read into
 * memory, edited (a value set, a section resized, retyped or left out), and
 * written again with px_checkpoint_writer, so every CRC is right and only
 * the solver's own checks of the contents stand between the forgery and a
 * run. Used by the hostile-input tests of the solvers. */
#ifndef PX_TEST_CK_H
#define PX_TEST_CK_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "partix/checkpoint.h"
#include "partix/sim.h"
#include "px_test.h"

#if defined(__GNUC__)
#define PX_TEST_UNUSED __attribute__((unused))
#else
#define PX_TEST_UNUSED
#endif

#define PX_TEST_CK_MAX 128

struct px_test_ck_sec {
  char name[64];
  enum px_dtype type;
  uint64_t count;
  unsigned char *data; /* owned (malloc), 8 bytes of slack */
};
struct px_test_ck {
  struct px_test_ck_sec v[PX_TEST_CK_MAX];
  size_t n;
  char solver[32];
  uint64_t hash, step;
  double time;
};

/* Read every section of the checkpoint at path; 0 when it cannot be read
 * whole (more than PX_TEST_CK_MAX sections included). */
PX_TEST_UNUSED static int px_test_ck_load(struct px_context *ctx, const char *path,
                                          struct px_test_ck *f) {
  struct px_checkpoint *ck = NULL;
  memset(f, 0, sizeof *f);
  if (px_checkpoint_open(ctx, path, &ck) != PX_STATUS_OK) return 0;
  snprintf(f->solver, sizeof f->solver, "%s", px_checkpoint_solver(ck));
  f->hash = px_checkpoint_case_hash(ck);
  f->step = px_checkpoint_step(ck);
  f->time = px_checkpoint_time(ck);
  size_t n = px_checkpoint_section_count(ck);
  int ok = n <= PX_TEST_CK_MAX;
  for (size_t k = 0; ok && k < n; ++k) {
    const char *name = NULL;
    struct px_test_ck_sec *s = &f->v[f->n++];
    px_checkpoint_section(ck, k, &name, &s->type, &s->count);
    snprintf(s->name, sizeof s->name, "%s", name);
    s->data = malloc((size_t)(s->count * px_dtype_size(s->type)) + 8);
    ok = s->data && px_checkpoint_read(ck, s->name, s->type, s->count, s->data) == PX_STATUS_OK;
  }
  px_checkpoint_close(ck);
  return ok;
}

PX_TEST_UNUSED static void px_test_ck_free(struct px_test_ck *f) {
  for (size_t k = 0; k < f->n; ++k) free(f->v[k].data);
  memset(f, 0, sizeof *f);
}

/* A deep copy (to forge one copy per case from one original). */
PX_TEST_UNUSED static void px_test_ck_copy(const struct px_test_ck *src, struct px_test_ck *dst) {
  *dst = *src;
  for (size_t k = 0; k < src->n; ++k) {
    size_t bytes = (size_t)(src->v[k].count * px_dtype_size(src->v[k].type)) + 8;
    dst->v[k].data = malloc(bytes);
    if (dst->v[k].data) memcpy(dst->v[k].data, src->v[k].data, bytes);
  }
}

PX_TEST_UNUSED static struct px_test_ck_sec *px_test_ck_find(struct px_test_ck *f,
                                                             const char *name) {
  for (size_t k = 0; k < f->n; ++k)
    if (strcmp(f->v[k].name, name) == 0) return &f->v[k];
  return NULL;
}

/* Section s resized to count elements (new ones zero). */
PX_TEST_UNUSED static void px_test_ck_resize(struct px_test_ck_sec *s, uint64_t count) {
  size_t es = px_dtype_size(s->type), old = (size_t)(s->count * es);
  unsigned char *d = realloc(s->data, (size_t)(count * es) + 8);
  if (!d) return;
  if ((size_t)(count * es) > old) memset(d + old, 0, (size_t)(count * es) - old);
  s->data = d;
  s->count = count;
}

/* Section `name` left out. */
PX_TEST_UNUSED static void px_test_ck_drop(struct px_test_ck *f, const char *name) {
  for (size_t k = 0; k < f->n; ++k)
    if (strcmp(f->v[k].name, name) == 0) {
      free(f->v[k].data);
      memmove(&f->v[k], &f->v[k + 1], (f->n - k - 1) * sizeof f->v[0]);
      --f->n;
      return;
    }
}

/* Element `index` (-1: the last) of section s read as type `as` (f64, f32,
 * or i32: sections of bytes hold typed values) set to value; nothing when
 * the section is shorter. */
PX_TEST_UNUSED static void px_test_ck_patch(struct px_test_ck_sec *s, enum px_dtype as, long index,
                                            double value) {
  const size_t es = px_dtype_size(as), bytes = (size_t)(s->count * px_dtype_size(s->type));
  const size_t at = index < 0 ? bytes / es - 1 : (size_t)index;
  if ((at + 1) * es > bytes) return;
  if (as == PX_DTYPE_F64) {
    memcpy(s->data + at * es, &value, 8);
  } else if (as == PX_DTYPE_F32) {
    const float x = (float)value;
    memcpy(s->data + at * es, &x, 4);
  } else {
    const int32_t i = (int32_t)value;
    memcpy(s->data + at * es, &i, 4);
  }
}

/* Write f to path with right CRCs. */
PX_TEST_UNUSED static enum px_status px_test_ck_write(struct px_context *ctx,
                                                      const struct px_test_ck *f,
                                                      const char *path) {
  struct px_checkpoint_writer *w = NULL;
  PX_TRY(px_checkpoint_writer_open(ctx, path, f->solver, f->hash, f->step, f->time, &w));
  for (size_t k = 0; k < f->n; ++k) {
    enum px_status st =
        px_checkpoint_write(w, f->v[k].name, f->v[k].type, f->v[k].count, f->v[k].data);
    if (st != PX_STATUS_OK) {
      px_checkpoint_writer_abort(w);
      return st;
    }
  }
  return px_checkpoint_writer_commit(w);
}

/* Open the checkpoint at path as `partix verify` does (check mode): its
 * status, the message in ctx. */
PX_TEST_UNUSED static enum px_status px_test_ck_verify(struct px_context *ctx, const char *path) {
  struct px_sim *sim = NULL;
  const enum px_status st = px_sim_open(ctx, path, NULL, 0, PX_SIM_MODE_CHECK, &sim);
  px_sim_free(sim);
  return st;
}

/* One forgery: element `index` (-1: the last) of section `name`, read as
 * type `as` (f64, f32 or i32), set to `value`; or, with as = PX_DTYPE_U8,
 * the section cut short (8 bytes of a byte section, one element of any
 * other). The verdict expected: PX_STATUS_FORMAT with `expect` in the
 * message. */
struct px_test_forgery {
  const char *name;
  enum px_dtype as;
  long index;
  double value;
  const char *expect;
};

/* Each forgery in turn on f (restored after each), written to `path` and
 * opened as `partix verify` does: each must be refused as expected, the
 * message naming the file (its last path component). */
PX_TEST_UNUSED static void px_test_ck_expect_refused(struct px_context *ctx, struct px_test_ck *f,
                                                     const struct px_test_forgery *fs, size_t n,
                                                     const char *path) {
  const char *file = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
  for (size_t k = 0; k < n; ++k) {
    struct px_test_ck_sec *s = px_test_ck_find(f, fs[k].name);
    const uint64_t count = s ? s->count : 0;
    const size_t bytes = s ? (size_t)(count * px_dtype_size(s->type)) : 0;
    unsigned char *keep = s ? malloc(bytes + 8) : NULL;
    PX_CHECK_MSG(s && keep, "no section %s", fs[k].name);
    if (!s || !keep) {
      free(keep);
      continue;
    }
    memcpy(keep, s->data, bytes);
    if (fs[k].as == PX_DTYPE_U8)
      s->count -= s->type == PX_DTYPE_U8 ? 8 : 1;
    else
      px_test_ck_patch(s, fs[k].as, fs[k].index, fs[k].value);
    enum px_status st = px_test_ck_write(ctx, f, path);
    PX_CHECK_MSG(st == PX_STATUS_OK, "%s: writing: %s", fs[k].name, px_context_message(ctx));
    if (st == PX_STATUS_OK) {
      st = px_test_ck_verify(ctx, path);
      const char *m = px_context_message(ctx);
      PX_CHECK_MSG(st == PX_STATUS_FORMAT && strstr(m, fs[k].expect) && strstr(m, file),
                   "forgery %zu (%s[%ld] = %g): %s: %s", k, fs[k].name, fs[k].index, fs[k].value,
                   px_status_name(st), m);
    }
    px_context_clear(ctx);
    memcpy(s->data, keep, bytes);
    s->count = count;
    free(keep);
  }
}

#endif
