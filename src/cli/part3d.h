/* partix part3d (part3d.c): a 3D part studied through plane sections, each
 * a 2D granular run of its own, and the results mapped back onto the part's
 * surface (part3d_map.c). */
#ifndef PX_CLI_PART3D_H
#define PX_CLI_PART3D_H

#include <libfyaml.h>

#include "cli/cli.h"
#include "io/geometry/geo_mesh.h"
#include "io/mesh_view.h"

#define PX_PART3D_MAX_SECTIONS 64
#define PX_PART3D_MAX_SET 16

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
};

/* The three views of the part's pictures: along the normal (the sections'
 * picture) or along the vibration (a map's), across the sections (along
 * v, the normal up) and oblique. */
void px_part3d_views(const struct px_part3d *p, int surface, struct px_mesh_view *v);
/* The surface map from the sections' runs that finished (finished[k] for
 * DIR/sections/K+1): DIR/surface.vtp, surface.csv, surface_*.png,
 * surface_summary.json. Returns a CLI exit status. */
int px_part3d_map(struct px_part3d *p, struct px_context *ctx, const int *finished);

#endif
