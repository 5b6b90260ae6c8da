/* VTK XML writer (binary appended, raw encoding, UInt64 block headers).
 *
 * Layout written (VTK file format documentation, "XML File Formats"):
 *   <VTKFile type=.. version="1.0" byte_order=.. header_type="UInt64">
 *     <PolyData|ImageData ..|UnstructuredGrid> <FieldData/> <Piece ..>
 *       <PointData/> <CellData/> <Points/> <Verts/> <Lines/> | <Cells/>
 *     </Piece> </..>
 *     <AppendedData encoding="raw">_ [UInt64 nbytes][nbytes of data] ...
 *   </VTKFile>
 * Each DataArray's offset attribute is the byte position of its block after
 * the '_'. Blocks are written in the order the DataArray elements appear. */
#include "partix/vtk.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/ioutil.h"
#include "partix/file.h"
#include "partix/memory.h"

#define PX_VTK_MAX_COMP 9
/* Scratch size for interleaving structure-of-arrays input. */
#define PX_VTK_CHUNK_BYTES ((size_t)1 << 18)

enum px_vtk_src {
  PX_VTK_SRC_SOA,  /* comp[k]: component k (NULL: zeros) */
  PX_VTK_SRC_AOS,  /* comp[0]: ncomp_in values per tuple */
  PX_VTK_SRC_IOTA, /* Int64 value i = start + i*step */
  PX_VTK_SRC_CONST /* UInt8 value `start` */
};

struct px_vtk_array {
  char *name; /* owned */
  enum px_vtk_assoc assoc;
  enum px_dtype dtype;
  size_t n;      /* tuples */
  int ncomp_in;  /* components given */
  int ncomp_out; /* components written (2 given -> 3 written) */
  enum px_vtk_src src;
  const void *comp[PX_VTK_MAX_COMP]; /* borrowed */
  int64_t start, step;
};

struct px_vtk_field {
  char *name; /* owned */
  double value;
};

struct px_vtk {
  struct px_context *ctx; /* borrowed */

  int have_points;
  struct px_vtk_array points; /* name unused */

  int have_image;
  size_t dims[3];
  double origin[3], spacing[3];

  int vertices;
  /* Lines (owned): line i is line_conn[line_end[i-1] .. line_end[i]-1]. */
  int64_t *line_conn;
  size_t nline_conn, line_conn_cap;
  int64_t *line_end;
  size_t nlines, line_end_cap;

  /* Explicit cells (borrowed) or uniform cells. */
  size_t ncells;
  const int64_t *cell_offsets;
  const int64_t *cell_conn;
  const uint8_t *cell_types;
  int cell_uniform_nodes; /* > 0: uniform cells of cell_uniform_type */
  enum px_vtk_cell cell_uniform_type;

  struct px_vtk_array *arrays; /* owned */
  size_t narrays, arrays_cap;

  int have_time;
  double time;
  int64_t step;
  struct px_vtk_field *fields; /* owned */
  size_t nfields, fields_cap;

  unsigned char *chunk; /* owned scratch, PX_VTK_CHUNK_BYTES */
};

enum px_vtk_kind { PX_VTK_KIND_POLY, PX_VTK_KIND_IMAGE, PX_VTK_KIND_UNSTRUCTURED };

/* ------------------------------------------------------------------------ */

