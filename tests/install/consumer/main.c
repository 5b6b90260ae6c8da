/* A program outside the partix tree using the installed library. */
#include <partix/partix.h>
#include <stdio.h>

int main(void) {
  struct px_context *ctx = NULL;
  struct px_backend *be = NULL;
  struct px_buffer *buf = NULL;
  double in[4] = {1, 2, 3, 4}, out[4] = {0, 0, 0, 0};
  if (px_context_create(&ctx) != PX_STATUS_OK) return 1;
  if (px_backend_create(ctx, "cpu", 0, 1, &be) != PX_STATUS_OK ||
      px_buffer_create(be, "consumer", sizeof in, &buf) != PX_STATUS_OK ||
      px_buffer_write(buf, 0, sizeof in, in) != PX_STATUS_OK ||
      px_buffer_read(buf, 0, sizeof out, out) != PX_STATUS_OK || out[3] != 4.0) {
    fprintf(stderr, "consumer: %s\n", px_context_message(ctx));
    return 1;
  }
  printf("consumer: partix %s ok\n", px_version());
  px_buffer_free(buf);
  px_backend_free(be);
  px_context_free(ctx);
  return 0;
}
