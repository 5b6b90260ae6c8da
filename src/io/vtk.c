/* VTK datasets: points, image geometry, topology, data arrays and fields
 * that px_vtk_write (vtk_write.c) writes as a VTK XML file. */
#include "partix/vtk.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/ioutil.h"
#include "io/vtk_impl.h"
#include "partix/memory.h"

/* ------------------------------------------------------------------------ */

const char *px_vtk_type_name(enum px_dtype t) {
  switch (t) {
    case PX_DTYPE_U8: return "UInt8";
    case PX_DTYPE_I32: return "Int32";
    case PX_DTYPE_U32: return "UInt32";
    case PX_DTYPE_I64: return "Int64";
    case PX_DTYPE_U64: return "UInt64";
    case PX_DTYPE_F32: return "Float32";
    case PX_DTYPE_F64: return "Float64";
  }
  return NULL;
}

const char *px_vtk_byte_order(void) {
  const uint16_t one = 1;
  unsigned char first;
  memcpy(&first, &one, 1);
  return first ? "LittleEndian" : "BigEndian";
}

enum px_status px_vtk_create(struct px_context *ctx, struct px_vtk **out) {
  struct px_vtk *v;
  if (!ctx || !out) return PX_STATUS_INVALID;
  *out = NULL;
  v = px_mem_calloc(ctx, "vtk", 1, sizeof *v);
  if (!v) return PX_STATUS_NOMEM;
  v->ctx = ctx;
  *out = v;
  return PX_STATUS_OK;
}

void px_vtk_reset(struct px_vtk *v) {
  size_t i;
  if (!v) return;
  for (i = 0; i < v->narrays; ++i) px_mem_free(v->ctx, v->arrays[i].name);
  for (i = 0; i < v->nfields; ++i) px_mem_free(v->ctx, v->fields[i].name);
  v->narrays = 0;
  v->nfields = 0;
  v->have_points = 0;
  v->have_image = 0;
  v->vertices = 0;
  v->nline_conn = 0;
  v->nlines = 0;
  v->ncells = 0;
  v->cell_offsets = NULL;
  v->cell_conn = NULL;
  v->cell_types = NULL;
  v->cell_uniform_nodes = 0;
  v->have_time = 0;
}

void px_vtk_free(struct px_vtk *v) {
  struct px_context *ctx;
  if (!v) return;
  ctx = v->ctx;
  px_vtk_reset(v);
  px_mem_free(ctx, v->arrays);
  px_mem_free(ctx, v->fields);
  px_mem_free(ctx, v->line_conn);
  px_mem_free(ctx, v->line_end);
  px_mem_free(ctx, v->chunk);
  px_mem_free(ctx, v);
}

/* Grow *buf (elements of `size` bytes) to hold at least `need` elements. */
enum px_status px_vtk_grow(struct px_context *ctx, void **buf, size_t *cap, size_t need,
                           size_t size) {
  size_t ncap;
  void *nb;
  if (need <= *cap) return PX_STATUS_OK;
  ncap = *cap ? *cap : 16;
  while (ncap < need) ncap *= 2;
  nb = px_mem_realloc(ctx, "vtk", *buf, ncap * size);
  if (!nb) return PX_STATUS_NOMEM;
  *buf = nb;
  *cap = ncap;
  return PX_STATUS_OK;
}

/* ---- Geometry ------------------------------------------------------------ */

static int px_vtk_is_real(enum px_dtype t) { return t == PX_DTYPE_F32 || t == PX_DTYPE_F64; }

enum px_status px_vtk_set_points(struct px_vtk *v, enum px_dtype dtype, size_t n, const void *x,
                                 const void *y, const void *z) {
  struct px_vtk_array *p;
  if (!v) return PX_STATUS_INVALID;
  if (!px_vtk_is_real(dtype))
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk points: coordinates must be f32 or f64, not %s",
                           px_dtype_name(dtype));
  if (n > 0 && (!x || !y))
    return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk points: x and y must not be NULL");
  p = &v->points;
  memset(p, 0, sizeof *p);
  p->dtype = dtype;
  p->n = n;
  p->ncomp_in = z ? 3 : 2;
  p->ncomp_out = 3;
  p->src = PX_VTK_SRC_SOA;
  p->comp[0] = x;
  p->comp[1] = y;
  p->comp[2] = z;
  v->have_points = 1;
  return PX_STATUS_OK;
}

enum px_status px_vtk_set_points_aos(struct px_vtk *v, enum px_dtype dtype, size_t n, int ncomp,
                                     const void *xyz) {
  struct px_vtk_array *p;
  if (!v) return PX_STATUS_INVALID;
  if (!px_vtk_is_real(dtype))
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk points: coordinates must be f32 or f64, not %s",
                           px_dtype_name(dtype));
  if (ncomp != 2 && ncomp != 3)
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk points: %d components per point (expected 2 or 3)", ncomp);
  if (n > 0 && !xyz)
    return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk points: data must not be NULL");
  p = &v->points;
  memset(p, 0, sizeof *p);
  p->dtype = dtype;
  p->n = n;
  p->ncomp_in = ncomp;
  p->ncomp_out = 3;
  p->src = PX_VTK_SRC_AOS;
  p->comp[0] = xyz;
  v->have_points = 1;
  return PX_STATUS_OK;
}