static const char *px_vtk_type_name(enum px_dtype t) {
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

static const char *px_vtk_byte_order(void) {
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
static enum px_status px_vtk_grow(struct px_context *ctx, void **buf, size_t *cap, size_t need,
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

/* ---- Writing ------------------------------------------------------------- */

/* The state of one write: the stream, the blocks in file order and the
 * running offset of the next block. */
struct px_vtk_out {
  struct px_vtk *v;
  const char *path;
  FILE *f;
  const struct px_vtk_array **blocks; /* owned list of borrowed arrays */
  size_t nblocks, blocks_cap;
  uint64_t offset;
  /* Internal arrays (topology generated or taken from the builder). */
  struct px_vtk_array gen[8];
  int ngen;
};

static uint64_t px_vtk_block_bytes(const struct px_vtk_array *a) {
  return (uint64_t)a->n * (uint64_t)a->ncomp_out * (uint64_t)px_dtype_size(a->dtype);
}

static struct px_vtk_array *px_vtk_gen(struct px_vtk_out *o, const char *name, enum px_dtype dtype,
                                       size_t n, enum px_vtk_src src, const void *data,
                                       int64_t start, int64_t step) {
  struct px_vtk_array *a = &o->gen[o->ngen++];
  memset(a, 0, sizeof *a);
  a->name = (char *)name; /* static string; never freed (gen arrays are not owned) */
  a->dtype = dtype;
  a->n = n;
  a->ncomp_in = a->ncomp_out = 1;
  a->src = src;
  a->comp[0] = data;
  a->start = start;
  a->step = step;
  return a;
}

/* Emit one <DataArray .../> element and queue its block. */
static enum px_status px_vtk_emit(struct px_vtk_out *o, const struct px_vtk_array *a,
                                  const char *indent) {
  FILE *f = o->f;
  PX_TRY(px_vtk_grow(o->v->ctx, (void **)&o->blocks, &o->blocks_cap, o->nblocks + 1,
                     sizeof *o->blocks));
  o->blocks[o->nblocks++] = a;
  fprintf(f, "%s<DataArray type=\"%s\" Name=\"", indent, px_vtk_type_name(a->dtype));
  px_ioutil_xml_escape(f, a->name);
  fputc('"', f);
  if (a->ncomp_out > 1) fprintf(f, " NumberOfComponents=\"%d\"", a->ncomp_out);
  fprintf(f, " format=\"appended\" offset=\"%" PRIu64 "\"/>\n", o->offset);
  o->offset += 8 + px_vtk_block_bytes(a);
  return PX_STATUS_OK;
}

static enum px_status px_vtk_emit_data(struct px_vtk_out *o, enum px_vtk_assoc assoc) {
  struct px_vtk *v = o->v;
  const char *tag = assoc == PX_VTK_ASSOC_POINT ? "PointData" : "CellData";
  const char *scalars = NULL, *vectors = NULL;
  size_t i, count = 0;
  for (i = 0; i < v->narrays; ++i) {
    const struct px_vtk_array *a = &v->arrays[i];
    if (a->assoc != assoc) continue;
    ++count;
    if (!scalars && a->ncomp_out == 1) scalars = a->name;
    if (!vectors && a->ncomp_out == 3) vectors = a->name;
  }
  if (!count) return PX_STATUS_OK;
  fprintf(o->f, "      <%s", tag);
  if (scalars) {
    fputs(" Scalars=\"", o->f);
    px_ioutil_xml_escape(o->f, scalars);
    fputc('"', o->f);
  }
  if (vectors) {
    fputs(" Vectors=\"", o->f);
    px_ioutil_xml_escape(o->f, vectors);
    fputc('"', o->f);
  }
  fputs(">\n", o->f);
  for (i = 0; i < v->narrays; ++i)
    if (v->arrays[i].assoc == assoc) PX_TRY(px_vtk_emit(o, &v->arrays[i], "        "));
  fprintf(o->f, "      </%s>\n", tag);
  return PX_STATUS_OK;
}

static void px_vtk_emit_field(struct px_vtk_out *o) {
  struct px_vtk *v = o->v;
  size_t i;
  if (!v->have_time && !v->nfields) return;
  fputs("    <FieldData>\n", o->f);
  if (v->have_time) {
    fprintf(o->f,
            "      <DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" "
            "format=\"ascii\">%.17g</DataArray>\n",
            v->time);
    fprintf(o->f,
            "      <DataArray type=\"Int64\" Name=\"Step\" NumberOfTuples=\"1\" "
            "format=\"ascii\">%" PRId64 "</DataArray>\n",
            v->step);
  }
  for (i = 0; i < v->nfields; ++i) {
    fputs("      <DataArray type=\"Float64\" Name=\"", o->f);
    px_ioutil_xml_escape(o->f, v->fields[i].name);
    fprintf(o->f, "\" NumberOfTuples=\"1\" format=\"ascii\">%.17g</DataArray>\n",
            v->fields[i].value);
  }
  fputs("    </FieldData>\n", o->f);
}

/* Copy `m` tuples starting at tuple `base` of `a` into dst, interleaved. */
static void px_vtk_fill(const struct px_vtk_array *a, size_t base, size_t m, unsigned char *dst) {
  size_t es = px_dtype_size(a->dtype), i;
  int nc = a->ncomp_out, k;
  if (a->src == PX_VTK_SRC_IOTA) {
    for (i = 0; i < m; ++i) {
      int64_t val = a->start + (int64_t)(base + i) * a->step;
      memcpy(dst + i * 8, &val, 8);
    }
    return;
  }
  if (a->src == PX_VTK_SRC_CONST) {
    memset(dst, (int)(a->start & 0xff), m);
    return;
  }
  for (k = 0; k < nc; ++k) {
    const unsigned char *src;
    size_t sstride;
    if (a->src == PX_VTK_SRC_SOA) {
      src = k < a->ncomp_in ? a->comp[k] : NULL;
      if (src) src += base * es;
      sstride = es;
    } else {
      src = k < a->ncomp_in ? (const unsigned char *)a->comp[0] : NULL;
      if (src) src += (base * (size_t)a->ncomp_in + (size_t)k) * es;
      sstride = es * (size_t)a->ncomp_in;
    }
    {
      unsigned char *d = dst + (size_t)k * es;
      size_t dstride = es * (size_t)nc;
      if (!src) {
        for (i = 0; i < m; ++i) memset(d + i * dstride, 0, es);
      } else if (es == 8) {
        for (i = 0; i < m; ++i) {
          uint64_t w;
          memcpy(&w, src + i * sstride, 8);
          memcpy(d + i * dstride, &w, 8);
        }
      } else if (es == 4) {
        for (i = 0; i < m; ++i) {
          uint32_t w;
          memcpy(&w, src + i * sstride, 4);
          memcpy(d + i * dstride, &w, 4);
        }
      } else {
        for (i = 0; i < m; ++i) memcpy(d + i * dstride, src + i * sstride, es);
      }
    }
  }
}

static enum px_status px_vtk_write_block(struct px_vtk_out *o, const struct px_vtk_array *a) {
  struct px_vtk *v = o->v;
  uint64_t bytes = px_vtk_block_bytes(a);
  size_t es = px_dtype_size(a->dtype);
  size_t tuple = es * (size_t)a->ncomp_out;
  int direct = a->src == PX_VTK_SRC_AOS
                   ? a->ncomp_in == a->ncomp_out
                   : (a->src == PX_VTK_SRC_SOA && a->ncomp_out == 1 && a->comp[0] != NULL);
  if (fwrite(&bytes, sizeof bytes, 1, o->f) != 1) goto fail;
  if (a->n == 0) return PX_STATUS_OK;
  if (direct) {
    if (fwrite(a->comp[0], tuple, a->n, o->f) != a->n) goto fail;
  } else {
    size_t per = PX_VTK_CHUNK_BYTES / tuple, base;
    if (!v->chunk) {
      v->chunk = px_mem_alloc(v->ctx, "vtk", PX_VTK_CHUNK_BYTES);
      if (!v->chunk) return PX_STATUS_NOMEM;
    }
    for (base = 0; base < a->n; base += per) {
      size_t m = a->n - base < per ? a->n - base : per;
      px_vtk_fill(a, base, m, v->chunk);
      if (fwrite(v->chunk, tuple, m, o->f) != m) goto fail;
    }
  }
  return PX_STATUS_OK;
fail:
  return px_context_fail(v->ctx, PX_STATUS_IO, "cannot write %s (array '%s'): %s", o->path, a->name,
                         strerror(errno));
}

static enum px_status px_vtk_check_count(struct px_vtk *v, enum px_vtk_assoc assoc, size_t expected,
                                         const char *what) {
  size_t i;
  for (i = 0; i < v->narrays; ++i) {
    const struct px_vtk_array *a = &v->arrays[i];
    if (a->assoc == assoc && a->n != expected)
      return px_context_fail(v->ctx, PX_STATUS_INVALID,
                             "vtk array '%s' has %zu tuples but the dataset has %zu %s", a->name,
                             a->n, expected, what);
  }
  return PX_STATUS_OK;
}

static enum px_status px_vtk_check_ids(struct px_vtk *v, const int64_t *ids, size_t n,
                                       const char *what) {
  size_t i;
  for (i = 0; i < n; ++i)
    if (ids[i] < 0 || (uint64_t)ids[i] >= (uint64_t)v->points.n)
      return px_context_fail(v->ctx, PX_STATUS_INVALID,
                             "vtk %s: point id %" PRId64 " at position %zu is outside 0..%zu", what,
                             ids[i], i, v->points.n ? v->points.n - 1 : 0);
  return PX_STATUS_OK;
}

/* Validate the builder for `kind` and compute the number of cells. */
static enum px_status px_vtk_validate(struct px_vtk *v, enum px_vtk_kind kind, size_t *ncells,
                                      size_t *npoints) {
  if (kind == PX_VTK_KIND_IMAGE) {
    size_t k, nc = 1, np = 1;
    if (!v->have_image)
      return px_context_fail(v->ctx, PX_STATUS_INVALID,
                             "a .vti file needs px_vtk_set_image (dims, origin, spacing)");
    if (v->have_points || v->vertices || v->nlines || v->ncells)
      return px_context_fail(v->ctx, PX_STATUS_INVALID,
                             "a .vti file has implicit points and cells: remove the points, "
                             "vertices, lines and cells or write .vtp/.vtu");
    for (k = 0; k < 3; ++k) {
      np *= v->dims[k];
      nc *= v->dims[k] > 1 ? v->dims[k] - 1 : 1;
    }
    *ncells = nc;
    *npoints = np;
  } else {
    if (!v->have_points)
      return px_context_fail(v->ctx, PX_STATUS_INVALID, "a %s file needs points",
                             kind == PX_VTK_KIND_POLY ? ".vtp" : ".vtu");
    if (v->have_image)
      return px_context_fail(v->ctx, PX_STATUS_INVALID,
                             "image geometry (px_vtk_set_image) only goes into a .vti file");
    *npoints = v->points.n;
    if (kind == PX_VTK_KIND_POLY) {
      if (v->ncells)
        return px_context_fail(v->ctx, PX_STATUS_INVALID,
                               "a .vtp file has vertices and lines, not cells "
                               "(px_vtk_set_cells is for .vtu)");
      PX_TRY(px_vtk_check_ids(v, v->line_conn, v->nline_conn, "line"));
      *ncells = (v->vertices ? v->points.n : 0) + v->nlines;
    } else {
      if (v->nlines)
        return px_context_fail(v->ctx, PX_STATUS_INVALID,
                               "polylines go into a .vtp file; a .vtu takes px_vtk_set_cells");
      if (v->vertices && v->ncells)
        return px_context_fail(v->ctx, PX_STATUS_INVALID,
                               "a .vtu file takes either vertices or cells, not both");
      if (!v->vertices && !v->ncells && v->points.n)
        return px_context_fail(v->ctx, PX_STATUS_INVALID,
                               "a .vtu file needs cells (px_vtk_set_cells) or vertices");
      if (v->ncells && v->cell_uniform_nodes) {
        PX_TRY(px_vtk_check_ids(v, v->cell_conn, v->ncells * (size_t)v->cell_uniform_nodes,
                                "cell connectivity"));
      } else if (v->ncells) {
        size_t i;
        int64_t prev = 0;
        for (i = 0; i < v->ncells; ++i) {
          if (v->cell_offsets[i] <= prev)
            return px_context_fail(v->ctx, PX_STATUS_INVALID,
                                   "vtk cells: offsets[%zu] = %" PRId64
                                   " is not above the previous end %" PRId64
                                   " (offsets are cell ends)",
                                   i, v->cell_offsets[i], prev);
          prev = v->cell_offsets[i];
        }
        PX_TRY(px_vtk_check_ids(v, v->cell_conn, (size_t)prev, "cell connectivity"));
      }
      *ncells = v->vertices ? v->points.n : v->ncells;
    }
  }
  PX_TRY(px_vtk_check_count(v, PX_VTK_ASSOC_POINT, *npoints, "points"));
  PX_TRY(px_vtk_check_count(v, PX_VTK_ASSOC_CELL, *ncells, "cells"));
  return PX_STATUS_OK;
}

static enum px_status px_vtk_write_xml(struct px_vtk_out *o, enum px_vtk_kind kind, size_t ncells,
                                       size_t npoints) {
  struct px_vtk *v = o->v;
  FILE *f = o->f;
  static const char *const type_names[] = {"PolyData", "ImageData", "UnstructuredGrid"};
  const char *type = type_names[kind];
  size_t k;

  fprintf(f,
          "<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"%s\" version=\"1.0\" byte_order=\"%s\" header_type=\"UInt64\">\n",
          type, px_vtk_byte_order());
  if (kind == PX_VTK_KIND_IMAGE) {
    char extent[200];
    snprintf(extent, sizeof extent, "0 %zu 0 %zu 0 %zu", v->dims[0] - 1, v->dims[1] - 1,
             v->dims[2] - 1);
    fprintf(f,
            "  <ImageData WholeExtent=\"%s\" Origin=\"%.17g %.17g %.17g\" "
            "Spacing=\"%.17g %.17g %.17g\">\n",
            extent, v->origin[0], v->origin[1], v->origin[2], v->spacing[0], v->spacing[1],
            v->spacing[2]);
    px_vtk_emit_field(o);
    fprintf(f, "    <Piece Extent=\"%s\">\n", extent);
  } else if (kind == PX_VTK_KIND_POLY) {
    fprintf(f, "  <PolyData>\n");
    px_vtk_emit_field(o);
    fprintf(f,
            "    <Piece NumberOfPoints=\"%zu\" NumberOfVerts=\"%zu\" NumberOfLines=\"%zu\" "
            "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
            npoints, v->vertices ? npoints : (size_t)0, v->nlines);
  } else {
    fprintf(f, "  <UnstructuredGrid>\n");
    px_vtk_emit_field(o);
    fprintf(f, "    <Piece NumberOfPoints=\"%zu\" NumberOfCells=\"%zu\">\n", npoints, ncells);
  }
  PX_TRY(px_vtk_emit_data(o, PX_VTK_ASSOC_POINT));
  PX_TRY(px_vtk_emit_data(o, PX_VTK_ASSOC_CELL));
  if (kind != PX_VTK_KIND_IMAGE) {
    v->points.name = (char *)"Points";
    fprintf(f, "      <Points>\n");
    PX_TRY(px_vtk_emit(o, &v->points, "        "));
    fprintf(f, "      </Points>\n");
    v->points.name = NULL;
  }
  if (kind == PX_VTK_KIND_POLY) {
    if (v->vertices) {
      fprintf(f, "      <Verts>\n");
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "connectivity", PX_DTYPE_I64, npoints, PX_VTK_SRC_IOTA, NULL, 0, 1),
          "        "));
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "offsets", PX_DTYPE_I64, npoints, PX_VTK_SRC_IOTA, NULL, 1, 1),
          "        "));
      fprintf(f, "      </Verts>\n");
    }
    if (v->nlines) {
      fprintf(f, "      <Lines>\n");
      PX_TRY(px_vtk_emit(o,
                         px_vtk_gen(o, "connectivity", PX_DTYPE_I64, v->nline_conn, PX_VTK_SRC_SOA,
                                    v->line_conn, 0, 0),
                         "        "));
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "offsets", PX_DTYPE_I64, v->nlines, PX_VTK_SRC_SOA, v->line_end, 0, 0),
          "        "));
      fprintf(f, "      </Lines>\n");
    }
  } else if (kind == PX_VTK_KIND_UNSTRUCTURED) {
    fprintf(f, "      <Cells>\n");
    if (v->vertices) {
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "connectivity", PX_DTYPE_I64, npoints, PX_VTK_SRC_IOTA, NULL, 0, 1),
          "        "));
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "offsets", PX_DTYPE_I64, npoints, PX_VTK_SRC_IOTA, NULL, 1, 1),
          "        "));
      PX_TRY(px_vtk_emit(o,
                         px_vtk_gen(o, "types", PX_DTYPE_U8, npoints, PX_VTK_SRC_CONST, NULL,
                                    PX_VTK_CELL_VERTEX, 0),
                         "        "));
    } else if (v->cell_uniform_nodes) {
      int64_t nodes = v->cell_uniform_nodes;
      PX_TRY(px_vtk_emit(o,
                         px_vtk_gen(o, "connectivity", PX_DTYPE_I64, ncells * (size_t)nodes,
                                    PX_VTK_SRC_SOA, v->cell_conn, 0, 0),
                         "        "));
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "offsets", PX_DTYPE_I64, ncells, PX_VTK_SRC_IOTA, NULL, nodes, nodes),
          "        "));
      PX_TRY(px_vtk_emit(o,
                         px_vtk_gen(o, "types", PX_DTYPE_U8, ncells, PX_VTK_SRC_CONST, NULL,
                                    (int64_t)v->cell_uniform_type, 0),
                         "        "));
    } else {
      size_t nconn = ncells ? (size_t)v->cell_offsets[ncells - 1] : 0;
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "connectivity", PX_DTYPE_I64, nconn, PX_VTK_SRC_SOA, v->cell_conn, 0, 0),
          "        "));
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "offsets", PX_DTYPE_I64, ncells, PX_VTK_SRC_SOA, v->cell_offsets, 0, 0),
          "        "));
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "types", PX_DTYPE_U8, ncells, PX_VTK_SRC_SOA, v->cell_types, 0, 0),
          "        "));
    }
    fprintf(f, "      </Cells>\n");
  }
  fprintf(f, "    </Piece>\n  </%s>\n  <AppendedData encoding=\"raw\">\n   _", type);
  for (k = 0; k < o->nblocks; ++k) PX_TRY(px_vtk_write_block(o, o->blocks[k]));
  fprintf(f, "\n  </AppendedData>\n</VTKFile>\n");
  return PX_STATUS_OK;
}

