/* partix part3d (part3d.c): a 3D part studied through plane sections, each
 * a 2D granular run of its own (part3d_sections.c), and the results mapped
 * back onto the part's surface (part3d_map.c). */
#ifndef PX_CLI_PART3D_H
#define PX_CLI_PART3D_H

#include <libfyaml.h>
#include <stdint.h>

#include "cli/cli.h"
#include "io/geometry/geo_dxf.h"
#include "io/geometry/geo_mesh.h"
#include "io/mesh_view.h"

/* Points of a section's contour, all its loops together: each starts a
 * boundary segment of the 2D case, whose granular solver takes at most as
 * many segments (PX_GRAN_SEG_MAX) as its DXF reader takes entities: a
 * section beyond it could not run, and its file alone would take some
 * 50 bytes a point. */
#define PX_PART3D_MAX_POINTS PX_GEO_DXF_PIECES_MAX

struct px_sweep; /* cli/sweep.h */

#define PX_PART3D_MAX_SECTIONS 64
#define PX_PART3D_MAX_SET 16
/* units [m per mesh unit]: from a mesh in nanometres to one in kilometres */
#define PX_PART3D_UNITS_MIN 1e-9
#define PX_PART3D_UNITS_MAX 1e3

/* A contour of the 2D case other than the part, where the media may be
 * (the container): a polygon [m] (part3d_fit.c). */
struct px_part3d_region {
  char name[128];
  double *xy; /* owned (malloc): n points x, y */
  size_t n;
  double lo[2], hi[2]; /* its bounding box [m] */
};

struct px_part3d {
  const char *file;        /* the part3d file (argument) */
  struct fy_document *doc; /* owned */
  char base[4096];         /* the 2D base case, resolved against the file */
  char mesh_path[4096];    /* the surface mesh, resolved against the file */
  char dir[4096];          /* the study's folder */
  const char *contour;     /* borrowed (doc): the base case's contour the sections replace */
  int contour_index;       /* its index in granular.contours */
  double units;            /* [m per mesh unit] */
  double weld;             /* [mesh units] */
  double normal[3], vibration[3];
  double spacing;   /* [m] of the sections' points: the case's segment length */
  double center[2]; /* [m] where the part's centre goes in the 2D case */
  size_t nsec;
  double offset[PX_PART3D_MAX_SECTIONS]; /* [m] n . p of each section's plane */
  const char *set_key[PX_PART3D_MAX_SET], *set_value[PX_PART3D_MAX_SET]; /* borrowed */
  size_t nset;
  enum px_log_level log_level; /* the command's */
  struct px_geo_mesh mesh;     /* owned, in metres, checked */
  double u[3], v[3], n[3];     /* the sections' frame: u the vibration in the plane */
  double cu, cv;               /* the part's centre in plane coordinates [m] */
  struct px_geo_polyline *loops[PX_PART3D_MAX_SECTIONS]; /* owned: plane coordinates */
  size_t nloops[PX_PART3D_MAX_SECTIONS];
  struct px_part3d_region *regions; /* owned: the case's other contours that may hold media */
  size_t nregions;
  int part_inside; /* the replaced contour holds the media itself (side: inside) */
  /* 64-bit FNV-1a of what defines each section's run: its case (the base
   * case with the part3d overrides, resolved) and its contour, as written
   * to DIR/contours/section-K.dxf */
  uint64_t fingerprint[PX_PART3D_MAX_SECTIONS];
};

/* The base case's contours other than the part (and other than those with
 * side: outside) as regions, from its loaded case c (p->contour_index set);
 * p->part_inside. A CLI exit status (2: a shape that cannot be read, said
 * on stderr). */
int px_part3d_regions(struct px_part3d *p, struct px_context *ctx, const struct px_case *c);
void px_part3d_regions_free(struct px_part3d *p);
/* The first region that holds every point of section k (placed in the 2D
 * case: x - cu + center[0], y - cv + center[1]), or NULL. */
const struct px_part3d_region *px_part3d_container(const struct px_part3d *p, size_t k);

/* The three views of the part's pictures: along the normal (the sections'
 * picture) or along the vibration (a map's), across the sections (along
 * v, the normal up) and oblique. */
void px_part3d_views(const struct px_part3d *p, int surface, struct px_mesh_view *v);
/* The surface map from the sections' runs that finished (finished[k] for
 * DIR/sections/K+1): DIR/surface.vtp, surface.csv, surface_*.png,
 * surface_summary.json. Returns a CLI exit status. */
int px_part3d_map(struct px_part3d *p, struct px_context *ctx, const int *finished);

/* The sections' files and runs (part3d_sections.c). */
/* Loop q resampled at spacing h: its number of points, -1 out of memory; *x, *y when at most max.
 */
double px_part3d_resample(const struct px_geo_polyline *q, double h, double max, double **x,
                          double **y);
/* DIR/sections.csv and DIR/sections.png (the part with its sections). */
enum px_status px_part3d_write_sections(struct px_part3d *p, struct px_context *ctx);
/* The sweep s of the K section runs and each section's fingerprint; writes nothing. */
int px_part3d_make_sweep(struct px_part3d *p, struct px_context *ctx, struct px_sweep *s);
/* DIR/contours/section-K.dxf of every section. */
int px_part3d_write_contours(struct px_part3d *p, struct px_context *ctx, const struct px_sweep *s);
/* Refuses (2) a study whose section folders hold runs of other settings. */
int px_part3d_check_reuse(const struct px_part3d *p, const struct px_sweep *s);
/* DIR/sections/K.fingerprint of each section whose run starts now. */
int px_part3d_write_records(const struct px_part3d *p, struct px_context *ctx,
                            const struct px_sweep *s);

#endif
