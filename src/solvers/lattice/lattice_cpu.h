/* The cpu lattice engine's state (lattice_cpu.c) and its loops, compiled
 * once per precision from lattice_cpu_impl.h and lattice_cpu_fields_impl.h
 * (lattice_cpu_f32.c, lattice_cpu_f64.c; names px_lattice_cpu_*_f32 /
 * _f64). Private to the engine. */
#ifndef PX_LATTICE_CPU_H
#define PX_LATTICE_CPU_H

#include <stddef.h>
#include <stdint.h>

#include "core/tuner.h"
#include "solvers/lattice/lattice_engine.h"

/* Reals of one link-once scratch set (struct lt_l1s) for rows of n0
 * cells and planes of n1 rows: x-links of a row, y-links of two rows, z-links
 * of two planes, 6 components each. */
#define LT_L1_WORDS(n0, n1) (6 * (((n0) + 1) + 2 * (n0) + 2 * (n0) * (n1)))
/* Reals of one stage's window of volumetric coefficients in the fused RK4
 * sweep (nu != 0; lattice_cpu_vol_impl.h): 3 planes, 3 components each of
 * n1 + 1 rows (the plane, then row 0 of the next plane). */
#define LT_PW_WORDS(n0, n1) (9 * ((n1) + 1) * (n0))

/* Work split of the loops (lattice_cpu_impl.h), taken dynamically so that a
 * thread another process holds off its core delays one block, not 1/T of
 * the step. Rows (n0 up to a few hundred elements) per block of the row
 * loops, and boundary-condition elements per block: */
#define LT_ROWS_CHUNK 8
#define LT_BC_CHUNK 256
/* The link-once passes split the planes into slabs: at most
 * LT_SLABS_PER_THREAD per thread, at least LT_SLAB_MIN planes each (a
 * slab's first plane evaluates its lower links itself: one extra plane of
 * z-links per slab) */
#define LT_SLABS_PER_THREAD 3
#define LT_SLAB_MIN 8

struct px_lattice_cpu {
  struct px_context *ctx;           /* borrowed */
  const struct px_lattice_model *m; /* borrowed */
  enum px_lattice_integrator integ;
  enum px_lattice_scheme scheme;
  int dbl;               /* 1: double, 0: float */
  int threads;           /* most threads (scratch sets) */
  int active;            /* threads of the current step (1..threads; the
                            same bits on any count) */
  struct px_tuner tuner; /* picks `active` per step */
  size_t ns;             /* component stride (elements) */
  /* State buffers (owned), each PX_LATTICE_NCOMP x ns reals. RK4: y0 (the
   * state), ya, yb (stage states), acc. Leapfrog: buf[cur] is the state. */
  void *buf[4];
  int nbuf, cur;
  uint8_t *lp, *lm;     /* owned; link flags (plus / minus bits) */
  const uint8_t *group; /* borrowed (model) */
  uint8_t *free;        /* owned; 1 = no boundary condition
                           (group 0 or 1), 0 = in bc_list */
  size_t *bc_list;      /* owned; elements with a BC group */
  uint8_t *bc_group;    /* owned; nbc: their groups, in the same order (read
                           in the row loops: the model's group array, one
                           byte per row there, missed the cache each time) */
  size_t nbc;
  size_t *bc_row;        /* owned; nrow + 1: bc_list[bc_row[r],
                            bc_row[r + 1]) lie in row r */
  long *row_lo, *row_hi; /* owned; occupied x range per row */
  double *rowsum;        /* owned; 3 per row (reductions) */
  void *table;           /* owned; group table, ngroup x 18 reals */
  double *table_d;       /* owned; the same in double */
  double table_t;        /* time the table was computed for */
  int table_tdep;
  void **scratch; /* owned; per thread, link-once sets
                     (4 for the fused RK4 sweep, else 1),
                     the fused sweep's 4 windows of P_a
                     (nu != 0, at pw_off), then the flag
                     rows (at flag_off) */
  size_t pw_off, flag_off, scratch_words;
  void *tabs[3];                    /* owned; fused RK4: group tables at
                                       t, t + dt/2, t + dt */
  unsigned char lpar[64], fpar[64]; /* struct lt_lpar, lt_fpar in the engine's
                                       precision (px_lattice_cpu_params_*) */
  double alpha;
  /* volumetric term (nu != 0; lattice_kernel.h): pv the coefficients P_a of
   * the state being advanced, 3 x ns reals (owned; NULL at nu = 0), lh2 =
   * lambda h^2 [N] */
  void *pv;
  double lh2;
  long broken_ends;
  /* a block of a decomposition over ranks (lattice_engine.h): has_blk 0
   * for the whole grid */
  struct px_lattice_block blk;
  int has_blk;
};