enum px_status px_vtk_write(struct px_vtk *v, const char *path) {
  struct px_vtk_out o;
  struct px_file *file = NULL;
  enum px_vtk_kind kind;
  enum px_status s;
  size_t ncells = 0, npoints = 0;
  if (!v || !path) return PX_STATUS_INVALID;
  if (px_ioutil_has_ext(path, ".vtp"))
    kind = PX_VTK_KIND_POLY;
  else if (px_ioutil_has_ext(path, ".vti"))
    kind = PX_VTK_KIND_IMAGE;
  else if (px_ioutil_has_ext(path, ".vtu"))
    kind = PX_VTK_KIND_UNSTRUCTURED;
  else
    return px_context_fail(v->ctx, PX_STATUS_INVALID,
                           "%s: unknown VTK file kind (expected .vtp, .vti or .vtu)", path);
  s = px_vtk_validate(v, kind, &ncells, &npoints);
  if (s != PX_STATUS_OK) return px_context_prefix(v->ctx, "%s", path);
  PX_TRY(px_file_open(v->ctx, path, &file));
  memset(&o, 0, sizeof o);
  o.v = v;
  o.path = path;
  o.f = px_file_stream(file);
  s = px_vtk_write_xml(&o, kind, ncells, npoints);
  v->points.name = NULL;
  px_mem_free(v->ctx, o.blocks);
  if (s != PX_STATUS_OK) {
    px_file_abort(file);
    return s;
  }
  return px_file_commit(file);
}

