/* Files that are never torn: output is written to a temporary file next to the
 * target, flushed, fsynced, and renamed over it, so a crash, a kill or a full
 * disk at any moment leaves either the old or the new file, never a mixture. */
#ifndef PARTIX_FILE_H
#define PARTIX_FILE_H

#include <stdio.h>

#include "partix/context.h"
#include "partix/export.h"

#ifdef __cplusplus
extern "C" {
#endif

struct px_file;

/* Open `path` for atomic replacement (the data goes to "path.tmp-PID-N" until
 * commit; PID is the writing process, N counts opens within it, so that two
 * writers never share a temporary). The temporary is always a new file
 * (O_CREAT | O_EXCL | O_NOFOLLOW): a file or symbolic link planted at its
 * name is never written through, the name is skipped. A symbolic link at
 * `path` itself is replaced by the new file, its target left alone. The
 * directory must exist. */
PX_API enum px_status px_file_open(struct px_context *ctx, const char *path, struct px_file **out);
/* The stream to write to (owned by the px_file). */
PX_API FILE *px_file_stream(struct px_file *f);
/* Flush, check for write errors, fsync, close and rename over the target, then
 * fsync the directory. Frees f in every case; on failure the temporary file is
 * removed, the target is untouched and the message says why (e.g. disk full). */
PX_API enum px_status px_file_commit(struct px_file *f);
/* Discard everything written; the target is untouched. NULL-safe. */
PX_API void px_file_abort(struct px_file *f);
/* Write a whole buffer atomically. */
PX_API enum px_status px_file_write_all(struct px_context *ctx, const char *path, const void *data,
                                        size_t bytes);

/* Remove the temporaries "path.tmp-PID[-N]" that writers of `path` which no
 * longer run (killed, crashed) left behind; those of live processes (this one
 * included) are kept. Best effort: returns how many were removed and logs each
 * at info level. A PID reused by an unrelated live process only keeps a stale
 * file longer. Caution: on a directory shared between hosts, PIDs of other
 * hosts cannot be checked; writers on two hosts must not share a target. */
PX_API size_t px_file_remove_stale(struct px_context *ctx, const char *path);
/* The same for every target in the folder `dir` (not its subfolders): the
 * temporaries "NAME.tmp-PID[-N]" of any NAME whose writer no longer runs.
 * A run folder is swept when a run opens it. */
PX_API size_t px_file_remove_stale_in(struct px_context *ctx, const char *dir);

/* Create a directory and its parents (like mkdir -p). */
PX_API enum px_status px_file_mkdirs(struct px_context *ctx, const char *path);
/* 1 if `path` exists (any type). */
PX_API int px_file_exists(const char *path);
/* Join directory and name into buf ("dir/name"); fails if it does not fit. */
PX_API enum px_status px_file_join(struct px_context *ctx, char *buf, size_t size, const char *dir,
                                   const char *name);

#ifdef __cplusplus
}
#endif
#endif