enum px_status px_vtk_set_image(struct px_vtk *v, const size_t dims[3], const double origin[3],
                                const double spacing[3]) {
  int k;
  if (!v || !dims || !origin || !spacing) return PX_STATUS_INVALID;
  for (k = 0; k < 3; ++k) {
    if (dims[k] < 1)
      return px_context_fail(v->ctx, PX_STATUS_INVALID,
                             "vtk image: dims[%d] = %zu (at least 1 point per axis)", k, dims[k]);
    if (!isfinite(origin[k]) || !isfinite(spacing[k]) || spacing[k] <= 0.0)
      return px_context_fail(v->ctx, PX_STATUS_INVALID,
                             "vtk image: origin[%d] = %g, spacing[%d] = %g (finite, spacing > 0)",
                             k, origin[k], k, spacing[k]);
    v->dims[k] = dims[k];
    v->origin[k] = origin[k];
    v->spacing[k] = spacing[k];
  }
  v->have_image = 1;
  return PX_STATUS_OK;
}

/* ---- Topology ------------------------------------------------------------ */

enum px_status px_vtk_add_vertices(struct px_vtk *v) {
  if (!v) return PX_STATUS_INVALID;
  v->vertices = 1;
  return PX_STATUS_OK;
}

static enum px_status px_vtk_push_line(struct px_vtk *v, size_t count, const int64_t *ids,
                                       size_t first, int closed) {
  size_t total = count + (closed ? 1 : 0), i;
  if (count < 2)
    return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk polyline with %zu points (at least 2)",
                           count);
  PX_TRY(px_vtk_grow(v->ctx, (void **)&v->line_conn, &v->line_conn_cap, v->nline_conn + total,
                     sizeof *v->line_conn));
  PX_TRY(px_vtk_grow(v->ctx, (void **)&v->line_end, &v->line_end_cap, v->nlines + 1,
                     sizeof *v->line_end));
  for (i = 0; i < count; ++i) v->line_conn[v->nline_conn + i] = ids ? ids[i] : (int64_t)(first + i);
  if (closed) v->line_conn[v->nline_conn + count] = v->line_conn[v->nline_conn];
  v->nline_conn += total;
  v->line_end[v->nlines++] = (int64_t)v->nline_conn;
  return PX_STATUS_OK;
}

enum px_status px_vtk_add_polyline(struct px_vtk *v, size_t count, const int64_t *ids, int closed) {
  if (!v || (count && !ids)) return PX_STATUS_INVALID;
  return px_vtk_push_line(v, count, ids, 0, closed);
}

enum px_status px_vtk_add_polyline_range(struct px_vtk *v, size_t first, size_t count, int closed) {
  if (!v) return PX_STATUS_INVALID;
  return px_vtk_push_line(v, count, NULL, first, closed);
}

enum px_status px_vtk_add_segments(struct px_vtk *v, size_t first, size_t count, int closed) {
  size_t nseg, i;
  if (!v) return PX_STATUS_INVALID;
  if (count < 2)
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk segments through %zu points (at least 2)", count);
  nseg = closed ? count : count - 1;
  PX_TRY(px_vtk_grow(v->ctx, (void **)&v->line_conn, &v->line_conn_cap, v->nline_conn + 2 * nseg,
                     sizeof *v->line_conn));
  PX_TRY(px_vtk_grow(v->ctx, (void **)&v->line_end, &v->line_end_cap, v->nlines + nseg,
                     sizeof *v->line_end));
  for (i = 0; i < nseg; ++i) {
    v->line_conn[v->nline_conn++] = (int64_t)(first + i);
    v->line_conn[v->nline_conn++] = (int64_t)(first + (i + 1) % count);
    v->line_end[v->nlines++] = (int64_t)v->nline_conn;
  }
  return PX_STATUS_OK;
}

enum px_status px_vtk_set_cells(struct px_vtk *v, size_t ncells, const int64_t *offsets,
                                const int64_t *connectivity, const uint8_t *types) {
  if (!v) return PX_STATUS_INVALID;
  if (ncells && (!offsets || !connectivity || !types))
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk cells: offsets, connectivity and types must not be NULL");
  v->ncells = ncells;
  v->cell_offsets = offsets;
  v->cell_conn = connectivity;
  v->cell_types = types;
  v->cell_uniform_nodes = 0;
  return PX_STATUS_OK;
}

enum px_status px_vtk_set_cells_uniform(struct px_vtk *v, size_t ncells, enum px_vtk_cell type,
                                        int nodes, const int64_t *connectivity) {
  if (!v) return PX_STATUS_INVALID;
  if (nodes < 1 || (ncells && !connectivity) || (int)type < 1 || (int)type > 255)
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk uniform cells: type %d with %d nodes (need a VTK cell type, "
                           "nodes >= 1 and connectivity)",
                           (int)type, nodes);
  v->ncells = ncells;
  v->cell_offsets = NULL;
  v->cell_conn = connectivity;
  v->cell_types = NULL;
  v->cell_uniform_nodes = nodes;
  v->cell_uniform_type = type;
  return PX_STATUS_OK;
}