/* ---- .pvd series --------------------------------------------------------- */

struct px_vtk_entry {
  double time;
  int part;
  char *file; /* owned */
};

struct px_vtk_series {
  struct px_context *ctx;       /* borrowed */
  char *path;                   /* owned */
  struct px_vtk_entry *entries; /* owned */
  size_t n, cap;
};

static enum px_status px_vtk_series_write(struct px_vtk_series *s) {
  struct px_file *file;
  FILE *f;
  size_t i;
  PX_TRY(px_file_open(s->ctx, s->path, &file));
  f = px_file_stream(file);
  fprintf(f,
          "<?xml version=\"1.0\"?>\n"
          "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"%s\">\n"
          "  <Collection>\n",
          px_vtk_byte_order());
  for (i = 0; i < s->n; ++i) {
    fprintf(f, "    <DataSet timestep=\"%.17g\" group=\"\" part=\"%d\" file=\"", s->entries[i].time,
            s->entries[i].part);
    px_ioutil_xml_escape(f, s->entries[i].file);
    fputs("\"/>\n", f);
  }
  fputs("  </Collection>\n</VTKFile>\n", f);
  return px_file_commit(file);
}

static enum px_status px_vtk_series_push(struct px_vtk_series *s, double time, int part,
                                         const char *file) {
  char *copy;
  PX_TRY(px_vtk_grow(s->ctx, (void **)&s->entries, &s->cap, s->n + 1, sizeof *s->entries));
  copy = px_ioutil_strdup(s->ctx, "vtk series", file);
  if (!copy) return PX_STATUS_NOMEM;
  s->entries[s->n].time = time;
  s->entries[s->n].part = part;
  s->entries[s->n].file = copy;
  ++s->n;
  return PX_STATUS_OK;
}

