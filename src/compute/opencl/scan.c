/* Exclusive prefix sum of uint32 arrays on OpenCL devices (scan.cl). */
#include "compute/opencl/opencl_impl.h"

struct px_scan_plan {
  struct px_backend *be;
  cl_kernel blocks, add;
  size_t w; /* work-group size; a block is 2w elements */
  cl_mem scratch;
};

/* Scan n values in[in_off..] into out[out_off..]; block totals go to
 * scratch[soff..]. Returns (in *total_off) where the grand total was
 * written in scratch. */
static enum px_status px_scan_level(struct px_scan_plan *p, cl_mem in, cl_uint in_off, cl_mem out,
                                    cl_uint out_off, size_t n, cl_uint soff, cl_uint *total_off) {
  struct px_backend *be = p->be;
  const size_t block = 2 * p->w;
  const size_t nb = (n + block - 1) / block;
  const cl_uint n32 = (cl_uint)n, block32 = (cl_uint)block;
  struct px_opencl_args a;
  px_opencl_args_begin(&a, be, p->blocks);
  px_opencl_args_u32(&a, "n", n32);
  px_opencl_args_clmem(&a, "in", in);
  px_opencl_args_u32(&a, "in_off", in_off);
  px_opencl_args_clmem(&a, "out", out);
  px_opencl_args_u32(&a, "out_off", out_off);
  px_opencl_args_clmem(&a, "sums", p->scratch);
  px_opencl_args_u32(&a, "sums_off", soff);
  px_opencl_args_i32(&a, "write_sums", 1);
  px_opencl_args_local(&a, "tmp", block * sizeof(cl_uint));
  PX_TRY(px_opencl_args_launch(&a, nb * p->w, p->w));
  if (nb == 1) {
    *total_off = soff;
    return PX_STATUS_OK;
  }
  /* Scan the block totals in place; their own totals go after them. */
  PX_TRY(px_scan_level(p, p->scratch, soff, p->scratch, soff, nb, soff + (cl_uint)nb, total_off));
  px_opencl_args_begin(&a, be, p->add);
  px_opencl_args_u32(&a, "n", n32);
  px_opencl_args_clmem(&a, "out", out);
  px_opencl_args_u32(&a, "out_off", out_off);
  px_opencl_args_clmem(&a, "sums", p->scratch);
  px_opencl_args_u32(&a, "sums_off", soff);
  px_opencl_args_u32(&a, "block", block32);
  return px_opencl_args_launch(&a, n, 0);
}

enum px_status px_opencl_scan_u32(struct px_backend *be, struct px_buffer *in,
                                  struct px_buffer *out, size_t n, uint32_t *total) {
  struct px_scan_plan p;
  cl_program prog;
  size_t words = 0, m, local_cap;
  cl_uint total_off = 0;
  if (n == 0) {
    if (total) *total = 0;
    return PX_STATUS_OK;
  }
  if (n > 0x7fffffffu)
    return px_context_fail(be->ctx, PX_STATUS_INVALID,
                           "prefix sum of %zu values exceeds the 32-bit index range", n);
  p.be = be;
  PX_TRY(px_opencl_program(be, "scan", px_cl_source_scan, "", &prog));
  PX_TRY(px_opencl_kernel(be, prog, "px_scan_blocks", &p.blocks));
  PX_TRY(px_opencl_kernel(be, prog, "px_scan_add", &p.add));
  local_cap = px_opencl_local_mem(be) / (2 * sizeof(cl_uint));
  PX_TRY(px_opencl_local_pow2(be, p.blocks, local_cap < 256 ? local_cap : 256, &p.w));
  for (m = n;;) {
    m = (m + 2 * p.w - 1) / (2 * p.w);
    words += m;
    if (m == 1) break;
  }
  PX_TRY(px_opencl_scratch(be, 0, words * sizeof(cl_uint), &p.scratch));
  PX_TRY(px_scan_level(&p, px_opencl_mem(in), 0, px_opencl_mem(out), 0, n, 0, &total_off));
  if (total) {
    cl_int err =
        clEnqueueReadBuffer(px_opencl_queue(be), p.scratch, CL_TRUE, total_off * sizeof(cl_uint),
                            sizeof *total, total, 0, NULL, NULL);
    PX_TRY(px_opencl_check(be, err, "reading the total of a prefix sum"));
  }
  return PX_STATUS_OK;
}
