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
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/crc32.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "partix/version.h"

/* ----------------------------------------------------------- the format */

static const unsigned char px_ck_magic[8] = {'P', 'X', 'C', 'H', 'K', 'P', 'T', 0};
static const unsigned char px_ck_section_tag[8] = {'P', 'X', 'S', 'E', 'C', 'T', 0, 0};
static const unsigned char px_ck_end_tag[8] = {'P', 'X', 'E', 'N', 'D', 0, 0, 0};

#define PX_CK_ENDIAN UINT32_C(0x01020304)
#define PX_CK_ENDIAN_SWAPPED UINT32_C(0x04030201)

/* Header: fixed part, then solver name and partix version (lengths at 56 and
 * 60), zero padding, CRC in the last 4 bytes; total a multiple of 8. */
#define PX_CK_HDR_VERSION 8
#define PX_CK_HDR_ENDIAN 12
#define PX_CK_HDR_BYTES 16
#define PX_CK_HDR_FLAGS 20
#define PX_CK_HDR_CASE_HASH 24
#define PX_CK_HDR_STEP 32
#define PX_CK_HDR_TIME 40
#define PX_CK_HDR_CREATED 48
#define PX_CK_HDR_SOLVER_LEN 56
#define PX_CK_HDR_VERSION_LEN 60
#define PX_CK_HDR_FIXED 64
#define PX_CK_HDR_MAX 200 /* PX_CK_HDR_FIXED + 63 + 63 + 4, rounded up to 8 */

/* Section header (96 bytes), then payload, zero padding to a multiple of 8,
 * then an 8-byte trailer: CRC (u32) and 4 zero bytes. */
#define PX_CK_SEC_DTYPE 8
#define PX_CK_SEC_NAME_LEN 12
#define PX_CK_SEC_COUNT 16
#define PX_CK_SEC_BYTES 24
#define PX_CK_SEC_NAME 32
#define PX_CK_SEC_HEADER 96
#define PX_CK_SEC_TRAILER 8

/* End record (32 bytes): tag, section count (u64), file length (u64), CRC of
 * all bytes before the CRC field (u32), 4 zero bytes. */
#define PX_CK_END_COUNT 8
#define PX_CK_END_FILE_BYTES 16
#define PX_CK_END_CRC 24
#define PX_CK_END_RECORD 32

/* Validation streams payloads through a buffer of this size. */
#define PX_CK_BUFFER (1u << 20)

static uint64_t px_ck_pad8(uint64_t n) { return (8 - (n & 7)) & 7; }

static void px_ck_put_u32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void px_ck_put_u64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static uint32_t px_ck_get_u32(const unsigned char *p) {
  uint32_t v;
  memcpy(&v, p, 4);
  return v;
}
static uint64_t px_ck_get_u64(const unsigned char *p) {
  uint64_t v;
  memcpy(&v, p, 8);
  return v;
}

static int px_ck_name_char(int c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-' || c == '.' || c == '/' || c == ':';
}