static enum px_status px_vtk_series_new(struct px_context *ctx, const char *path,
                                        struct px_vtk_series **out) {
  struct px_vtk_series *s;
  if (!ctx || !path || !out) return PX_STATUS_INVALID;
  *out = NULL;
  s = px_mem_calloc(ctx, "vtk series", 1, sizeof *s);
  if (!s) return PX_STATUS_NOMEM;
  s->ctx = ctx;
  s->path = px_ioutil_strdup(ctx, "vtk series", path);
  if (!s->path) {
    px_mem_free(ctx, s);
    return PX_STATUS_NOMEM;
  }
  *out = s;
  return PX_STATUS_OK;
}

void px_vtk_series_close(struct px_vtk_series *s) {
  size_t i;
  if (!s) return;
  for (i = 0; i < s->n; ++i) px_mem_free(s->ctx, s->entries[i].file);
  px_mem_free(s->ctx, s->entries);
  px_mem_free(s->ctx, s->path);
  px_mem_free(s->ctx, s);
}

enum px_status px_vtk_series_open(struct px_context *ctx, const char *path,
                                  struct px_vtk_series **out) {
  enum px_status st;
  PX_TRY(px_vtk_series_new(ctx, path, out));
  st = px_vtk_series_write(*out);
  if (st != PX_STATUS_OK) {
    px_vtk_series_close(*out);
    *out = NULL;
  }
  return st;
}

