#include "partix/file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "partix/memory.h"

struct px_file {
  struct px_context *ctx; /* borrowed */
  FILE *stream;           /* owned */
  char *path;             /* owned: the target */
  char *tmp;              /* owned: the temporary */
};

static void px_file_release(struct px_file *f) {
  px_mem_free(f->ctx, f->path);
  px_mem_free(f->ctx, f->tmp);
  px_mem_free(f->ctx, f);
}

static char *px_file_strdup(struct px_context *ctx, const char *s, size_t extra) {
  size_t n = strlen(s);
  char *d = px_mem_alloc(ctx, "file", n + extra + 1);
  if (d) memcpy(d, s, n + 1);
  return d;
}

enum px_status px_file_open(struct px_context *ctx, const char *path, struct px_file **out) {
  struct px_file *f;
  if (!ctx || !path || !out) return PX_STATUS_INVALID;
  *out = NULL;
  f = px_mem_calloc(ctx, "file", 1, sizeof *f);
  if (!f) return PX_STATUS_NOMEM;
  f->ctx = ctx;
  f->path = px_file_strdup(ctx, path, 0);
  f->tmp = px_file_strdup(ctx, path, 32);
  if (!f->path || !f->tmp) {
    px_file_release(f);
    return PX_STATUS_NOMEM;
  }
  snprintf(f->tmp + strlen(path), 32, ".tmp-%ld", (long)getpid());
  f->stream = fopen(f->tmp, "wb");
  if (!f->stream) {
    enum px_status s =
        px_context_fail(ctx, PX_STATUS_IO, "cannot create %s: %s", f->tmp, strerror(errno));
    px_file_release(f);
    return s;
  }
  *out = f;
  return PX_STATUS_OK;
}

FILE *px_file_stream(struct px_file *f) { return f ? f->stream : NULL; }

void px_file_abort(struct px_file *f) {
  if (!f) return;
  if (f->stream) fclose(f->stream);
  remove(f->tmp);
  px_file_release(f);
}

/* fsync the directory holding `path` so that the rename itself is durable. */
static void px_file_sync_dir(const char *path) {
  char dir[4096];
  const char *slash = strrchr(path, '/');
  int fd;
  if (!slash) {
    strcpy(dir, ".");
  } else {
    size_t n = (size_t)(slash - path);
    if (n == 0) n = 1;
    if (n >= sizeof dir) return;
    memcpy(dir, path, n);
    dir[n] = '\0';
  }
  fd = open(dir, O_RDONLY);
  if (fd >= 0) {
    fsync(fd);
    close(fd);
  }
}

enum px_status px_file_commit(struct px_file *f) {
  struct px_context *ctx;
  int err = 0;
  if (!f) return PX_STATUS_INVALID;
  ctx = f->ctx;
  if (fflush(f->stream) != 0) err = errno;
  if (!err && ferror(f->stream)) err = EIO;
  if (!err && fsync(fileno(f->stream)) != 0) err = errno;
  if (fclose(f->stream) != 0 && !err) err = errno;
  f->stream = NULL;
  if (!err && rename(f->tmp, f->path) != 0) err = errno;
  if (err) {
    enum px_status s =
        px_context_fail(ctx, PX_STATUS_IO, "cannot write %s: %s (the previous file, if any, is kept)",
                        f->path, strerror(err));
    remove(f->tmp);
    px_file_release(f);
    return s;
  }
  px_file_sync_dir(f->path);
  px_file_release(f);
  return PX_STATUS_OK;
}

enum px_status px_file_write_all(struct px_context *ctx, const char *path, const void *data,
                                 size_t bytes) {
  struct px_file *f;
  PX_TRY(px_file_open(ctx, path, &f));
  if (bytes && fwrite(data, 1, bytes, f->stream) != bytes) {
    enum px_status s = px_context_fail(ctx, PX_STATUS_IO, "cannot write %s: %s", path,
                                       strerror(errno));
    px_file_abort(f);
    return s;
  }
  return px_file_commit(f);
}

enum px_status px_file_mkdirs(struct px_context *ctx, const char *path) {
  char buf[4096];
  size_t n = strlen(path), i;
  if (n == 0) return PX_STATUS_OK;
  if (n >= sizeof buf) return px_context_fail(ctx, PX_STATUS_INVALID, "path too long: %s", path);
  memcpy(buf, path, n + 1);
  for (i = 1; i <= n; ++i) {
    if (buf[i] == '/' || buf[i] == '\0') {
      char c = buf[i];
      struct stat st;
      buf[i] = '\0';
      if (mkdir(buf, 0777) != 0 && errno != EEXIST)
        return px_context_fail(ctx, PX_STATUS_IO, "cannot create directory %s: %s", buf,
                               strerror(errno));
      if (stat(buf, &st) != 0 || !S_ISDIR(st.st_mode))
        return px_context_fail(ctx, PX_STATUS_IO, "%s exists and is not a directory", buf);
      buf[i] = c;
    }
  }
  return PX_STATUS_OK;
}

int px_file_exists(const char *path) {
  struct stat st;
  return path && stat(path, &st) == 0;
}

enum px_status px_file_join(struct px_context *ctx, char *buf, size_t size, const char *dir,
                            const char *name) {
  int n;
  if (!dir || !dir[0] || strcmp(dir, ".") == 0)
    n = snprintf(buf, size, "%s", name);
  else if (dir[strlen(dir) - 1] == '/')
    n = snprintf(buf, size, "%s%s", dir, name);
  else
    n = snprintf(buf, size, "%s/%s", dir, name);
  if (n < 0 || (size_t)n >= size)
    return px_context_fail(ctx, PX_STATUS_INVALID, "path too long: %s/%s", dir, name);
  return PX_STATUS_OK;
}
