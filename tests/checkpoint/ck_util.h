/* Helpers shared by the checkpoint and file tests: whole-file read/write
 * without the atomic machinery (to craft damaged files), scratch
 * directories, temporary-file counting. */
#ifndef PX_TESTS_CK_UTIL_H
#define PX_TESTS_CK_UTIL_H

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "px_test.h"

/* Whole file into a malloc'ed buffer (NULL if it cannot be read). */
static inline unsigned char *ck_slurp(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  unsigned char *data;
  long n;
  if (!f) return NULL;
  if (fseek(f, 0, SEEK_END) != 0 || (n = ftell(f)) < 0 || fseek(f, 0, SEEK_SET) != 0) {
    fclose(f);
    return NULL;
  }
  data = malloc((size_t)n + 1);
  if (data && fread(data, 1, (size_t)n, f) != (size_t)n) {
    free(data);
    data = NULL;
  }
  fclose(f);
  *size = (size_t)n;
  return data;
}

/* Plain (non-atomic) write, for crafting files. Returns 0 on success. */
static inline int ck_spit(const char *path, const void *data, size_t n) {
  FILE *f = fopen(path, "wb");
  int bad;
  if (!f) return -1;
  bad = n && fwrite(data, 1, n, f) != n;
  bad |= fclose(f) != 0;
  return bad ? -1 : 0;
}

/* Remove a directory tree (files and subdirectories). */
static inline void ck_rm_rf(const char *path) {
  DIR *d = opendir(path);
  struct dirent *e;
  char full[4096];
  if (!d) {
    remove(path);
    return;
  }
  while ((e = readdir(d)) != NULL) {
    struct stat st;
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    if (snprintf(full, sizeof full, "%s/%s", path, e->d_name) >= (int)sizeof full) continue;
    if (lstat(full, &st) == 0 && S_ISDIR(st.st_mode))
      ck_rm_rf(full);
    else
      remove(full);
  }
  closedir(d);
  rmdir(path);
}

/* A fresh, empty scratch directory named after the test. */
static inline void ck_scratch(const char *dir) {
  ck_rm_rf(dir);
  mkdir(dir, 0777);
}

/* Number of entries of `dir` named "<base>.tmp-..." (temporaries of base). */
static inline int ck_count_temps(const char *dir, const char *base) {
  DIR *d = opendir(dir);
  struct dirent *e;
  size_t n = strlen(base);
  int count = 0;
  if (!d) return -1;
  while ((e = readdir(d)) != NULL)
    if (strncmp(e->d_name, base, n) == 0 && strncmp(e->d_name + n, ".tmp-", 5) == 0) ++count;
  closedir(d);
  return count;
}

static inline int ck_contains(const char *haystack, const char *needle) {
  return haystack && strstr(haystack, needle) != NULL;
}

/* xorshift64*: deterministic test data and sample positions. */
static inline uint64_t ck_rand(uint64_t *state) {
  uint64_t x = *state;
  x ^= x >> 12;
  x ^= x << 25;
  x ^= x >> 27;
  *state = x;
  return x * UINT64_C(2685821657736338717);
}

#endif