/* Decode the XML entities we write (and numeric ones) in place. */
static void px_vtk_xml_unescape(char *s) {
  static const struct {
    const char *ent;
    char c;
  } ents[] = {{"&amp;", '&'}, {"&lt;", '<'}, {"&gt;", '>'}, {"&quot;", '"'}, {"&apos;", '\''}};
  char *r = s, *w = s;
  while (*r) {
    size_t k;
    int done = 0;
    if (*r == '&') {
      for (k = 0; k < sizeof ents / sizeof ents[0]; ++k) {
        size_t len = strlen(ents[k].ent);
        if (strncmp(r, ents[k].ent, len) == 0) {
          *w++ = ents[k].c;
          r += len;
          done = 1;
          break;
        }
      }
    }
    if (!done) *w++ = *r++;
  }
  *w = '\0';
}

/* `name` next to the file `path` (in the same folder) into buf; 0 if it does
 * not fit. */
static int px_vtk_sibling(const char *path, const char *name, char *buf, size_t size) {
  const char *slash = strrchr(path, '/');
  int n = slash ? snprintf(buf, size, "%.*s/%s", (int)(slash - path), path, name)
                : snprintf(buf, size, "%s", name);
  return n > 0 && (size_t)n < size;
}

/* Parse the attributes of the element starting at *p (just after its name)
 * up to '/>' or '>'. Fills timestep/part/file; returns 0 on a syntax error. */
