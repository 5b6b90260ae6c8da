/* Forging checkpoints for the granular tests: a checkpoint's sections
 * read into memory, edited, and written again with px_checkpoint_writer (so
 * every CRC is right), then opened as `partix verify` does. */
#ifndef GRANULAR_TEST_CK_H
#define GRANULAR_TEST_CK_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "granular_test_util.h"
#include "partix/checkpoint.h"
#include "partix/sim.h"

/* The sections of a checkpoint, in file order, to be forged and written
 * again with right CRCs. */
struct gt_ck_sec {
  char name[64];
  enum px_dtype type;
  uint64_t count;
  unsigned char *data;
};
struct gt_ck_file {
  struct gt_ck_sec v[128];
  size_t n;
  char solver[32];
  uint64_t hash, step;
  double time;
};

GT_UNUSED static int gt_ck_load(struct px_context *ctx, const char *path, struct gt_ck_file *f) {
  struct px_checkpoint *ck = NULL;
  size_t k;
  memset(f, 0, sizeof *f);
  if (px_checkpoint_open(ctx, path, &ck) != PX_STATUS_OK) return 0;
  snprintf(f->solver, sizeof f->solver, "%s", px_checkpoint_solver(ck));
  f->hash = px_checkpoint_case_hash(ck);
  f->step = px_checkpoint_step(ck);
  f->time = px_checkpoint_time(ck);
  f->n = px_checkpoint_section_count(ck);
  for (k = 0; k < f->n && k < 128; ++k) {
    const char *name = NULL;
    struct gt_ck_sec *s = &f->v[k];
    px_checkpoint_section(ck, k, &name, &s->type, &s->count);
    snprintf(s->name, sizeof s->name, "%s", name);
    s->data = malloc((size_t)(s->count * px_dtype_size(s->type)) + 8);
    if (s->data) px_checkpoint_read(ck, s->name, s->type, s->count, s->data);
  }
  px_checkpoint_close(ck);
  return f->n <= 128;
}

GT_UNUSED static void gt_ck_free(struct gt_ck_file *f) {
  size_t k;
  for (k = 0; k < f->n && k < 128; ++k) free(f->v[k].data);
}

GT_UNUSED static struct gt_ck_sec *gt_ck_find(struct gt_ck_file *f, const char *name) {
  size_t k;
  for (k = 0; k < f->n; ++k)
    if (strcmp(f->v[k].name, name) == 0) return &f->v[k];
  return NULL;
}

GT_UNUSED static enum px_status gt_ck_write(struct px_context *ctx, const struct gt_ck_file *f,
                                            const char *path) {
  struct px_checkpoint_writer *w = NULL;
  size_t k;
  PX_TRY(px_checkpoint_writer_open(ctx, path, f->solver, f->hash, f->step, f->time, &w));
  for (k = 0; k < f->n; ++k) {
    const enum px_status st =
        px_checkpoint_write(w, f->v[k].name, f->v[k].type, f->v[k].count, f->v[k].data);
    if (st != PX_STATUS_OK) {
      px_checkpoint_writer_abort(w);
      return st;
    }
  }
  return px_checkpoint_writer_commit(w);
}

/* One forgery: section `name`, element `index` of the real type `as`
 * (f64, f32 or i32: sections of bytes hold typed values) set to `value`;
 * or, with as = PX_DTYPE_U8, the section one element shorter. */
struct gt_forgery {
  const char *name;
  enum px_dtype as;
  long index; /* -1: the last element */
  double value;
  const char *expect; /* in the message: the section named */
};

/* The section's element size as `as` (the precision of the run: double). */
GT_UNUSED static void gt_ck_patch(struct gt_ck_sec *s, enum px_dtype as, long index, double value) {
  const size_t es = px_dtype_size(as), bytes = (size_t)(s->count * px_dtype_size(s->type));
  const size_t at = index < 0 ? bytes / es - 1 : (size_t)index;
  if ((at + 1) * es > bytes) return;
  if (as == PX_DTYPE_F64) {
    memcpy(s->data + at * es, &value, 8);
  } else if (as == PX_DTYPE_F32) {
    const float f = (float)value;
    memcpy(s->data + at * es, &f, 4);
  } else {
    const int32_t i = (int32_t)value;
    memcpy(s->data + at * es, &i, 4);
  }
}

/* Open the forged file as `partix verify` does: the status and message. */
GT_UNUSED static enum px_status gt_ck_open(struct px_context *ctx, const char *path) {
  struct px_sim *sim = NULL;
  const enum px_status st = px_sim_open(ctx, path, NULL, 0, PX_SIM_MODE_CHECK, &sim);
  px_sim_free(sim);
  return st;
}

#endif