/* NULL if `name` is a valid section or solver name, else why not. */
static const char *px_ck_name_problem(const char *name) {
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

static int px_ck_dtype_known(uint32_t dtype) { return px_dtype_size((enum px_dtype)dtype) != 0; }

static const char *px_ck_host_endian(void) {
  const uint32_t probe = PX_CK_ENDIAN;
  unsigned char b[4];
  memcpy(b, &probe, 4);
  return b[0] == 0x04 ? "little" : "big";
}

static char *px_ck_strdup(struct px_context *ctx, const char *s) {
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

/* ---------------------------------------------------------------- reader */

struct px_ck_section {
  char name[PX_CHECKPOINT_NAME_MAX + 1];
  enum px_dtype dtype;
  uint64_t count;
  uint64_t offset; /* of the section header, bytes from the start of the file */
  uint64_t bytes;  /* payload bytes (without padding) */
  uint32_t crc;    /* stored CRC */
};

struct px_checkpoint {
  struct px_context *ctx; /* borrowed */
  char *path;             /* owned */
  int fd;                 /* owned, open until close */
  uint64_t size;          /* file size at open, bytes */
  char solver[PX_CHECKPOINT_NAME_MAX + 1];
  char version[PX_CHECKPOINT_NAME_MAX + 1];
  uint32_t format;
  uint64_t case_hash, step, created;
  double time;
  struct px_ck_section *sections; /* owned, file order */
  size_t nsections, sections_cap;
  /* Piecewise read in progress (px_checkpoint_read_begin). */
  const struct px_ck_section *reading; /* NULL when none; points into sections */
  uint64_t read_done;                  /* payload bytes delivered */
  uint32_t read_crc;
};

/* Read exactly n bytes at `off`, which the caller has checked lie within
 * ck->size; a short read means the file shrank under us. */
static enum px_status px_ck_pread(struct px_checkpoint *ck, void *dst, size_t n, uint64_t off) {
  unsigned char *p = dst;
  while (n) {
    ssize_t got = pread(ck->fd, p, n, (off_t)off);
    if (got < 0) {
      if (errno == EINTR) continue;
      return px_context_fail(ck->ctx, PX_STATUS_IO, "%s: cannot read at byte %" PRIu64 ": %s",
                             ck->path, off, strerror(errno));
    }
    if (got == 0)
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: truncated: file ends at byte %" PRIu64
                             " (it shrank while being read)",
                             ck->path, off);
    p += got;
    n -= (size_t)got;
    off += (uint64_t)got;
  }
  return PX_STATUS_OK;
}

/* The name of the last indexed section, for "after section 'x'" messages. */
static const char *px_ck_after(const struct px_checkpoint *ck, char *buf, size_t size) {
  if (ck->nsections == 0)
    snprintf(buf, size, "the header");
  else
    snprintf(buf, size, "section '%s'", ck->sections[ck->nsections - 1].name);
  return buf;
}

static enum px_status px_ck_read_header(struct px_checkpoint *ck, uint64_t *header_bytes) {
  unsigned char h[PX_CK_HDR_MAX];
  size_t avail = ck->size < PX_CK_HDR_FIXED ? (size_t)ck->size : PX_CK_HDR_FIXED;
  uint32_t version, endian, hbytes, flags, ls, lv, stored, computed;
  size_t expect, i;
  const char *path = ck->path;

  PX_TRY(px_ck_pread(ck, h, avail, 0));
  if (memcmp(h, px_ck_magic, avail < 8 ? avail : 8) != 0)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT, "%s: not a partix checkpoint (bad magic)",
                           path);
  if (avail < PX_CK_HDR_ENDIAN + 4)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: truncated: file ends at byte %zu inside the header", path, avail);
  endian = px_ck_get_u32(h + PX_CK_HDR_ENDIAN);
  if (endian == PX_CK_ENDIAN_SWAPPED)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: written on a %s-endian machine; this one is %s-endian and "
                           "cannot read it",
                           path, strcmp(px_ck_host_endian(), "little") == 0 ? "big" : "little",
                           px_ck_host_endian());
  if (endian != PX_CK_ENDIAN)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: bad byte-order marker 0x%08" PRIx32
                           " (expected 0x01020304): the file is damaged",
                           path, endian);
  version = px_ck_get_u32(h + PX_CK_HDR_VERSION);
  if (version > PX_CHECKPOINT_FORMAT_VERSION)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: format version %" PRIu32 " is newer than this partix (reads %u)",
                           path, version, PX_CHECKPOINT_FORMAT_VERSION);
  if (version != PX_CHECKPOINT_FORMAT_VERSION)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: format version %" PRIu32 " is not valid: the file is damaged", path,
                           version);
  if (avail < PX_CK_HDR_FIXED)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: truncated: file ends at byte %zu inside the header", path, avail);
  hbytes = px_ck_get_u32(h + PX_CK_HDR_BYTES);
  ls = px_ck_get_u32(h + PX_CK_HDR_SOLVER_LEN);
  lv = px_ck_get_u32(h + PX_CK_HDR_VERSION_LEN);
  expect = PX_CK_HDR_FIXED + (size_t)ls + lv + 4;
  expect += (size_t)px_ck_pad8(expect);
  if (ls == 0 || ls > PX_CHECKPOINT_NAME_MAX || lv == 0 || lv > PX_CHECKPOINT_NAME_MAX ||
      hbytes != expect)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: damaged header (length %" PRIu32 ", solver name length %" PRIu32
                           ", version length %" PRIu32 " do not fit together)",
                           path, hbytes, ls, lv);
  if (ck->size < hbytes)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: truncated: file ends at byte %" PRIu64
                           " inside the header (expected %" PRIu32 " header bytes)",
                           path, ck->size, hbytes);
  PX_TRY(px_ck_pread(ck, h + PX_CK_HDR_FIXED, hbytes - PX_CK_HDR_FIXED, PX_CK_HDR_FIXED));
  stored = px_ck_get_u32(h + hbytes - 4);
  computed = px_crc32_update(0, h, hbytes - 4);
  if (stored != computed)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: CRC mismatch in the header (stored 0x%08" PRIx32
                           ", computed 0x%08" PRIx32 "): the file is damaged",
                           path, stored, computed);
  flags = px_ck_get_u32(h + PX_CK_HDR_FLAGS);
  if (flags != 0)
    return px_context_fail(
        ck->ctx, PX_STATUS_FORMAT,
        "%s: header flags 0x%08" PRIx32 " name features this partix does not know", path, flags);
  for (i = 0; i < ls; ++i)
    if (!px_ck_name_char(h[PX_CK_HDR_FIXED + i]))
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: damaged header (invalid character in the solver name)", path);
  for (i = 0; i < lv; ++i) {
    unsigned char c = h[PX_CK_HDR_FIXED + ls + i];
    if (c < 0x20 || c > 0x7e)
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: damaged header (invalid character in the version)", path);
  }
  for (i = PX_CK_HDR_FIXED + ls + lv; i < hbytes - 4; ++i)
    if (h[i] != 0)
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: damaged header (nonzero padding at byte %zu)", path, i);
  memcpy(ck->solver, h + PX_CK_HDR_FIXED, ls);
  ck->solver[ls] = '\0';
  memcpy(ck->version, h + PX_CK_HDR_FIXED + ls, lv);
  ck->version[lv] = '\0';
  ck->format = version;
  ck->case_hash = px_ck_get_u64(h + PX_CK_HDR_CASE_HASH);
  ck->step = px_ck_get_u64(h + PX_CK_HDR_STEP);
  memcpy(&ck->time, h + PX_CK_HDR_TIME, 8);
  ck->created = px_ck_get_u64(h + PX_CK_HDR_CREATED);
  *header_bytes = hbytes;
  return PX_STATUS_OK;
}

