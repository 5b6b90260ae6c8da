/* Checkpoint files: reading the sections of an open, validated checkpoint,
 * whole or piece by piece, each checked against its CRC. */
#include "partix/checkpoint.h"

#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "io/checkpoint_impl.h"
#include "io/crc32.h"

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
