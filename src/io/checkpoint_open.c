/* Checkpoint files: opening one, and validating all of it (header, every
 * section and the end record, with their CRCs) before anything is read. */
#include "partix/checkpoint.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io/checkpoint_impl.h"
#include "io/crc32.h"
#include "partix/memory.h"

/* Read exactly n bytes at `off`, which the caller has checked lie within
 * ck->size; a short read means the file shrank under us. */
enum px_status px_ck_pread(struct px_checkpoint *ck, void *dst, size_t n, uint64_t off) {
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