/* Check a section header read at `off` (index = its position); fills sec. */
static enum px_status px_ck_parse_section(struct px_checkpoint *ck, const unsigned char *h,
                                          uint64_t off, struct px_ck_section *sec) {
  uint32_t dtype = px_ck_get_u32(h + PX_CK_SEC_DTYPE);
  uint32_t nlen = px_ck_get_u32(h + PX_CK_SEC_NAME_LEN);
  uint64_t count = px_ck_get_u64(h + PX_CK_SEC_COUNT);
  uint64_t bytes = px_ck_get_u64(h + PX_CK_SEC_BYTES);
  size_t i;
  if (nlen == 0 || nlen > PX_CHECKPOINT_NAME_MAX)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: damaged header of section #%zu at byte %" PRIu64
                           " (name length %" PRIu32 ")",
                           ck->path, ck->nsections + 1, off, nlen);
  for (i = 0; i < 64; ++i) {
    unsigned char c = h[PX_CK_SEC_NAME + i];
    if (i < nlen ? !px_ck_name_char(c) : c != 0)
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: damaged header of section #%zu at byte %" PRIu64
                             " (bad byte 0x%02x in its name field)",
                             ck->path, ck->nsections + 1, off, c);
  }
  memcpy(sec->name, h + PX_CK_SEC_NAME, nlen);
  sec->name[nlen] = '\0';
  if (!px_ck_dtype_known(dtype))
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: damaged header of section '%s' at byte %" PRIu64
                           " (unknown element type %" PRIu32 ")",
                           ck->path, sec->name, off, dtype);
  {
    uint64_t elem = px_dtype_size((enum px_dtype)dtype);
    if (count > UINT64_MAX / 2 / elem || bytes != count * elem)
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: damaged header of section '%s' at byte %" PRIu64 " (%" PRIu64
                             " elements of %s do not make %" PRIu64 " bytes)",
                             ck->path, sec->name, off, count, px_dtype_name((enum px_dtype)dtype),
                             bytes);
  }
  sec->dtype = (enum px_dtype)dtype;
  sec->count = count;
  sec->bytes = bytes;
  sec->offset = off;
  return PX_STATUS_OK;
}

