/* The VTK writer's private layout (vtk.c: the dataset a caller builds;
 * vtk_write.c: the XML file; vtk_series.c: .pvd series). */
#ifndef PX_VTK_IMPL_H
#define PX_VTK_IMPL_H

#include <stddef.h>
#include <stdint.h>

#include "partix/vtk.h"

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

/* VTK's name of a data type ("Float64"), NULL for none. */
const char *px_vtk_type_name(enum px_dtype t);
/* "LittleEndian" or "BigEndian": this machine's byte order. */
const char *px_vtk_byte_order(void);
/* Grow *buf (elements of `size` bytes) to hold at least `need` elements. */
enum px_status px_vtk_grow(struct px_context *ctx, void **buf, size_t *cap, size_t need,
                           size_t size);

#endif
