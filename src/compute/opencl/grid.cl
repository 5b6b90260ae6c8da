/* Neighbour grid on OpenCL devices (neighbors/grid_opencl.c drives it).
 * Built with -DPX_REAL=float|double (the coordinate precision); the integer
 * kernels are the same in both builds.
 *
 * Deterministic build: cell per particle; cell counts by atomic increments
 * (a count does not depend on the order of increments) and an exclusive scan
 * give start/end. The permutation then comes from one of two paths, chosen
 * by whether any cell holds more than PX_GRID_SMALL_CELL particles (a flag
 * set by the counting kernel, read by the host):
 *   - small cells (the usual grid, cell ~ particle size): every particle
 *     got a slot in its cell from its atomic increment; scatter by slot (an
 *     order that depends on the schedule), then sort each cell's slice by
 *     particle index (insertion sort, one work-item per cell): O(n) with a
 *     small constant, ~5 kernels;
 *   - crowded cells: a stable LSD radix sort of the cell indices, 4 bits
 *     per pass, which costs the same for any distribution: each work-group
 *     sorts a tile of w keys locally
 * (four stable 1-bit splits with a work-group scan) and records per-digit
 * counts; a global scan of the [digit][tile] counts gives every tile's
 * output offsets, and a scatter writes each key to its offset plus its rank
 * within the tile (Satish, Harris & Garland, "Designing efficient sorting
 * algorithms for manycore GPUs", IPDPS 2009). Every step is stable, so the
 * result is exactly the stable counting sort, whatever the schedule.
 * Both paths give exactly that result. */
#include "kernels/grid.h"
#include "workgroup.h"

__kernel void px_grid_cells_2d(const uint n, __global const px_real *x, __global const px_real *y,
                               const px_real ox, const px_real oy, const px_real inv_h,
                               const int nx, const int ny, __global uint *cell) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  cell[i] = (uint)px_grid_cell_2d(x[i], y[i], ox, oy, inv_h, nx, ny);
}

__kernel void px_grid_cells_3d(const uint n, __global const px_real *x, __global const px_real *y,
                               __global const px_real *z, const px_real ox, const px_real oy,
                               const px_real oz, const px_real inv_h, const int nx, const int ny,
                               const int nz, __global uint *cell) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  cell[i] = (uint)px_grid_cell_3d(x[i], y[i], z[i], ox, oy, oz, inv_h, nx, ny, nz);
}

/* Most particles per cell for the scatter + per-cell sort path. */
#define PX_GRID_SMALL_CELL 32u

/* counts[cell[i]] += 1 (counts zeroed before); slot[i] = the count before
 * the increment (a place in the cell, in arrival order); *crowded = 1 when a
 * cell gets more than PX_GRID_SMALL_CELL particles (exactly one increment
 * per such cell sees that count, so the flag costs few atomics).
 * Work-item k counts particle n-1-k: devices that run work-items in order
 * (CPU OpenCL) then deliver every cell reversed, so the per-cell sort is
 * always exercised by the tests instead of finding sorted slices. */
__kernel void px_grid_count_cells(const uint n, __global const uint *cell, __global uint *counts,
                                  __global uint *slot, __global uint *crowded) {
  const uint k = get_global_id(0);
  uint i, s;
  if (k >= n) return;
  i = n - 1 - k;
  s = atomic_inc(&counts[cell[i]]);
  slot[i] = s;
  if (s == PX_GRID_SMALL_CELL) atomic_or(crowded, 1u);
}

/* perm[start[cell[i]] + slot[i]] = i: cell order, arbitrary within a cell. */
__kernel void px_grid_scatter(const uint n, __global const uint *cell, __global const uint *slot,
                              __global const uint *start, __global uint *perm) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  perm[start[cell[i]] + slot[i]] = i;
}

/* Sort the slice of cell c by particle index (insertion sort: the slice has
 * at most PX_GRID_SMALL_CELL entries on this path). */
__kernel void px_grid_sort_cells(const uint ncells, __global const uint *start,
                                 __global const uint *end, __global uint *perm) {
  const uint c = get_global_id(0);
  uint a, b, k;
  if (c >= ncells) return;
  a = start[c];
  b = end[c];
  for (k = a + 1; k < b; ++k) {
    const uint v = perm[k];
    uint j = k;
    while (j > a && perm[j - 1] > v) {
      perm[j] = perm[j - 1];
      --j;
    }
    perm[j] = v;
  }
}

/* end[c] = start[c + 1], end[last] = n (start = exclusive scan of counts). */
__kernel void px_grid_cell_ends(const uint ncells, const uint n, __global const uint *start,
                                __global uint *end) {
  const uint c = get_global_id(0);
  if (c >= ncells) return;
  end[c] = c + 1 < ncells ? start[c + 1] : n;
}

__kernel void px_grid_iota(const uint n, __global uint *perm) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  perm[i] = i;
}

