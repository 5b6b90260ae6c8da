/* Work-group primitives for OpenCL C programs (OpenCL-only; included by
 * .cl files, inlined by the embedder). Every work-item of the group must
 * call them (they contain barriers). */
#ifndef PX_OPENCL_WORKGROUP_H
#define PX_OPENCL_WORKGROUP_H

/* In-place exclusive prefix sum of data[0..m) in local memory, m a power of
 * two, by the w work-items of the group (lid = get_local_id(0)); returns the
 * total to every work-item. Work-efficient up-sweep/down-sweep scan:
 * Blelloch, "Prefix sums and their applications" (CMU-CS-90-190, 1990),
 * O(m) additions in 2 log2(m) barrier phases. */
static inline uint px_wg_exclusive_scan(__local uint *data, const uint m, const uint lid,
                                        const uint w) {
  uint offset = 1, d, k, total;
  for (d = m >> 1; d > 0; d >>= 1) {
    barrier(CLK_LOCAL_MEM_FENCE);
    for (k = lid; k < d; k += w) {
      const uint ai = offset * (2 * k + 1) - 1, bi = offset * (2 * k + 2) - 1;
      data[bi] += data[ai];
    }
    offset <<= 1;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  total = data[m - 1];
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid == 0) data[m - 1] = 0;
  for (d = 1; d < m; d <<= 1) {
    offset >>= 1;
    barrier(CLK_LOCAL_MEM_FENCE);
    for (k = lid; k < d; k += w) {
      const uint ai = offset * (2 * k + 1) - 1, bi = offset * (2 * k + 2) - 1;
      const uint t = data[ai];
      data[ai] = data[bi];
      data[bi] += t;
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  return total;
}

#endif
