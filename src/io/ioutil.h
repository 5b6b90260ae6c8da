/* Small helpers shared by the output writers (not part of the public API). */
#ifndef PX_IO_IOUTIL_H
#define PX_IO_IOUTIL_H

#include <stddef.h>
#include <stdio.h>

#include "partix/context.h"

/* Copy of s in px_mem memory under `label` (NULL and a NOMEM failure in ctx
 * when out of memory). */
char *px_ioutil_strdup(struct px_context *ctx, const char *label, const char *s);

/* Write s to f with the five XML special characters escaped (attribute-safe). */
void px_ioutil_xml_escape(FILE *f, const char *s);

/* Read a whole file into a NUL-terminated px_mem buffer (*out owned by the
 * caller, free with px_mem_free). A missing file is PX_STATUS_NOT_FOUND. */
enum px_status px_ioutil_read_file(struct px_context *ctx, const char *path, char **out,
                                   size_t *len);

/* 1 if `path` ends with `ext` (e.g. ".vtp"). */
int px_ioutil_has_ext(const char *path, const char *ext);

#endif