/* One radix pass, step 1: sort the tile of this work-group (w keys, w a
 * power of two >= 16) stably by digit (key >> shift) & 15 in local memory.
 * Writes the tile in digit order to kt/vt, hist[d * ntiles + tile] = number
 * of keys with digit d, tile_start[tile * 16 + d] = where digit d begins in
 * the sorted tile. The first pass takes the values as the particle index.
 * Positions past n carry key 0xffffffff: digit 15, sorted after every real
 * key of the tile (they start last and the splits are stable), never
 * counted nor written. */
__kernel void px_radix_tile(const uint n, const uint shift, const int first,
                            __global const uint *kin, __global const uint *vin, __global uint *kt,
                            __global uint *vt, __global uint *hist, __global uint *tile_start,
                            const uint ntiles, __local uint *lk, __local uint *lv,
                            __local uint *ls) {
  const uint lid = get_local_id(0), w = get_local_size(0), tile = get_group_id(0);
  const uint gid = tile * w + lid;
  const uint m = min(w, n - tile * w);
  __local uint *dstart = ls + w, *dend = ls + w + 16;
  uint key = gid < n ? kin[gid] : 0xffffffffu;
  uint val = gid < n ? (first ? gid : vin[gid]) : 0u;
  uint bit, d;
  for (bit = 0; bit < 4; ++bit) {
    const uint b = (key >> (shift + bit)) & 1u;
    uint zeros, rank;
    ls[lid] = 1u - b;
    zeros = px_wg_exclusive_scan(ls, w, lid, w);
    /* ls[lid] = zeros before lid; ones before lid = lid - ls[lid] */
    rank = b ? zeros + lid - ls[lid] : ls[lid];
    lk[rank] = key;
    lv[rank] = val;
    barrier(CLK_LOCAL_MEM_FENCE);
    key = lk[lid];
    val = lv[lid];
  }
  d = (key >> shift) & 15u;
  if (lid < 16) {
    dstart[lid] = 0;
    dend[lid] = 0;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid < m) {
    if (lid == 0 || ((lk[lid - 1] >> shift) & 15u) != d) dstart[d] = lid;
    if (lid == m - 1 || ((lk[lid + 1] >> shift) & 15u) != d) dend[d] = lid + 1;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  if (lid < 16) {
    hist[lid * ntiles + tile] = dend[lid] - dstart[lid];
    tile_start[tile * 16 + lid] = dstart[lid];
  }
  if (lid < m) {
    kt[gid] = key;
    vt[gid] = val;
  }
}

/* One radix pass, step 2: offsets = exclusive scan of hist (digit-major), so
 * the key at position p of tile t with digit d goes to
 * offsets[d * ntiles + t] + p - tile_start[t * 16 + d]. */
__kernel void px_radix_scatter(const uint n, const uint shift, const uint tile_w, const uint ntiles,
                               __global const uint *kt, __global const uint *vt,
                               __global const uint *offsets, __global const uint *tile_start,
                               __global uint *kout, __global uint *vout, const int write_keys) {
  const uint i = get_global_id(0);
  uint tile, key, d, dst;
  if (i >= n) return;
  tile = i / tile_w;
  key = kt[i];
  d = (key >> shift) & 15u;
  dst = offsets[d * ntiles + tile] + (i - tile * tile_w) - tile_start[tile * 16 + d];
  vout[dst] = vt[i];
  if (write_keys) kout[dst] = key;
}

/* dst[k] = src[perm[k]] for elements of 1, 2, 4 and 8 bytes. */
__kernel void px_gather_u8(const uint n, __global const uint *perm, __global const uchar *src,
                           __global uchar *dst) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  dst[k] = src[perm[k]];
}

__kernel void px_gather_u16(const uint n, __global const uint *perm, __global const ushort *src,
                            __global ushort *dst) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  dst[k] = src[perm[k]];
}

__kernel void px_gather_u32(const uint n, __global const uint *perm, __global const uint *src,
                            __global uint *dst) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  dst[k] = src[perm[k]];
}

__kernel void px_gather_u64(const uint n, __global const uint *perm, __global const ulong *src,
                            __global ulong *dst) {
  const uint k = get_global_id(0);
  if (k >= n) return;
  dst[k] = src[perm[k]];
}

__kernel void px_grid_neighbours_2d(const uint n, const px_real range2, __global const px_real *x,
                                    __global const px_real *y, __global const uint *cell,
                                    __global const uint *perm, __global const uint *start,
                                    __global const uint *end, const int nx, const int ny,
                                    __global uint *out) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  out[i] = px_grid_count_2d(i, range2, x, y, cell, perm, start, end, nx, ny);
}

__kernel void px_grid_neighbours_3d(const uint n, const px_real range2, __global const px_real *x,
                                    __global const px_real *y, __global const px_real *z,
                                    __global const uint *cell, __global const uint *perm,
                                    __global const uint *start, __global const uint *end,
                                    const int nx, const int ny, const int nz, __global uint *out) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  out[i] = px_grid_count_3d(i, range2, x, y, z, cell, perm, start, end, nx, ny, nz);
}
