/* Checkpoint files, private layout (checkpoint.c: the format and the
 * writer; checkpoint_open.c: opening and validating a file;
 * checkpoint_read.c: reading its sections). */
#ifndef PX_CHECKPOINT_IMPL_H
#define PX_CHECKPOINT_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "partix/checkpoint.h"

/* ----------------------------------------------------------- the format */

extern const unsigned char px_ck_magic[8];
extern const unsigned char px_ck_section_tag[8];
extern const unsigned char px_ck_end_tag[8];

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

/* Zero bytes that pad n bytes to a multiple of 8. */
uint64_t px_ck_pad8(uint64_t n);
void px_ck_put_u32(unsigned char *p, uint32_t v);
void px_ck_put_u64(unsigned char *p, uint64_t v);
uint32_t px_ck_get_u32(const unsigned char *p);
uint64_t px_ck_get_u64(const unsigned char *p);
/* 1 if c may appear in a section or solver name. */
int px_ck_name_char(int c);
/* NULL if `name` is a valid section or solver name, else why not. */
const char *px_ck_name_problem(const char *name);
int px_ck_dtype_known(uint32_t dtype);
/* "little" or "big": this machine's byte order. */
const char *px_ck_host_endian(void);
/* A px_mem copy of s (owned by the caller), NULL when out of memory. */
char *px_ck_strdup(struct px_context *ctx, const char *s);

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
enum px_status px_ck_pread(struct px_checkpoint *ck, void *dst, size_t n, uint64_t off);

#endif
