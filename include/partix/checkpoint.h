/* Checkpoints: everything the next step of a solver reads, in one versioned,
 * self-describing binary file of named, typed sections, each with a CRC32,
 * written atomically (temporary file, fsync, rename), so that a crash at any
 * moment leaves the previous checkpoint intact and any damage is detected on
 * load. The byte layout is in docs/checkpoint-format.md.
 *
 * Writing:
 *   px_checkpoint_writer_open(ctx, "run/step-100.chk", "granular", hash, 100, t, &w);
 *   px_checkpoint_write(w, "pos_x", PX_DTYPE_F64, n, x);  ... one call per section
 *   px_checkpoint_writer_commit(w);   (or px_checkpoint_writer_abort(w) on error)
 * Reading:
 *   px_checkpoint_open(ctx, path, &ck);   validates the whole file
 *   px_checkpoint_read(ck, "pos_x", PX_DTYPE_F64, n, x);
 *   px_checkpoint_close(ck);
 *
 * Errors: PX_STATUS_FORMAT when a file is damaged, truncated or incompatible,
 * PX_STATUS_IO when it cannot be opened, read or written; a section whose type
 * or count differs from what the reader expects is PX_STATUS_FORMAT too (the
 * file does not fit this solver), a missing one PX_STATUS_NOT_FOUND. A wrong
 * call (bad or duplicate name, NULL data) is PX_STATUS_INVALID. Every message
 * starts with the file name and says where and what. */
#ifndef PARTIX_CHECKPOINT_H
#define PARTIX_CHECKPOINT_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "partix/export.h"
#include "partix/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The format version this partix writes and the only one it reads. */
#define PX_CHECKPOINT_FORMAT_VERSION 1u
/* Longest section name and solver name in bytes (names use the characters
 * A-Z a-z 0-9 _ - . / : only). */
#define PX_CHECKPOINT_NAME_MAX 63

struct px_checkpoint_writer;
struct px_checkpoint;

/* ------------------------------------------------------------------ writer */

/* Start a checkpoint at `path` for `solver` (e.g. "granular"), the hash of the
 * case it belongs to, the step about to be taken and the simulated time. The
 * data go to a temporary file next to `path` (path.tmp-PID-N) that replaces
 * `path` only on commit. Temporaries left next to `path` by writers that were
 * killed (processes no longer alive) are removed here. */
PX_API enum px_status px_checkpoint_writer_open(struct px_context *ctx, const char *path,
                                                const char *solver, uint64_t case_hash,
                                                uint64_t step, double sim_time,
                                                struct px_checkpoint_writer **out);

/* Write a whole section: `count` elements of `dtype` from `data` (may be NULL
 * when count is 0). Names are unique within a checkpoint. */
PX_API enum px_status px_checkpoint_write(struct px_checkpoint_writer *w, const char *name,
                                          enum px_dtype dtype, uint64_t count, const void *data);

/* Write a section piecewise (e.g. downloading a device buffer in chunks):
 * begin declares the total count; chunks append elements in order; end checks
 * that exactly `count` elements were given. No other section may be written
 * between begin and end. */
PX_API enum px_status px_checkpoint_write_begin(struct px_checkpoint_writer *w, const char *name,
                                                enum px_dtype dtype, uint64_t count);
PX_API enum px_status px_checkpoint_write_chunk(struct px_checkpoint_writer *w, const void *data,
                                                uint64_t count);
PX_API enum px_status px_checkpoint_write_end(struct px_checkpoint_writer *w);

/* Finish the file (end marker), flush, fsync, rename over `path`, fsync the
 * directory. Frees w in every case. After any failed call on w (including a
 * wrong call such as a duplicate name) commit refuses and nothing replaces
 * `path`: a checkpoint is written completely or not at all. */
PX_API enum px_status px_checkpoint_writer_commit(struct px_checkpoint_writer *w);
/* Discard the temporary file; `path` is untouched. Frees w. NULL-safe. */
PX_API void px_checkpoint_writer_abort(struct px_checkpoint_writer *w);

/* ------------------------------------------------------------------ reader */

/* Open and validate the whole file (magic, version, byte order, every CRC,
 * the end marker, no trailing bytes), streaming through it with a fixed
 * buffer, and index its sections. The file stays open until close. */
PX_API enum px_status px_checkpoint_open(struct px_context *ctx, const char *path,
                                         struct px_checkpoint **out);
/* NULL-safe. */
PX_API void px_checkpoint_close(struct px_checkpoint *ck);

/* Header fields. Strings are owned by ck. */
PX_API const char *px_checkpoint_solver(const struct px_checkpoint *ck);
PX_API uint64_t px_checkpoint_case_hash(const struct px_checkpoint *ck);
PX_API uint64_t px_checkpoint_step(const struct px_checkpoint *ck);
PX_API double px_checkpoint_time(const struct px_checkpoint *ck);
/* The partix version that wrote the file ("0.1.0"). */
PX_API const char *px_checkpoint_version(const struct px_checkpoint *ck);
/* The format version of the file (PX_CHECKPOINT_FORMAT_VERSION). */
PX_API uint32_t px_checkpoint_format_version(const struct px_checkpoint *ck);
/* When the writer was opened, in seconds since 1970-01-01 UTC. */
PX_API uint64_t px_checkpoint_created(const struct px_checkpoint *ck);

/* Sections in file order. px_checkpoint_section fails with PX_STATUS_INVALID
 * for index >= count; any of the out-pointers may be NULL; *name is owned by ck. */
PX_API size_t px_checkpoint_section_count(const struct px_checkpoint *ck);
PX_API enum px_status px_checkpoint_section(const struct px_checkpoint *ck, size_t index,
                                            const char **name, enum px_dtype *dtype,
                                            uint64_t *count);
/* Look a section up by name. PX_STATUS_NOT_FOUND (message lists the sections
 * present) when absent. dtype and count may be NULL. */
PX_API enum px_status px_checkpoint_find(struct px_checkpoint *ck, const char *name,
                                         enum px_dtype *dtype, uint64_t *count);

/* Read a whole section into dst (count * px_dtype_size(dtype) bytes). The
 * section must hold exactly `count` elements of `dtype`, else
 * PX_STATUS_FORMAT says what differs. The section's CRC is verified again
 * while reading; on any failure dst holds unspecified bytes. */
PX_API enum px_status px_checkpoint_read(struct px_checkpoint *ck, const char *name,
                                         enum px_dtype dtype, uint64_t count, void *dst);

/* Read a section piecewise (e.g. uploading to a device in chunks): begin checks
 * type and count like px_checkpoint_read; chunks deliver the next `count`
 * elements in order; end checks that all were read and verifies the CRC. Data
 * delivered by chunks must not be trusted until end succeeds. */
PX_API enum px_status px_checkpoint_read_begin(struct px_checkpoint *ck, const char *name,
                                               enum px_dtype dtype, uint64_t count);
PX_API enum px_status px_checkpoint_read_chunk(struct px_checkpoint *ck, void *dst, uint64_t count);
PX_API enum px_status px_checkpoint_read_end(struct px_checkpoint *ck);

#ifdef __cplusplus
}
#endif
#endif
