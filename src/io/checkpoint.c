/* Checkpoint files, format version 1. The byte layout is specified in
 * docs/checkpoint-format.md; the constants and offsets below follow it.
 *
 * Integrity: the header ends with the CRC of its bytes; each section ends with
 * the CRC of its header, payload and padding; the end record carries the CRC
 * of every byte before that field. The whole-file CRC is maintained with
 * px_crc32_combine, so that each payload byte goes through the CRC only once
 * on writing and once on validation. */
#include "partix/checkpoint.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "io/checkpoint_impl.h"
#include "io/crc32.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "partix/version.h"

/* ----------------------------------------------------------- the format */

const unsigned char px_ck_magic[8] = {'P', 'X', 'C', 'H', 'K', 'P', 'T', 0};
const unsigned char px_ck_section_tag[8] = {'P', 'X', 'S', 'E', 'C', 'T', 0, 0};
const unsigned char px_ck_end_tag[8] = {'P', 'X', 'E', 'N', 'D', 0, 0, 0};

uint64_t px_ck_pad8(uint64_t n) { return (8 - (n & 7)) & 7; }

void px_ck_put_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
void px_ck_put_u64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
uint32_t px_ck_get_u32(const unsigned char *p) {
  uint32_t v;
  memcpy(&v, p, 4);
  return v;
}
uint64_t px_ck_get_u64(const unsigned char *p) {
  uint64_t v;
  memcpy(&v, p, 8);
  return v;
}

int px_ck_name_char(int c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.' || c == '/' || c == ':';
}

/* NULL if `name` is a valid section or solver name, else why not. */
const char *px_ck_name_problem(const char *name) {
  size_t i, n;
  if (!name) return "no name given";
  n = strlen(name);
  if (n == 0) return "empty name";
  if (n > PX_CHECKPOINT_NAME_MAX) return "longer than 63 bytes";
  for (i = 0; i < n; ++i)
    if (!px_ck_name_char((unsigned char)name[i]))
      return "only A-Z a-z 0-9 _ - . / : are allowed in names";
  return NULL;
}

int px_ck_dtype_known(uint32_t dtype) { return px_dtype_size((enum px_dtype)dtype) != 0; }

const char *px_ck_host_endian(void) {
  const uint32_t probe = PX_CK_ENDIAN;
  unsigned char b[4];
  memcpy(b, &probe, 4);
  return b[0] == 0x04 ? "little" : "big";
}

char *px_ck_strdup(struct px_context *ctx, const char *s) {
  size_t n = strlen(s) + 1;
  char *d = px_mem_alloc(ctx, "checkpoint", n);
  if (d) memcpy(d, s, n);
  return d;
}

/* ---------------------------------------------------------------- writer */

struct px_checkpoint_writer {
  struct px_context *ctx; /* borrowed */
  struct px_file *file;   /* owned until commit or abort */
  FILE *out;              /* borrowed from file */
  char *path;             /* owned: the target, for messages */
  uint64_t offset;        /* bytes written so far */
  /* CRC of all bytes written before the current section (of all bytes
   * written, between sections). */
  uint32_t file_crc;
  enum px_status failed;                     /* first failure; PX_STATUS_OK while usable */
  char first_error[512];                     /* its message */
  char (*names)[PX_CHECKPOINT_NAME_MAX + 1]; /* owned: sections written, in order */
  size_t nsections, names_cap;
  /* The section being written (between begin and end). */
  int in_section;
  uint64_t sec_count, sec_done; /* elements declared, written */
  size_t sec_elem;              /* bytes per element */
  uint64_t sec_bytes;           /* payload bytes declared */
  uint32_t sec_crc;             /* CRC of the section bytes so far */
};

/* Record the first failure of w (a failed writer refuses everything after). */
static enum px_status px_ckw_fail(struct px_checkpoint_writer *w, enum px_status status,
                                  const char *fmt, ...) PX_PRINTF(3, 4);
static enum px_status px_ckw_fail(struct px_checkpoint_writer *w, enum px_status status,
                                  const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  px_context_vfail(w->ctx, status, fmt, ap);
  va_end(ap);
  if (w->failed == PX_STATUS_OK) {
    w->failed = status;
    snprintf(w->first_error, sizeof w->first_error, "%s", px_context_message(w->ctx));
  }
  return status;
}