/* ---- Data arrays --------------------------------------------------------- */

static enum px_status px_vtk_new_array(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                       enum px_dtype dtype, size_t n, int ncomp,
                                       struct px_vtk_array **out) {
  struct px_vtk_array *a = NULL;
  size_t i;
  if (!name || !name[0])
    return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk array without a name");
  if (assoc != PX_VTK_ASSOC_POINT && assoc != PX_VTK_ASSOC_CELL)
    return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk array '%s': unknown association %d",
                           name, (int)assoc);
  if (!px_vtk_type_name(dtype))
    return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk array '%s': unknown dtype %d", name,
                           (int)dtype);
  if (ncomp < 1 || ncomp > PX_VTK_MAX_COMP)
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk array '%s': %d components (expected 1 to %d)", name, ncomp,
                           PX_VTK_MAX_COMP);
  for (i = 0; i < v->narrays; ++i)
    if (v->arrays[i].assoc == assoc && strcmp(v->arrays[i].name, name) == 0)
      return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk array '%s' added twice to %s data",
                             name, assoc == PX_VTK_ASSOC_POINT ? "point" : "cell");
  PX_TRY(
      px_vtk_grow(v->ctx, (void **)&v->arrays, &v->arrays_cap, v->narrays + 1, sizeof *v->arrays));
  a = &v->arrays[v->narrays];
  memset(a, 0, sizeof *a);
  a->name = px_ioutil_strdup(v->ctx, "vtk", name);
  if (!a->name) return PX_STATUS_NOMEM;
  a->assoc = assoc;
  a->dtype = dtype;
  a->n = n;
  a->ncomp_in = ncomp;
  a->ncomp_out = ncomp == 2 ? 3 : ncomp;
  ++v->narrays;
  *out = a;
  return PX_STATUS_OK;
}

enum px_status px_vtk_add_array(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                enum px_dtype dtype, size_t n, int ncomp,
                                const void *const comps[]) {
  struct px_vtk_array *a = NULL;
  int k;
  if (!v) return PX_STATUS_INVALID;
  if (!comps) return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk array: comps is NULL");
  PX_TRY(px_vtk_new_array(v, assoc, name, dtype, n, ncomp, &a));
  a->src = PX_VTK_SRC_SOA;
  for (k = 0; k < ncomp; ++k) {
    if (n > 0 && !comps[k]) {
      px_mem_free(v->ctx, a->name);
      --v->narrays;
      return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk array '%s': component %d is NULL",
                             name, k);
    }
    a->comp[k] = comps[k];
  }
  return PX_STATUS_OK;
}

enum px_status px_vtk_add_array_aos(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                    enum px_dtype dtype, size_t n, int ncomp, const void *data) {
  struct px_vtk_array *a = NULL;
  if (!v) return PX_STATUS_INVALID;
  if (n > 0 && !data)
    return px_context_fail(v->ctx, PX_STATUS_INVALID, "vtk array '%s': data is NULL",
                           name ? name : "?");
  PX_TRY(px_vtk_new_array(v, assoc, name, dtype, n, ncomp, &a));
  a->src = PX_VTK_SRC_AOS;
  a->comp[0] = data;
  return PX_STATUS_OK;
}

enum px_status px_vtk_add_scalar(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                 enum px_dtype dtype, size_t n, const void *data) {
  const void *comps[1];
  comps[0] = data;
  return px_vtk_add_array(v, assoc, name, dtype, n, 1, comps);
}

enum px_status px_vtk_add_vector(struct px_vtk *v, enum px_vtk_assoc assoc, const char *name,
                                 enum px_dtype dtype, size_t n, const void *x, const void *y,
                                 const void *z) {
  struct px_vtk_array *a = NULL;
  if (!v) return PX_STATUS_INVALID;
  if (n > 0 && (!x || !y))
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "vtk vector '%s': x and y components must not be NULL",
                           name ? name : "?");
  PX_TRY(px_vtk_new_array(v, assoc, name, dtype, n, 3, &a));
  a->src = PX_VTK_SRC_SOA;
  a->comp[0] = x;
  a->comp[1] = y;
  a->comp[2] = z; /* NULL: zeros */
  return PX_STATUS_OK;
}

void px_vtk_set_time(struct px_vtk *v, double time, int64_t step) {
  if (!v) return;
  v->have_time = 1;
  v->time = time;
  v->step = step;
}

enum px_status px_vtk_add_field(struct px_vtk *v, const char *name, double value) {
  struct px_vtk_field *fd;
  if (!v || !name || !name[0]) return PX_STATUS_INVALID;
  PX_TRY(
      px_vtk_grow(v->ctx, (void **)&v->fields, &v->fields_cap, v->nfields + 1, sizeof *v->fields));
  fd = &v->fields[v->nfields];
  fd->name = px_ioutil_strdup(v->ctx, "vtk", name);
  if (!fd->name) return PX_STATUS_NOMEM;
  fd->value = value;
  ++v->nfields;
  return PX_STATUS_OK;
}