/* Reals per row cell of the flag rows: the six link flags, then the free
 * flag (lt_cpu_row_flags). */
#define LT_ROW_FLAGS 7

/* The loops of each precision (lattice_cpu_impl.h says what they do):
 * lpar = h2 k cl kb dk cr and fpar = ifn ift imb imt (lattice_kernel.h) in
 * double, converted once; state buffers PX_LATTICE_NCOMP x ns reals; dt [s].
 * The int results are nonzero when a non-finite value was written. Ranges:
 * rows [r0, r1) (row r = y + n[1] z) or planes [za, zb). */
void px_lattice_cpu_params_f32(struct px_lattice_cpu *e, const double lpar[6],
                               const double fpar[4]);
int px_lattice_cpu_rk4_stage_f32(struct px_lattice_cpu *e, const float *restrict ys,
                                 float *restrict yn, float *restrict y0, float *restrict acc,
                                 int stage, float dt, long r0, long r1);
int px_lattice_cpu_leapfrog_f32(struct px_lattice_cpu *e, const float *restrict ya,
                                float *restrict yb, float dt, long r0, long r1);
int px_lattice_cpu_pass_l1_f32(struct px_lattice_cpu *e, const float *restrict ys,
                               float *restrict yn, float *restrict y0, float *restrict acc,
                               int stage, float dt, long za, long zb);
int px_lattice_cpu_rk4_l1_f32(struct px_lattice_cpu *e, float *restrict y0, float *restrict ya,
                              float *restrict yb, float *restrict acc, const float *const tabs[3],
                              float dt);
long px_lattice_cpu_fracture_f32(struct px_lattice_cpu *e, const float *restrict y, long r0,
                                 long r1);
void px_lattice_cpu_vol_f32(struct px_lattice_cpu *e, const float *restrict y, long r0, long r1);
void px_lattice_cpu_fields_f32(struct px_lattice_cpu *e, const float *restrict y, double t_sync_dt,
                               const struct px_lattice_fields *f, int sums, long r0, long r1);

void px_lattice_cpu_params_f64(struct px_lattice_cpu *e, const double lpar[6],
                               const double fpar[4]);
int px_lattice_cpu_rk4_stage_f64(struct px_lattice_cpu *e, const double *restrict ys,
                                 double *restrict yn, double *restrict y0, double *restrict acc,
                                 int stage, double dt, long r0, long r1);
int px_lattice_cpu_leapfrog_f64(struct px_lattice_cpu *e, const double *restrict ya,
                                double *restrict yb, double dt, long r0, long r1);
int px_lattice_cpu_pass_l1_f64(struct px_lattice_cpu *e, const double *restrict ys,
                               double *restrict yn, double *restrict y0, double *restrict acc,
                               int stage, double dt, long za, long zb);
int px_lattice_cpu_rk4_l1_f64(struct px_lattice_cpu *e, double *restrict y0, double *restrict ya,
                              double *restrict yb, double *restrict acc,
                              const double *const tabs[3], double dt);
long px_lattice_cpu_fracture_f64(struct px_lattice_cpu *e, const double *restrict y, long r0,
                                 long r1);
void px_lattice_cpu_vol_f64(struct px_lattice_cpu *e, const double *restrict y, long r0, long r1);
void px_lattice_cpu_fields_f64(struct px_lattice_cpu *e, const double *restrict y, double t_sync_dt,
                               const struct px_lattice_fields *f, int sums, long r0, long r1);

#endif