/* Validate and index the section whose 8-byte tag is at `off` and return the
 * offset after it. crc: in = CRC of the file before `off`, out = after. */
static enum px_status px_ck_scan_section(struct px_checkpoint *ck, unsigned char *buf,
                                         size_t buf_size, uint64_t off, uint64_t *next,
                                         uint32_t *file_crc) {
  unsigned char h[PX_CK_SEC_HEADER], tail[16];
  struct px_ck_section sec;
  uint64_t pos, left, pad, tail_bytes;
  uint32_t crc, stored;
  size_t i;
  char after[96];
  if (ck->size - off < PX_CK_SEC_HEADER)
    return px_context_fail(
        ck->ctx, PX_STATUS_FORMAT,
        "%s: truncated: file ends at byte %" PRIu64 " inside the header of section #%zu (after %s)",
        ck->path, ck->size, ck->nsections + 1, px_ck_after(ck, after, sizeof after));
  PX_TRY(px_ck_pread(ck, h, sizeof h, off));
  memset(&sec, 0, sizeof sec);
  PX_TRY(px_ck_parse_section(ck, h, off, &sec));
  for (i = 0; i < ck->nsections; ++i)
    if (strcmp(ck->sections[i].name, sec.name) == 0)
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: section '%s' appears twice (at bytes %" PRIu64 " and %" PRIu64
                             "): the file is damaged",
                             ck->path, sec.name, ck->sections[i].offset, off);
  pos = off + PX_CK_SEC_HEADER;
  if (ck->size - pos < sec.bytes)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: truncated: file ends at byte %" PRIu64
                           " inside section '%s' (expected %" PRIu64 " payload bytes)",
                           ck->path, ck->size, sec.name, sec.bytes);
  pad = px_ck_pad8(sec.bytes);
  tail_bytes = pad + PX_CK_SEC_TRAILER;
  if (ck->size - pos - sec.bytes < tail_bytes)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: truncated: file ends at byte %" PRIu64
                           " inside the CRC of section '%s'",
                           ck->path, ck->size, sec.name);
  crc = px_crc32_update(0, h, sizeof h);
  for (left = sec.bytes; left;) {
    size_t n = left < buf_size ? (size_t)left : buf_size;
    PX_TRY(px_ck_pread(ck, buf, n, pos));
    crc = px_crc32_update(crc, buf, n);
    pos += n;
    left -= n;
  }
  PX_TRY(px_ck_pread(ck, tail, (size_t)tail_bytes, pos));
  crc = px_crc32_update(crc, tail, (size_t)pad);
  stored = px_ck_get_u32(tail + pad);
  if (stored != crc)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: CRC mismatch in section '%s' (stored 0x%08" PRIx32
                           ", computed 0x%08" PRIx32 "): the file is damaged",
                           ck->path, sec.name, stored, crc);
  for (i = 0; i < tail_bytes; ++i)
    if (i != pad && i != pad + 1 && i != pad + 2 && i != pad + 3 && tail[i] != 0)
      return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                             "%s: nonzero padding after section '%s' at byte %" PRIu64
                             ": the file is damaged",
                             ck->path, sec.name, pos + i);
  sec.crc = stored;
  *file_crc = px_crc32_combine(*file_crc, crc, PX_CK_SEC_HEADER + sec.bytes + pad);
  *file_crc = px_crc32_update(*file_crc, tail + pad, PX_CK_SEC_TRAILER);
  if (ck->nsections == ck->sections_cap) {
    size_t cap = ck->sections_cap ? 2 * ck->sections_cap : 16;
    void *grown = px_mem_realloc(ck->ctx, "checkpoint", ck->sections, cap * sizeof *ck->sections);
    if (!grown) return PX_STATUS_NOMEM;
    ck->sections = grown;
    ck->sections_cap = cap;
  }
  ck->sections[ck->nsections++] = sec;
  *next = pos + tail_bytes;
  return PX_STATUS_OK;
}

