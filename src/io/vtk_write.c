/* VTK XML writer (binary appended, raw encoding, UInt64 block headers).
 *
 * Layout written (VTK file format documentation, "XML File Formats"):
 *   <VTKFile type=.. version="1.0" byte_order=.. header_type="UInt64">
 *     <PolyData|ImageData ..|UnstructuredGrid> <FieldData/> <Piece ..>
 *       <PointData/> <CellData/> <Points/> <Verts/> <Lines/> <Polys/> | <Cells/>
 *     </Piece> </..>
 *     <AppendedData encoding="raw">_ [UInt64 nbytes][nbytes of data] ...
 *   </VTKFile>
 * Each DataArray's offset attribute is the byte position of its block after
 * the '_'. Blocks are written in the order the DataArray elements appear. */
#include "partix/vtk.h"

#include <errno.h>
#include <inttypes.h>
#include <stdlib.h>
#include <string.h>

#include "io/ioutil.h"
#include "io/vtk_impl.h"
#include "partix/file.h"
#include "partix/memory.h"

enum px_vtk_kind { PX_VTK_KIND_POLY, PX_VTK_KIND_IMAGE, PX_VTK_KIND_UNSTRUCTURED };

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
      const enum px_vtk_cell t = v->cell_uniform_type;
      if (v->ncells &&
          (!v->cell_uniform_nodes ||
           (t != PX_VTK_CELL_TRIANGLE && t != PX_VTK_CELL_QUAD && t != PX_VTK_CELL_POLYGON)))
        return px_context_fail(v->ctx, PX_STATUS_INVALID,
                               "a .vtp file has vertices, lines and polygons of one kind "
                               "(px_vtk_set_cells_uniform with triangles, quads or polygons); "
                               "other cells go into a .vtu");
      PX_TRY(px_vtk_check_ids(v, v->line_conn, v->nline_conn, "line"));
      if (v->ncells)
        PX_TRY(px_vtk_check_ids(v, v->cell_conn, v->ncells * (size_t)v->cell_uniform_nodes,
                                "polygon connectivity"));
      *ncells = (v->vertices ? v->points.n : 0) + v->nlines + v->ncells;
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
            "NumberOfStrips=\"0\" NumberOfPolys=\"%zu\">\n",
            npoints, v->vertices ? npoints : (size_t)0, v->nlines, v->ncells);
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
    if (v->ncells) {
      const int64_t nodes = v->cell_uniform_nodes;
      fprintf(f, "      <Polys>\n");
      PX_TRY(px_vtk_emit(o,
                         px_vtk_gen(o, "connectivity", PX_DTYPE_I64, v->ncells * (size_t)nodes,
                                    PX_VTK_SRC_SOA, v->cell_conn, 0, 0),
                         "        "));
      PX_TRY(px_vtk_emit(
          o, px_vtk_gen(o, "offsets", PX_DTYPE_I64, v->ncells, PX_VTK_SRC_IOTA, NULL, nodes, nodes),
          "        "));
      fprintf(f, "      </Polys>\n");
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
