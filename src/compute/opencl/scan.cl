/* Exclusive prefix sums of uint arrays: px_opencl_scan_u32 (scan.c).
 * Level 0 scans blocks of 2w elements per work-group and writes each block's
 * total; the block totals are scanned the same way (recursively, on the
 * host side), then added back to every element of their block. */
#include "workgroup.h"

/* out[i] = sum of in[j] for block_start <= j < i, per block of 2w elements;
 * sums[block] = block total (when write_sums). in and out may be the same. */
__kernel void px_scan_blocks(const uint n, __global const uint *in, const uint in_off,
                             __global uint *out, const uint out_off, __global uint *sums,
                             const uint sums_off, const int write_sums, __local uint *tmp) {
  const uint lid = get_local_id(0), w = get_local_size(0);
  const uint base = get_group_id(0) * 2 * w;
  const uint i0 = base + lid, i1 = base + lid + w;
  uint total;
  tmp[lid] = i0 < n ? in[in_off + i0] : 0u;
  tmp[lid + w] = i1 < n ? in[in_off + i1] : 0u;
  total = px_wg_exclusive_scan(tmp, 2 * w, lid, w);
  if (i0 < n) out[out_off + i0] = tmp[lid];
  if (i1 < n) out[out_off + i1] = tmp[lid + w];
  if (write_sums && lid == 0) sums[sums_off + get_group_id(0)] = total;
}

/* out[i] += sums[i / block] (the scanned totals of the preceding blocks). */
__kernel void px_scan_add(const uint n, __global uint *out, const uint out_off,
                          __global const uint *sums, const uint sums_off, const uint block) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  out[out_off + i] += sums[sums_off + i / block];
}
