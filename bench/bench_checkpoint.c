/* Checkpoint throughput: CRC32, writing (with fsync and rename), opening
 * (whole-file validation) and reading, for one checkpoint of SIZE MB.
 * usage: bench_checkpoint [SIZE_MB=128] [DIR=.]
 * Prints one JSON object per line: bytes is counted (the bytes the step
 * handles, four f64 sections), the code is serial (threads 1), and the load
 * average is read before and after each operation (bench_util.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/crc32.h"
#include "bench_util.h"
#include "partix/partix.h"

static double g_load0 = -1; /* load average when the operation started */

static void report(const char *what, double bytes, double seconds) {
  printf(
      "{\"bench\":\"checkpoint\",\"op\":\"%s\",\"bytes\":%.0f,\"seconds\":%.6f,"
      "\"MB_per_s\":%.1f",
      what, bytes, seconds, bytes / 1e6 / seconds);
  px_bench_json_env(stdout, 1, 1, g_load0, px_bench_load1());
  printf("}\n");
  g_load0 = px_bench_load1();
}

int main(int argc, char **argv) {
  size_t mb = argc > 1 ? (size_t)strtoul(argv[1], NULL, 10) : 128;
  const char *dir = argc > 2 ? argv[2] : ".";
  size_t n = mb * ((size_t)1 << 20) / 8 / 4, i; /* four f64 sections */
  char path[4096];
  struct px_context *ctx = NULL;
  struct px_checkpoint_writer *w = NULL;
  struct px_checkpoint *ck = NULL;
  double *v = malloc(n * sizeof *v), t0, bytes = 4.0 * (double)n * 8.0;
  enum px_status s;
  uint32_t crc;
  if (!v || px_context_create(&ctx) != PX_STATUS_OK) return 1;
  g_load0 = px_bench_load1();
  if (px_file_join(ctx, path, sizeof path, dir, "bench_checkpoint.chk") != PX_STATUS_OK) return 1;
  for (i = 0; i < n; ++i) v[i] = (double)i * 1e-3;

  t0 = px_time_now();
  crc = px_crc32_update(0, v, n * sizeof *v);
  report("crc32", (double)(n * sizeof *v), px_time_now() - t0);

  t0 = px_time_now();
  s = px_checkpoint_writer_open(ctx, path, "bench", crc, 1, 0.0, &w);
  if (s == PX_STATUS_OK) s = px_checkpoint_write(w, "a", PX_DTYPE_F64, n, v);
  if (s == PX_STATUS_OK) s = px_checkpoint_write(w, "b", PX_DTYPE_F64, n, v);
  if (s == PX_STATUS_OK) s = px_checkpoint_write(w, "c", PX_DTYPE_F64, n, v);
  if (s == PX_STATUS_OK) s = px_checkpoint_write(w, "d", PX_DTYPE_F64, n, v);
  if (s == PX_STATUS_OK)
    s = px_checkpoint_writer_commit(w);
  else
    px_checkpoint_writer_abort(w);
  if (s != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  report("write+fsync", bytes, px_time_now() - t0);

  t0 = px_time_now();
  if (px_checkpoint_open(ctx, path, &ck) != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  report("open+validate", bytes, px_time_now() - t0);

  t0 = px_time_now();
  s = px_checkpoint_read(ck, "a", PX_DTYPE_F64, n, v);
  if (s == PX_STATUS_OK) s = px_checkpoint_read(ck, "b", PX_DTYPE_F64, n, v);
  if (s == PX_STATUS_OK) s = px_checkpoint_read(ck, "c", PX_DTYPE_F64, n, v);
  if (s == PX_STATUS_OK) s = px_checkpoint_read(ck, "d", PX_DTYPE_F64, n, v);
  if (s != PX_STATUS_OK) {
    fprintf(stderr, "%s\n", px_context_message(ctx));
    return 1;
  }
  report("read+verify", bytes, px_time_now() - t0);
  px_checkpoint_close(ck);
  remove(path);
  px_context_free(ctx);
  free(v);
  return 0;
}
