#include "partix/file.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdatomic.h>
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

/* Numbers the temporaries of this process: two px_file open on the same
 * target (two threads, or a writer that was never committed nor aborted) must
 * not write into one file, which a bare path.tmp-PID would make them do. */
static atomic_ulong px_file_sequence;

static char *px_file_strdup(struct px_context *ctx, const char *s, size_t extra) {
  size_t n = strlen(s);
  char *d = px_mem_alloc(ctx, "file", n + extra + 1);
  if (d) memcpy(d, s, n + 1);
  return d;
}

/* How many taken temporary names px_file_open skips before giving up. */
#define PX_FILE_TRIES 1000

enum px_status px_file_open(struct px_context *ctx, const char *path, struct px_file **out) {
  struct px_file *f;
  int fd = -1, tries;
  if (!ctx || !path || !out) return PX_STATUS_INVALID;
  *out = NULL;
  f = px_mem_calloc(ctx, "file", 1, sizeof *f);
  if (!f) return PX_STATUS_NOMEM;
  f->ctx = ctx;
  f->path = px_file_strdup(ctx, path, 0);
  f->tmp = px_file_strdup(ctx, path, 48);
  if (!f->path || !f->tmp) {
    px_file_release(f);
    return PX_STATUS_NOMEM;
  }
  /* A new file, never an existing one or the target of a planted symbolic
     link (O_EXCL refuses both; O_NOFOLLOW also a link at the last step):
     a name that is taken is skipped for the next number. */
  for (tries = 0;; ++tries) {
    snprintf(f->tmp + strlen(path), 48, ".tmp-%ld-%lu", (long)getpid(),
             atomic_fetch_add(&px_file_sequence, 1ul));
    fd = open(f->tmp, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST || tries == PX_FILE_TRIES) break;
  }
  if (fd >= 0) {
    f->stream = fdopen(fd, "wb");
    if (!f->stream) close(fd);
  }
  if (!f->stream) {
    enum px_status s = px_context_fail(
        ctx, PX_STATUS_IO, "cannot write %s: cannot create %s: %s%s", path, f->tmp, strerror(errno),
        errno == EEXIST ? " (and the names before it are taken too)" : "");
    if (fd >= 0) remove(f->tmp);
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
    enum px_status s = px_context_fail(ctx, PX_STATUS_IO,
                                       "cannot write %s: %s (the previous file, if any, is kept)",
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
    enum px_status s =
        px_context_fail(ctx, PX_STATUS_IO, "cannot write %s: %s", path, strerror(errno));
    px_file_abort(f);
    return s;
  }
  return px_file_commit(f);
}

enum px_status px_file_mkdirs(struct px_context *ctx, const char *path) {
  char buf[4096];
  size_t n, i;
  if (!path) return px_context_fail(ctx, PX_STATUS_INVALID, "px_file_mkdirs: no path");
  n = strlen(path);
  if (n == 0) return PX_STATUS_OK;
  if (n >= sizeof buf) return px_context_fail(ctx, PX_STATUS_INVALID, "path too long: %s", path);
  memcpy(buf, path, n + 1);
  for (i = 1; i <= n; ++i) {
    if (buf[i] == '/' || buf[i] == '\0') {
      char c = buf[i];
      struct stat st;
      buf[i] = '\0';
      /* An existing directory is fine whatever mkdir says about it (EEXIST,
       * but also EACCES/EROFS on some file systems for an existing path). */
      if (mkdir(buf, 0777) != 0) {
        int err = errno;
        if (stat(buf, &st) != 0)
          return px_context_fail(ctx, PX_STATUS_IO, "cannot create directory %s: %s", buf,
                                 strerror(err));
        if (!S_ISDIR(st.st_mode))
          return px_context_fail(ctx, PX_STATUS_IO,
                                 "cannot create directory %s: %s exists and is not a directory",
                                 path, buf);
      }
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
  if (!buf || size == 0 || !name)
    return px_context_fail(ctx, PX_STATUS_INVALID, "px_file_join: no buffer or no name");
  if (!dir || !dir[0] || strcmp(dir, ".") == 0)
    n = snprintf(buf, size, "%s", name);
  else if (dir[strlen(dir) - 1] == '/')
    n = snprintf(buf, size, "%s%s", dir, name);
  else
    n = snprintf(buf, size, "%s/%s", dir, name);
  if (n < 0 || (size_t)n >= size)
    return px_context_fail(ctx, PX_STATUS_INVALID, "path too long (more than %zu bytes): %s/%s",
                           size - 1, dir ? dir : "", name);
  return PX_STATUS_OK;
}

/* Parses "<digits>" or "<digits>-<digits>" (the whole string) into a PID. */
static long px_file_temp_pid(const char *s) {
  long pid = 0;
  const char *p = s;
  if (*p < '0' || *p > '9') return -1;
  while (*p >= '0' && *p <= '9') {
    if (pid > 99999999L) return -1;
    pid = 10 * pid + (*p++ - '0');
  }
  if (*p == '-') {
    ++p;
    if (*p < '0' || *p > '9') return -1;
    while (*p >= '0' && *p <= '9') ++p;
  }
  return *p == '\0' && pid > 0 ? pid : -1;
}

/* Remove from `dir` the temporaries "BASE.tmp-PID[-N]" of writers that no
 * longer run; base == NULL matches any BASE. */
static size_t px_file_sweep(struct px_context *ctx, const char *dir, const char *base) {
  char full[4096];
  size_t blen = base ? strlen(base) : 0, removed = 0;
  long self = (long)getpid();
  DIR *d;
  struct dirent *e;
  d = opendir(dir);
  if (!d) return 0;
  while ((e = readdir(d)) != NULL) {
    const char *tmp;
    long pid;
    if (base) {
      if (strncmp(e->d_name, base, blen) != 0 || strncmp(e->d_name + blen, ".tmp-", 5) != 0)
        continue;
      tmp = e->d_name + blen;
    } else {
      /* the last ".tmp-" of the name, after a non-empty target name */
      const char *p = e->d_name, *q;
      tmp = NULL;
      while ((q = strstr(p, ".tmp-")) != NULL) {
        if (q > e->d_name) tmp = q;
        p = q + 1;
      }
      if (!tmp) continue;
    }
    pid = px_file_temp_pid(tmp + 5);
    if (pid <= 0 || pid == self) continue;
    /* ESRCH: no such process. EPERM means it exists (another user): keep. */
    if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue;
    if (snprintf(full, sizeof full, "%s/%s", dir, e->d_name) >= (int)sizeof full) continue;
    if (remove(full) == 0) {
      ++removed;
      px_log(ctx, PX_LOG_LEVEL_INFO, "removed %s, left by process %ld which no longer runs", full,
             pid);
    }
  }
  closedir(d);
  return removed;
}

size_t px_file_remove_stale(struct px_context *ctx, const char *path) {
  char dir[4096];
  const char *base, *slash;
  if (!path || !path[0]) return 0;
  slash = strrchr(path, '/');
  if (slash) {
    size_t n = (size_t)(slash - path);
    if (n == 0) n = 1; /* "/name" */
    if (n >= sizeof dir) return 0;
    memcpy(dir, path, n);
    dir[n] = '\0';
    base = slash + 1;
  } else {
    strcpy(dir, ".");
    base = path;
  }
  if (!base[0]) return 0;
  return px_file_sweep(ctx, dir, base);
}

size_t px_file_remove_stale_in(struct px_context *ctx, const char *dir) {
  if (!dir || !dir[0]) return 0;
  return px_file_sweep(ctx, dir, NULL);
}
