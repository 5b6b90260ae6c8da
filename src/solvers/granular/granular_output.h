/* What the outputs of the granular solver (granular_output.c) and its
 * pictures (granular_pictures.c) share. */
#ifndef PX_GRAN_OUTPUT_H
#define PX_GRAN_OUTPUT_H

#include "solvers/granular/granular_impl.h"

/* Columns of the per-segment report. */
enum {
  PX_GRAN_SEG_S,
  PX_GRAN_SEG_X,
  PX_GRAN_SEG_Y,
  PX_GRAN_SEG_NX,
  PX_GRAN_SEG_NY,
  PX_GRAN_SEG_LEN,
  PX_GRAN_SEG_IMPACTS,
  PX_GRAN_SEG_RATE,
  PX_GRAN_SEG_VN_MEAN,
  PX_GRAN_SEG_VN_RMS,
  PX_GRAN_SEG_VN_MAX,
  PX_GRAN_SEG_VT_MEAN,
  PX_GRAN_SEG_EN,
  PX_GRAN_SEG_ET,
  PX_GRAN_SEG_EN_LEN,
  PX_GRAN_SEG_ET_LEN,
  PX_GRAN_SEG_EN_AREA,
  PX_GRAN_SEG_ET_AREA,
  PX_GRAN_SEG_IMPULSE,
  PX_GRAN_SEG_LOAD,
  PX_GRAN_SEG_SLIDE,
  PX_GRAN_SEG_ARCH_V,
  PX_GRAN_SEG_ARCH_D,
  PX_GRAN_SEG_FIN_V,
  PX_GRAN_SEG_FIN_D,
  PX_GRAN_SEG_CTIME,
  PX_GRAN_SEG_CFRAC,
  PX_GRAN_SEG_DUR,
  PX_GRAN_SEG_FIRST,
  PX_GRAN_SEG_LAST,
  PX_GRAN_SEG_HARD,
  PX_GRAN_SEG_RES,
  PX_GRAN_SEG_NCOL
};
/* Names of the columns (csv headers, vtk arrays). */
extern const char *const px_gran_seg_names[PX_GRAN_SEG_NCOL];

/* World position [m] of vertex k of the geometry (contour c) at the
 * frames of the current step. */
void px_gran_world(const struct px_gran_run *r, size_t c, size_t k, double *x, double *y);
/* A resumed run removes its stale end-of-run picture once. */
void px_gran_resume_tidy(struct px_gran_run *r, const struct px_sim_output *o);
/* r->view: the statistics of the system with the contacts in progress added,
 * as they would be if every contact ended now. */
enum px_status px_gran_out_view(struct px_gran_run *r);
/* Unit of column q of the segment table. */
const char *px_gran_seg_unit(const struct px_gran_run *r, int q);
/* The segment table of contour c at time t [s] into cols[PX_GRAN_SEG_*][k]. */
void px_gran_seg_table(const struct px_gran_run *r, size_t c, double t, double **cols);
/* PX_GRAN_SEG_NCOL columns of n doubles (owned; px_gran_cols_free). */
double **px_gran_cols_alloc(struct px_context *ctx, size_t n);
void px_gran_cols_free(struct px_context *ctx, double **cols);

/* Pictures (granular_pictures.c). The reported contours (body frame)
 * coloured by quantity q; quantity q along contour c against s; column col
 * of the run's rows (n of PX_GRAN_PLOT_NCOL) against time. */
enum px_status px_gran_contours_png(struct px_gran_run *r, int q, const char *dir, double t);
enum px_status px_gran_profile_png(struct px_gran_run *r, size_t c, int q, const char *dir,
                                   double t);
enum px_status px_gran_plot(struct px_gran_run *r, const char *dir, const char *file,
                            const char *title, const char *ylabel, const double *rows, size_t n,
                            size_t col);

#endif