static int px_vtk_parse_dataset(char **p, double *time, int *part, char **file, int *have_time) {
  char *q = *p;
  *have_time = 0;
  *part = 0;
  *file = NULL;
  for (;;) {
    char *name, *value, quote;
    size_t nlen;
    while (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r') ++q;
    if (q[0] == '/' && q[1] == '>') {
      *p = q + 2;
      return 1;
    }
    if (q[0] == '>') {
      *p = q + 1;
      return 1;
    }
    name = q;
    while ((*q >= 'a' && *q <= 'z') || (*q >= 'A' && *q <= 'Z') || *q == '_' || *q == '-' ||
           *q == ':' || (*q >= '0' && *q <= '9'))
      ++q;
    nlen = (size_t)(q - name);
    if (!nlen) return 0;
    while (*q == ' ' || *q == '\t') ++q;
    if (*q != '=') return 0;
    ++q;
    while (*q == ' ' || *q == '\t') ++q;
    quote = *q;
    if (quote != '"' && quote != '\'') return 0;
    value = ++q;
    while (*q && *q != quote) ++q;
    if (!*q) return 0;
    *q++ = '\0';
    if (nlen == 8 && strncmp(name, "timestep", 8) == 0) {
      char *end;
      *time = strtod(value, &end);
      if (end == value) return 0;
      *have_time = 1;
    } else if (nlen == 4 && strncmp(name, "part", 4) == 0) {
      *part = atoi(value);
    } else if (nlen == 4 && strncmp(name, "file", 4) == 0) {
      px_vtk_xml_unescape(value);
      *file = value;
    }
  }
}

enum px_status px_vtk_series_open_resume(struct px_context *ctx, const char *path, double t_resume,
                                         struct px_vtk_series **out) {
  struct px_vtk_series *s;
  char *text = NULL, *p;
  enum px_status st;
  size_t len;
  PX_TRY(px_vtk_series_new(ctx, path, &s));
  st = px_ioutil_read_file(ctx, path, &text, &len);
  if (st == PX_STATUS_NOT_FOUND) {
    px_context_clear(ctx);
    st = PX_STATUS_OK;
  } else if (st == PX_STATUS_OK) {
    if (!strstr(text, "<VTKFile") || !strstr(text, "type=\"Collection\"")) {
      st =
          px_context_fail(ctx, PX_STATUS_FORMAT,
                          "%s is not a VTK collection (.pvd) file; cannot resume its series", path);
    }
    p = text;
    while (st == PX_STATUS_OK && (p = strstr(p, "<DataSet")) != NULL) {
      size_t at = (size_t)(p - text);
      double t = 0.0;
      int part = 0, have_time = 0;
      char *file = NULL;
      p += 8;
      if (!px_vtk_parse_dataset(&p, &t, &part, &file, &have_time) || !have_time || !file) {
        st = px_context_fail(ctx, PX_STATUS_FORMAT,
                             "%s: byte %zu: a <DataSet> element needs timestep=\"..\" and "
                             "file=\"..\" attributes",
                             path, at);
        break;
      }
      if (t <= t_resume) {
        st = px_vtk_series_push(s, t, part, file);
      } else if (!strchr(file, '/') && !strchr(file, '\\') && strcmp(file, ".") != 0 &&
                 strcmp(file, "..") != 0) {
        /* The dropped entry's file belongs to the continuation being
         * replaced (an uninterrupted run would not have it, or will write it
         * again): delete it. Only plain names next to the .pvd. */
        char dropped[4096];
        if (px_vtk_sibling(path, file, dropped, sizeof dropped)) remove(dropped);
      }
    }
  }
  px_mem_free(ctx, text);
  if (st == PX_STATUS_OK) st = px_vtk_series_write(s);
  if (st != PX_STATUS_OK) {
    px_vtk_series_close(s);
    return st;
  }
  *out = s;
  return PX_STATUS_OK;
}

enum px_status px_vtk_series_add_part(struct px_vtk_series *s, double time, int part,
                                      const char *file) {
  if (!s || !file || !file[0]) return PX_STATUS_INVALID;
  if (!isfinite(time))
    return px_context_fail(s->ctx, PX_STATUS_INVALID, "%s: time %g of %s is not finite", s->path,
                           time, file);
  PX_TRY(px_vtk_series_push(s, time, part, file));
  if (px_vtk_series_write(s) != PX_STATUS_OK) {
    /* Keep memory equal to the file on disk (which still has the old list). */
    --s->n;
    px_mem_free(s->ctx, s->entries[s->n].file);
    return px_context_status(s->ctx);
  }
  return PX_STATUS_OK;
}

enum px_status px_vtk_series_add(struct px_vtk_series *s, double time, const char *file) {
  return px_vtk_series_add_part(s, time, 0, file);
}

size_t px_vtk_series_count(const struct px_vtk_series *s) { return s ? s->n : 0; }

double px_vtk_series_time(const struct px_vtk_series *s, size_t i) {
  return s && i < s->n ? s->entries[i].time : NAN;
}

const char *px_vtk_series_file(const struct px_vtk_series *s, size_t i) {
  return s && i < s->n ? s->entries[i].file : NULL;
}
