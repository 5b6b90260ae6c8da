/* The opencl lattice engine's state, shared by lattice_opencl.c (one
 * device, the whole grid) and lattice_opencl_block.c (a block of planes of
 * a run over ranks). Compiled only with the opencl backend. */
#ifndef PX_LATTICE_OPENCL_H
#define PX_LATTICE_OPENCL_H

#include "compute/opencl/kernels.h"
#include "solvers/lattice/lattice_engine.h"

/* Steps between reads of the blow-up flags (each read waits for the queue);
 * the kernels record the step and element a non-finite value appeared at
 * (lattice.cl lt_flag), so the report names them however late it is read. */
#define PX_LATTICE_OCL_CHECK 16
/* Work-group size of the field kernel. */
#define PX_LATTICE_OCL_WG 64

struct px_lattice_ocl {
  struct px_context *ctx;           /* borrowed */
  const struct px_lattice_model *m; /* borrowed */
  struct px_backend *be;            /* borrowed */
  enum px_lattice_integrator integ;
  enum px_precision prec;
  size_t real;              /* bytes per real */
  cl_program prog;          /* cached by the backend */
  struct px_buffer *buf[4]; /* RK4: y0 ya yb acc; leapfrog: 2 */
  int nbuf, cur;
  struct px_buffer *lp, *lm, *fr, *grp, *list, *tab, *bad, *ends, *out;
  cl_uint n, pad, ns, s1, s2, nbc;
  double alpha;
  double *table_d; /* owned; ngroup x 18 */
  void *table;     /* owned; the same in device reals */
  double table_t;
  int table_tdep;
  long unchecked;                     /* steps since the last blow-up check */
  long first_unchecked;               /* step index of the first of them */
  double t_end[PX_LATTICE_OCL_CHECK]; /* time at the end of each of them [s] */
  int l1;                             /* link-once scheme: links evaluated once into lk */
  struct px_buffer *lk;               /* 18 x ns reals (3 axes x F, G), link-once only */
  /* volumetric term (Poisson's ratio != 0; lattice.cl lt_vol): pv the
   * coefficients P_a of the state the next force pass reads, 3 x ns reals
   * (NULL at nu = 0); lh2 = lambda h^2 [N] */
  struct px_buffer *pv;
  struct px_buffer *vf; /* nalloc bytes: the model's vfree (nu != 0 only) */
  double lh2;
  /* the element kernels' range: entries at .. at + cnt of the padded layout
   * (the launch's `pad` and `n`); pad and n except during a block's pass */
  cl_uint at, cnt;
  struct px_buffer *rowbuf; /* 3 n[1] n[2] reals: the Rayleigh sums per row */
  double *rowsum;           /* owned; the same in double (3 n[1] n[2]) */
  void *rowh;               /* owned; host copy of rowbuf */
  /* over ranks (lattice_opencl_block.c) */
  int has_blk;
  struct px_lattice_block blk;
  void *mirror;   /* owned; host copy of a state buffer: the edge and halo planes */
  long ends_host; /* block: broken link ends of all ranks (the device counts this
                     rank's since the last pass) */
};

/* lattice_opencl.c */
enum px_status px_lattice_ocl_begin(struct px_lattice_ocl *e, const char *name, cl_uint n,
                                    struct px_opencl_args *a);
enum px_status px_lattice_ocl_table(struct px_lattice_ocl *e, double t, int force);
struct px_buffer *px_lattice_ocl_state(struct px_lattice_ocl *e);
enum px_status px_lattice_ocl_fracture(struct px_lattice_ocl *e, struct px_buffer *y);
enum px_status px_lattice_ocl_links(struct px_lattice_ocl *e, struct px_buffer *y);
/* The volumetric coefficients of state y into pv (nothing at nu = 0). */
enum px_status px_lattice_ocl_vol(struct px_lattice_ocl *e, struct px_buffer *y);
enum px_status px_lattice_ocl_rk4_stage(struct px_lattice_ocl *e, int bc, int stage,
                                        struct px_buffer *ys, struct px_buffer *yn, double cs,
                                        double dt, cl_int kstep);
enum px_status px_lattice_ocl_lf_kernel(struct px_lattice_ocl *e, int bc, struct px_buffer *ya,
                                        struct px_buffer *yb, double dt, cl_int kstep);
enum px_status px_lattice_ocl_check(struct px_lattice_ocl *e, long step);
/* Rayleigh sums of the rows [ra, rb) of the current state into e->rowsum
 * (lattice.cl lt_rows); nu != 0: with the coefficients in pv
 * (px_lattice_ocl_vol or, on a block, those of its rows and halo first). */
enum px_status px_lattice_ocl_row_sums(struct px_lattice_ocl *e, long ra, long rb);

/* lattice_opencl_block.c */
enum px_status px_lattice_ocl_set_block(void *p, const struct px_lattice_block *b);
enum px_status px_lattice_ocl_run_blk(struct px_lattice_ocl *e, long step, double t, double dt,
                                      long n);
enum px_status px_lattice_ocl_rayleigh_blk(struct px_lattice_ocl *e, double sums[3]);
/* The state's halo and (nu != 0) the coefficients of the block and its
 * halo at the current state, for the fields (lattice_opencl_block.c). */
enum px_status px_lattice_ocl_blk_current(struct px_lattice_ocl *e);
long px_lattice_ocl_broken_blk(struct px_lattice_ocl *e);
enum px_status px_lattice_ocl_set_broken_blk(struct px_lattice_ocl *e, long links);

#endif