static enum px_status px_ck_scan_end(struct px_checkpoint *ck, uint64_t off, uint32_t file_crc) {
  unsigned char e[PX_CK_END_RECORD];
  uint64_t count, file_bytes;
  uint32_t stored, computed;
  char after[96];
  if (ck->size - off < PX_CK_END_RECORD)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: truncated: file ends at byte %" PRIu64
                           " inside the end marker (after %s)",
                           ck->path, ck->size, px_ck_after(ck, after, sizeof after));
  PX_TRY(px_ck_pread(ck, e, sizeof e, off));
  count = px_ck_get_u64(e + PX_CK_END_COUNT);
  file_bytes = px_ck_get_u64(e + PX_CK_END_FILE_BYTES);
  stored = px_ck_get_u32(e + PX_CK_END_CRC);
  computed = px_crc32_update(file_crc, e, PX_CK_END_CRC);
  if (stored != computed)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: CRC mismatch over the whole file (stored 0x%08" PRIx32
                           ", computed 0x%08" PRIx32 "): the file is damaged",
                           ck->path, stored, computed);
  if (count != ck->nsections)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: the end marker counts %" PRIu64
                           " sections but the file has %zu: the file is damaged",
                           ck->path, count, ck->nsections);
  if (file_bytes != off + PX_CK_END_RECORD || px_ck_get_u32(e + PX_CK_END_CRC + 4) != 0)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT, "%s: damaged end marker at byte %" PRIu64,
                           ck->path, off);
  if (ck->size > file_bytes)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: %" PRIu64
                           " bytes of trailing junk after the end marker (the "
                           "checkpoint ends at byte %" PRIu64 ", the file at byte %" PRIu64 ")",
                           ck->path, ck->size - file_bytes, file_bytes, ck->size);
  return PX_STATUS_OK;
}

static enum px_status px_ck_validate(struct px_checkpoint *ck) {
  unsigned char tag[8], *buf;
  size_t buf_size;
  uint64_t off = 0;
  uint32_t file_crc;
  enum px_status s = PX_STATUS_OK;
  char after[96];
  PX_TRY(px_ck_read_header(ck, &off));
  {
    unsigned char h[PX_CK_HDR_MAX];
    PX_TRY(px_ck_pread(ck, h, (size_t)off, 0));
    file_crc = px_crc32_update(0, h, (size_t)off);
  }
  buf_size = ck->size < PX_CK_BUFFER ? (size_t)ck->size : PX_CK_BUFFER;
  buf = px_mem_alloc(ck->ctx, "checkpoint buffer", buf_size);
  if (!buf) return PX_STATUS_NOMEM;
  for (;;) {
    if (ck->size - off < sizeof tag) {
      if (ck->size == off)
        s = px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                            "%s: truncated: file ends at byte %" PRIu64
                            " after %s (expected another section or the end marker)",
                            ck->path, ck->size, px_ck_after(ck, after, sizeof after));
      else
        s = px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                            "%s: truncated: file ends at byte %" PRIu64
                            " inside the record after %s",
                            ck->path, ck->size, px_ck_after(ck, after, sizeof after));
      break;
    }
    s = px_ck_pread(ck, tag, sizeof tag, off);
    if (s != PX_STATUS_OK) break;
    if (memcmp(tag, px_ck_section_tag, 8) == 0) {
      s = px_ck_scan_section(ck, buf, buf_size, off, &off, &file_crc);
      if (s != PX_STATUS_OK) break;
    } else if (memcmp(tag, px_ck_end_tag, 8) == 0) {
      s = px_ck_scan_end(ck, off, file_crc);
      break;
    } else {
      s = px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                          "%s: damaged: expected a section or the end marker at byte %" PRIu64
                          " (after %s), found bytes %02x %02x %02x %02x %02x %02x %02x %02x",
                          ck->path, off, px_ck_after(ck, after, sizeof after), tag[0], tag[1],
                          tag[2], tag[3], tag[4], tag[5], tag[6], tag[7]);
      break;
    }
  }
  px_mem_free(ck->ctx, buf);
  return s;
}

