/* Neighbour search for the vortex wake: a bounding-volume tree over points
 * sorted along a Morton (Z-order) curve.
 *
 * Why not a uniform cell list: the VVD domain radius eps*_i (distance to the
 * nearest neighbours) spans four orders of magnitude across a wake (1e-3 of a
 * chord in the boundary layer, 1e1 far downstream), so does the query radius
 * 8 eps*; a uniform grid either has ~1e9 cells or thousands of vortices per
 * cell near the body. The tree answers fixed-radius and k-nearest queries for
 * any radius in O(log N + k), is built in O(N) (radix sort on 44-bit keys)
 * and is deterministic: the order depends only on the positions.
 *
 * Nodes form a binary tree over the sorted array: node 0 covers [0, n); a
 * node covering more than `leaf` points splits where the first bit in which
 * its keys differ turns to 1 (a binary radix tree, as in Karras 2012): each
 * node is a quadtree cell or its half, so node boxes are compact. (Splitting
 * at the middle index, as before 2026-11-28, made nodes runs of the curve
 * that cross cell borders: L-shaped point sets whose boxes took in 3.5 times
 * the neighbours a VVD query accepts; the radix split made the vortex step
 * 10-13% faster with the same results.) Equal keys beyond `leaf` split at
 * the middle index. */
#ifndef PX_VORTEX_TREE_H
#define PX_VORTEX_TREE_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"

struct px_vortex_tree {
  size_t n;        /* points */
  size_t cap;      /* allocated points */
  size_t leaf;     /* max points per leaf */
  uint32_t *order; /* owned: sorted position -> original index */
  double *sx, *sy; /* owned: coordinates in sorted order */
  size_t nnode, node_cap;
  uint32_t *lo, *hi;             /* owned: point range of each node */
  int32_t *left;                 /* owned: first child (second = left + 1), -1 for a leaf */
  double *bx0, *by0, *bx1, *by1; /* owned: node bounding boxes */
  uint64_t *key, *key2;          /* owned: work for the sort */
  uint32_t *ord2;                /* owned: work */
  uint32_t *leaf_of;             /* owned: leaf node of each sorted point */
};

/* Squared distance from (x, y) to the box of node k (0 inside). */
static inline double px_vortex_tree_box_dist2(const struct px_vortex_tree *t, size_t k, double x,
                                              double y) {
  double a = t->bx0[k] - x, b = x - t->bx1[k], c = t->by0[k] - y, d = y - t->by1[k];
  double dx = a > b ? a : b, dy = c > d ? c : d;
  dx = dx > 0.0 ? dx : 0.0;
  dy = dy > 0.0 ? dy : 0.0;
  return dx * dx + dy * dy;
}

void px_vortex_tree_init(struct px_vortex_tree *t);
void px_vortex_tree_free(struct px_context *ctx, struct px_vortex_tree *t);
/* Build over n points (x[i], y[i]). sorted: how many leading points are
 * expected to be almost in the tree's order already (0: none); a hint for
 * speed only, the tree is the same whatever it says. */
enum px_status px_vortex_tree_build(struct px_context *ctx, struct px_vortex_tree *t, size_t n,
                                    const double *x, const double *y, size_t sorted, int threads);

/* Sorted positions of the points within distance r of (x, y) (r inclusive),
 * in ascending sorted position, appended to *buf (grown as needed, owned by
 * the caller, freed with px_mem_free); returns the count, or (size_t)-1 when
 * out of memory. */
size_t px_vortex_tree_within(struct px_context *ctx, const struct px_vortex_tree *t, double x,
                             double y, double r, uint32_t **buf, size_t *cap);
/* Leaves (node indices, in ascending point order) whose box comes within r of
 * (x, y); returns their number, filling at most cap entries. */
size_t px_vortex_tree_leaves(const struct px_vortex_tree *t, double x, double y, double r,
                             uint32_t *leaves, size_t cap);
/* The nodes of t that hold at most gmax points and whose parent holds more
 * (or leaves, if larger), in ascending sorted order (depth first, left
 * first), into out (room for t->nnode); returns their count. */
size_t px_vortex_tree_groups(const struct px_vortex_tree *t, size_t gmax, uint32_t *out);
/* A disc covering the n >= 1 discs (x[q], y[q]) of radius r[q]: its centre
 * the middle of the centres' bounding box, into (*cx, *cy); its radius, the
 * largest distance of a centre from it plus that disc's radius, with a
 * margin against rounding in the distance tests, returned (one tree query
 * for a group of queries, each then filtered from its list). */
double px_vortex_cover(const double *x, const double *y, const double *r, size_t n, double *cx,
                       double *cy);
/* Of the n leaves cand (a px_vortex_tree_leaves list), those within r of
 * (x, y) by the same test, in their order, into out (room for n); returns
 * their count: px_vortex_tree_leaves's list for (x, y, r) when cand holds
 * every leaf within r of (x, y). The plain reference of
 * px_vortex_vvd_leaves_within (vortex_core.h), which the engine runs. */
size_t px_vortex_tree_leaves_of(const struct px_vortex_tree *t, const uint32_t *cand, size_t n,
                                double x, double y, double r, uint32_t *out);
/* The k (<= 8) smallest squared distances from (x, y) to tree points other
 * than the point at sorted position `skip` (pass (uint32_t)-1 to skip none),
 * ascending in d2[0..k-1]; missing ones are +inf. */
void px_vortex_tree_knn(const struct px_vortex_tree *t, double x, double y, uint32_t skip, int k,
                        double *d2);
/* The same for the tree point at sorted position sp (itself excluded),
 * starting from its own leaf: faster. work: cap entries of scratch. */
void px_vortex_tree_knn_point(const struct px_vortex_tree *t, uint32_t sp, int k, uint32_t *work,
                              size_t cap, double *d2);

#endif