static enum px_status px_ckw_usable(struct px_checkpoint_writer *w) {
  if (w->failed == PX_STATUS_OK) return PX_STATUS_OK;
  return px_context_fail(w->ctx, w->failed, "%s; the checkpoint was not written", w->first_error);
}

static enum px_status px_ckw_put(struct px_checkpoint_writer *w, const void *data, size_t n) {
  errno = 0;
  if (n && fwrite(data, 1, n, w->out) != n) {
    int err = errno ? errno : EIO;
    return px_ckw_fail(w, PX_STATUS_IO,
                       "%s: cannot write checkpoint: %s (the previous checkpoint, if any, is kept)",
                       w->path, strerror(err));
  }
  w->offset += n;
  return PX_STATUS_OK;
}

static void px_ckw_free(struct px_checkpoint_writer *w) {
  struct px_context *ctx = w->ctx;
  px_mem_free(ctx, w->names);
  px_mem_free(ctx, w->path);
  px_mem_free(ctx, w);
}

enum px_status px_checkpoint_writer_open(struct px_context *ctx, const char *path,
                                         const char *solver, uint64_t case_hash, uint64_t step,
                                         double sim_time, struct px_checkpoint_writer **out) {
  struct px_checkpoint_writer *w;
  unsigned char h[PX_CK_HDR_MAX];
  const char *problem;
  const char *version = PX_VERSION_STRING;
  size_t ls, lv, hbytes;
  time_t now;
  enum px_status s;
  if (!ctx) return PX_STATUS_INVALID;
  if (!path || !out)
    return px_context_fail(ctx, PX_STATUS_INVALID, "px_checkpoint_writer_open: no path or no out");
  *out = NULL;
  problem = px_ck_name_problem(solver);
  if (problem)
    return px_context_fail(ctx, PX_STATUS_INVALID, "%s: invalid solver name '%s': %s", path,
                           solver ? solver : "", problem);
  ls = strlen(solver);
  lv = strlen(version);
  if (lv == 0 || lv > PX_CHECKPOINT_NAME_MAX)
    return px_context_fail(ctx, PX_STATUS_INTERNAL, "partix version string '%s' is unusable",
                           version);
  w = px_mem_calloc(ctx, "checkpoint", 1, sizeof *w);
  if (!w) return PX_STATUS_NOMEM;
  w->ctx = ctx;
  w->path = px_ck_strdup(ctx, path);
  if (!w->path) {
    px_ckw_free(w);
    return PX_STATUS_NOMEM;
  }
  px_file_remove_stale(ctx, path);
  s = px_file_open(ctx, path, &w->file);
  if (s != PX_STATUS_OK) {
    px_ckw_free(w);
    return s;
  }
  w->out = px_file_stream(w->file);

  hbytes = PX_CK_HDR_FIXED + ls + lv + 4;
  hbytes += (size_t)px_ck_pad8(hbytes);
  memset(h, 0, sizeof h);
  memcpy(h, px_ck_magic, 8);
  px_ck_put_u32(h + PX_CK_HDR_VERSION, PX_CHECKPOINT_FORMAT_VERSION);
  px_ck_put_u32(h + PX_CK_HDR_ENDIAN, PX_CK_ENDIAN);
  px_ck_put_u32(h + PX_CK_HDR_BYTES, (uint32_t)hbytes);
  px_ck_put_u32(h + PX_CK_HDR_FLAGS, 0);
  px_ck_put_u64(h + PX_CK_HDR_CASE_HASH, case_hash);
  px_ck_put_u64(h + PX_CK_HDR_STEP, step);
  memcpy(h + PX_CK_HDR_TIME, &sim_time, 8);
  now = time(NULL);
  px_ck_put_u64(h + PX_CK_HDR_CREATED, now == (time_t)-1 ? 0 : (uint64_t)now);
  px_ck_put_u32(h + PX_CK_HDR_SOLVER_LEN, (uint32_t)ls);
  px_ck_put_u32(h + PX_CK_HDR_VERSION_LEN, (uint32_t)lv);
  memcpy(h + PX_CK_HDR_FIXED, solver, ls);
  memcpy(h + PX_CK_HDR_FIXED + ls, version, lv);
  px_ck_put_u32(h + hbytes - 4, px_crc32_update(0, h, hbytes - 4));
  s = px_ckw_put(w, h, hbytes);
  if (s != PX_STATUS_OK) {
    px_checkpoint_writer_abort(w);
    return s;
  }
  w->file_crc = px_crc32_update(0, h, hbytes);
  *out = w;
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_write_begin(struct px_checkpoint_writer *w, const char *name,
                                         enum px_dtype dtype, uint64_t count) {
  unsigned char h[PX_CK_SEC_HEADER];
  const char *problem;
  size_t i, elem, n;
  if (!w) return PX_STATUS_INVALID;
  PX_TRY(px_ckw_usable(w));
  if (w->in_section)
    return px_ckw_fail(w, PX_STATUS_INVALID,
                       "%s: section '%s' begun while section '%s' is not ended", w->path,
                       name ? name : "", w->names[w->nsections]);
  problem = px_ck_name_problem(name);
  if (problem)
    return px_ckw_fail(w, PX_STATUS_INVALID, "%s: invalid section name '%s': %s", w->path,
                       name ? name : "", problem);
  elem = px_dtype_size(dtype);
  if (elem == 0)
    return px_ckw_fail(w, PX_STATUS_INVALID, "%s: section '%s': unknown element type %d", w->path,
                       name, (int)dtype);
  if (count > UINT64_MAX / 2 / elem)
    return px_ckw_fail(w, PX_STATUS_INVALID, "%s: section '%s': %" PRIu64 " elements is too many",
                       w->path, name, count);
  for (i = 0; i < w->nsections; ++i)
    if (strcmp(w->names[i], name) == 0)
      return px_ckw_fail(w, PX_STATUS_INVALID,
                         "%s: section '%s' written twice (section names must be unique)", w->path,
                         name);
  if (w->nsections == w->names_cap) {
    size_t cap = w->names_cap ? 2 * w->names_cap : 16;
    void *grown = px_mem_realloc(w->ctx, "checkpoint", w->names, cap * sizeof *w->names);
    if (!grown) return px_ckw_fail(w, PX_STATUS_NOMEM, "%s: out of memory", w->path);
    w->names = grown;
    w->names_cap = cap;
  }
  n = strlen(name);
  memset(w->names[w->nsections], 0, sizeof w->names[w->nsections]);
  memcpy(w->names[w->nsections], name, n);

  memset(h, 0, sizeof h);
  memcpy(h, px_ck_section_tag, 8);
  px_ck_put_u32(h + PX_CK_SEC_DTYPE, (uint32_t)dtype);
  px_ck_put_u32(h + PX_CK_SEC_NAME_LEN, (uint32_t)n);
  px_ck_put_u64(h + PX_CK_SEC_COUNT, count);
  px_ck_put_u64(h + PX_CK_SEC_BYTES, count * elem);
  memcpy(h + PX_CK_SEC_NAME, name, n);
  PX_TRY(px_ckw_put(w, h, sizeof h));
  w->in_section = 1;
  w->sec_count = count;
  w->sec_done = 0;
  w->sec_elem = elem;
  w->sec_bytes = count * elem;
  w->sec_crc = px_crc32_update(0, h, sizeof h);
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_write_chunk(struct px_checkpoint_writer *w, const void *data,
                                         uint64_t count) {
  const unsigned char *p = data;
  uint64_t bytes;
  if (!w) return PX_STATUS_INVALID;
  PX_TRY(px_ckw_usable(w));
  if (!w->in_section)
    return px_ckw_fail(w, PX_STATUS_INVALID, "%s: chunk written outside a section", w->path);
  if (count > w->sec_count - w->sec_done)
    return px_ckw_fail(w, PX_STATUS_INVALID,
                       "%s: section '%s': chunk of %" PRIu64
                       " elements exceeds the declared %" PRIu64 " (%" PRIu64 " already written)",
                       w->path, w->names[w->nsections], count, w->sec_count, w->sec_done);
  if (count && !data)
    return px_ckw_fail(w, PX_STATUS_INVALID, "%s: section '%s': no data", w->path,
                       w->names[w->nsections]);
  bytes = count * w->sec_elem;
  /* CRC and write block by block so that each block is still in cache. */
  while (bytes) {
    size_t n = bytes < PX_CK_BUFFER ? (size_t)bytes : PX_CK_BUFFER;
    w->sec_crc = px_crc32_update(w->sec_crc, p, n);
    PX_TRY(px_ckw_put(w, p, n));
    p += n;
    bytes -= n;
  }
  w->sec_done += count;
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_write_end(struct px_checkpoint_writer *w) {
  static const unsigned char zeros[8] = {0};
  unsigned char trailer[PX_CK_SEC_TRAILER];
  uint64_t pad;
  if (!w) return PX_STATUS_INVALID;
  PX_TRY(px_ckw_usable(w));
  if (!w->in_section)
    return px_ckw_fail(w, PX_STATUS_INVALID, "%s: section ended but none was begun", w->path);
  if (w->sec_done != w->sec_count)
    return px_ckw_fail(w, PX_STATUS_INVALID,
                       "%s: section '%s' ended after %" PRIu64 " of its %" PRIu64 " elements",
                       w->path, w->names[w->nsections], w->sec_done, w->sec_count);
  pad = px_ck_pad8(w->sec_bytes);
  w->sec_crc = px_crc32_update(w->sec_crc, zeros, (size_t)pad);
  PX_TRY(px_ckw_put(w, zeros, (size_t)pad));
  w->file_crc = px_crc32_combine(w->file_crc, w->sec_crc, PX_CK_SEC_HEADER + w->sec_bytes + pad);
  px_ck_put_u32(trailer, w->sec_crc);
  px_ck_put_u32(trailer + 4, 0);
  PX_TRY(px_ckw_put(w, trailer, sizeof trailer));
  w->file_crc = px_crc32_update(w->file_crc, trailer, sizeof trailer);
  w->in_section = 0;
  w->nsections++;
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_write(struct px_checkpoint_writer *w, const char *name,
                                   enum px_dtype dtype, uint64_t count, const void *data) {
  if (!w) return PX_STATUS_INVALID;
  PX_TRY(px_checkpoint_write_begin(w, name, dtype, count));
  PX_TRY(px_checkpoint_write_chunk(w, data, count));
  return px_checkpoint_write_end(w);
}

enum px_status px_checkpoint_writer_commit(struct px_checkpoint_writer *w) {
  unsigned char e[PX_CK_END_RECORD];
  enum px_status s;
  if (!w) return PX_STATUS_INVALID;
  s = px_ckw_usable(w);
  if (s == PX_STATUS_OK && w->in_section)
    s = px_ckw_fail(w, PX_STATUS_INVALID,
                    "%s: section '%s' was begun but not ended; the checkpoint was not written",
                    w->path, w->names[w->nsections]);
  if (s == PX_STATUS_OK) {
    memset(e, 0, sizeof e);
    memcpy(e, px_ck_end_tag, 8);
    px_ck_put_u64(e + PX_CK_END_COUNT, (uint64_t)w->nsections);
    px_ck_put_u64(e + PX_CK_END_FILE_BYTES, w->offset + PX_CK_END_RECORD);
    px_ck_put_u32(e + PX_CK_END_CRC, px_crc32_update(w->file_crc, e, PX_CK_END_CRC));
    s = px_ckw_put(w, e, sizeof e);
  }
  if (s != PX_STATUS_OK) {
    px_checkpoint_writer_abort(w);
    return s;
  }
  s = px_file_commit(w->file); /* frees the px_file in every case */
  w->file = NULL;
  if (s == PX_STATUS_OK)
    px_log(w->ctx, PX_LOG_LEVEL_DEBUG, "wrote checkpoint %s (%zu sections, %" PRIu64 " bytes)",
           w->path, w->nsections, w->offset);
  px_ckw_free(w);
  return s;
}

void px_checkpoint_writer_abort(struct px_checkpoint_writer *w) {
  if (!w) return;
  px_file_abort(w->file);
  px_ckw_free(w);
}