void px_checkpoint_close(struct px_checkpoint *ck) {
  struct px_context *ctx;
  if (!ck) return;
  ctx = ck->ctx;
  if (ck->fd >= 0) close(ck->fd);
  px_mem_free(ctx, ck->sections);
  px_mem_free(ctx, ck->path);
  px_mem_free(ctx, ck);
}

enum px_status px_checkpoint_open(struct px_context *ctx, const char *path,
                                  struct px_checkpoint **out) {
  struct px_checkpoint *ck;
  struct stat st;
  enum px_status s;
  if (!ctx) return PX_STATUS_INVALID;
  if (!path || !out)
    return px_context_fail(ctx, PX_STATUS_INVALID, "px_checkpoint_open: no path or no out");
  *out = NULL;
  ck = px_mem_calloc(ctx, "checkpoint", 1, sizeof *ck);
  if (!ck) return PX_STATUS_NOMEM;
  ck->ctx = ctx;
  ck->fd = -1;
  ck->path = px_ck_strdup(ctx, path);
  if (!ck->path) {
    px_checkpoint_close(ck);
    return PX_STATUS_NOMEM;
  }
  do {
    ck->fd = open(path, O_RDONLY);
  } while (ck->fd < 0 && errno == EINTR);
  if (ck->fd < 0) {
    s = px_context_fail(ctx, PX_STATUS_IO, "cannot open checkpoint %s: %s", path, strerror(errno));
    px_checkpoint_close(ck);
    return s;
  }
  if (fstat(ck->fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    s = px_context_fail(ctx, PX_STATUS_IO, "cannot read checkpoint %s: not a regular file", path);
    px_checkpoint_close(ck);
    return s;
  }
  ck->size = (uint64_t)st.st_size;
  if (ck->size == 0) {
    s = px_context_fail(ctx, PX_STATUS_FORMAT, "%s: truncated: the file is empty", path);
    px_checkpoint_close(ck);
    return s;
  }
  s = px_ck_validate(ck);
  if (s != PX_STATUS_OK) {
    px_checkpoint_close(ck);
    return s;
  }
  px_log(ctx, PX_LOG_LEVEL_DEBUG,
         "checkpoint %s: solver %s, step %" PRIu64 ", %zu sections, %" PRIu64 " bytes, valid", path,
         ck->solver, ck->step, ck->nsections, ck->size);
  *out = ck;
  return PX_STATUS_OK;
}

const char *px_checkpoint_solver(const struct px_checkpoint *ck) { return ck ? ck->solver : ""; }
uint64_t px_checkpoint_case_hash(const struct px_checkpoint *ck) { return ck ? ck->case_hash : 0; }
uint64_t px_checkpoint_step(const struct px_checkpoint *ck) { return ck ? ck->step : 0; }
double px_checkpoint_time(const struct px_checkpoint *ck) { return ck ? ck->time : 0.0; }
const char *px_checkpoint_version(const struct px_checkpoint *ck) { return ck ? ck->version : ""; }
uint32_t px_checkpoint_format_version(const struct px_checkpoint *ck) {
  return ck ? ck->format : 0;
}
uint64_t px_checkpoint_created(const struct px_checkpoint *ck) { return ck ? ck->created : 0; }
size_t px_checkpoint_section_count(const struct px_checkpoint *ck) {
  return ck ? ck->nsections : 0;
}

enum px_status px_checkpoint_section(const struct px_checkpoint *ck, size_t index,
                                     const char **name, enum px_dtype *dtype, uint64_t *count) {
  const struct px_ck_section *sec;
  if (!ck) return PX_STATUS_INVALID;
  if (index >= ck->nsections)
    return px_context_fail(ck->ctx, PX_STATUS_INVALID, "%s: no section #%zu (the file has %zu)",
                           ck->path, index, ck->nsections);
  sec = &ck->sections[index];
  if (name) *name = sec->name;
  if (dtype) *dtype = sec->dtype;
  if (count) *count = sec->count;
  return PX_STATUS_OK;
}

static const struct px_ck_section *px_ck_lookup(const struct px_checkpoint *ck, const char *name) {
  size_t i;
  if (!name) return NULL;
  for (i = 0; i < ck->nsections; ++i)
    if (strcmp(ck->sections[i].name, name) == 0) return &ck->sections[i];
  return NULL;
}

static enum px_status px_ck_not_found(struct px_checkpoint *ck, const char *name) {
  char list[1024];
  size_t used = 0, i;
  list[0] = '\0';
  for (i = 0; i < ck->nsections; ++i) {
    const char *sep = i ? ", " : "";
    size_t need = strlen(sep) + strlen(ck->sections[i].name);
    if (used + need + 8 >= sizeof list) {
      snprintf(list + used, sizeof list - used, ", ...");
      break;
    }
    used += (size_t)snprintf(list + used, sizeof list - used, "%s%s", sep, ck->sections[i].name);
  }
  if (ck->nsections == 0)
    return px_context_fail(ck->ctx, PX_STATUS_NOT_FOUND,
                           "%s: no section '%s' (the file has no sections)", ck->path,
                           name ? name : "");
  return px_context_fail(ck->ctx, PX_STATUS_NOT_FOUND, "%s: no section '%s' (the file has %zu: %s)",
                         ck->path, name ? name : "", ck->nsections, list);
}

enum px_status px_checkpoint_find(struct px_checkpoint *ck, const char *name, enum px_dtype *dtype,
                                  uint64_t *count) {
  const struct px_ck_section *sec;
  if (!ck) return PX_STATUS_INVALID;
  sec = px_ck_lookup(ck, name);
  if (!sec) return px_ck_not_found(ck, name);
  if (dtype) *dtype = sec->dtype;
  if (count) *count = sec->count;
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_read_begin(struct px_checkpoint *ck, const char *name,
                                        enum px_dtype dtype, uint64_t count) {
  const struct px_ck_section *sec;
  unsigned char h[PX_CK_SEC_HEADER];
  if (!ck) return PX_STATUS_INVALID;
  ck->reading = NULL;
  sec = px_ck_lookup(ck, name);
  if (!sec) return px_ck_not_found(ck, name);
  if (sec->dtype != dtype || sec->count != count)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: section '%s': expected %" PRIu64 " %s, file has %" PRIu64 " %s",
                           ck->path, sec->name, count, px_dtype_name(dtype), sec->count,
                           px_dtype_name(sec->dtype));
  /* Read the header again: the CRC covers it, and it must still be the same
   * section (the file may have been changed in place since open). */
  PX_TRY(px_ck_pread(ck, h, sizeof h, sec->offset));
  if (memcmp(h, px_ck_section_tag, 8) != 0 || px_ck_get_u64(h + PX_CK_SEC_COUNT) != sec->count ||
      px_ck_get_u32(h + PX_CK_SEC_DTYPE) != (uint32_t)sec->dtype ||
      strncmp((const char *)h + PX_CK_SEC_NAME, sec->name, 64) != 0)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: section '%s' changed since the file was opened", ck->path,
                           sec->name);
  ck->reading = sec;
  ck->read_done = 0;
  ck->read_crc = px_crc32_update(0, h, sizeof h);
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_read_chunk(struct px_checkpoint *ck, void *dst, uint64_t count) {
  const struct px_ck_section *sec;
  unsigned char *p = dst;
  uint64_t bytes, elem, pos;
  if (!ck) return PX_STATUS_INVALID;
  sec = ck->reading;
  if (!sec)
    return px_context_fail(ck->ctx, PX_STATUS_INVALID, "%s: chunk read outside a section",
                           ck->path);
  elem = px_dtype_size(sec->dtype);
  if (count > (sec->bytes - ck->read_done) / elem) {
    ck->reading = NULL;
    return px_context_fail(ck->ctx, PX_STATUS_INVALID,
                           "%s: section '%s': chunk of %" PRIu64 " elements exceeds the %" PRIu64
                           " left",
                           ck->path, sec->name, count, (sec->bytes - ck->read_done) / elem);
  }
  if (count && !dst) {
    ck->reading = NULL;
    return px_context_fail(ck->ctx, PX_STATUS_INVALID, "%s: section '%s': no destination", ck->path,
                           sec->name);
  }
  bytes = count * elem;
  pos = sec->offset + PX_CK_SEC_HEADER + ck->read_done;
  while (bytes) {
    size_t n = bytes < PX_CK_BUFFER ? (size_t)bytes : PX_CK_BUFFER;
    enum px_status s = px_ck_pread(ck, p, n, pos);
    if (s != PX_STATUS_OK) {
      ck->reading = NULL;
      return s;
    }
    ck->read_crc = px_crc32_update(ck->read_crc, p, n);
    p += n;
    pos += n;
    bytes -= n;
    ck->read_done += n;
  }
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_read_end(struct px_checkpoint *ck) {
  const struct px_ck_section *sec;
  unsigned char tail[16];
  uint64_t pad;
  uint32_t stored, crc;
  if (!ck) return PX_STATUS_INVALID;
  sec = ck->reading;
  ck->reading = NULL;
  if (!sec)
    return px_context_fail(ck->ctx, PX_STATUS_INVALID, "%s: section read ended but none was begun",
                           ck->path);
  if (ck->read_done != sec->bytes)
    return px_context_fail(
        ck->ctx, PX_STATUS_INVALID,
        "%s: section '%s': read ended after %" PRIu64 " of its %" PRIu64 " elements", ck->path,
        sec->name, ck->read_done / px_dtype_size(sec->dtype), sec->count);
  pad = px_ck_pad8(sec->bytes);
  PX_TRY(px_ck_pread(ck, tail, (size_t)(pad + 4), sec->offset + PX_CK_SEC_HEADER + sec->bytes));
  crc = px_crc32_update(ck->read_crc, tail, (size_t)pad);
  stored = px_ck_get_u32(tail + pad);
  if (stored != crc || stored != sec->crc)
    return px_context_fail(ck->ctx, PX_STATUS_FORMAT,
                           "%s: CRC mismatch in section '%s' (stored 0x%08" PRIx32
                           ", computed 0x%08" PRIx32
                           "): the file was damaged or changed after it was opened",
                           ck->path, sec->name, stored, crc);
  return PX_STATUS_OK;
}

enum px_status px_checkpoint_read(struct px_checkpoint *ck, const char *name, enum px_dtype dtype,
                                  uint64_t count, void *dst) {
  if (!ck) return PX_STATUS_INVALID;
  PX_TRY(px_checkpoint_read_begin(ck, name, dtype, count));
  {
    enum px_status s = px_checkpoint_read_chunk(ck, dst, count);
    if (s != PX_STATUS_OK) {
      ck->reading = NULL;
      return s;
    }
  }
  return px_checkpoint_read_end(ck);
}
