/* The lattice model on the host: body, material, link constants, boundary
 * conditions grouped per element, time functions, stability limit, and the
 * padded dense layout every engine (reference, cpu, opencl) shares.
 *
 * Layout. Element arrays cover the grid's bounding box densely: cell
 * (i, j, k) is at index pad + i + n0p (j + n1 k) (px_lattice_index), where
 * rows are padded to n0p = n0 rounded up to PX_LATTICE_ROW_ALIGN so that SIMD
 * loops run whole, aligned vectors; `pad` >= n0p n1 + n0p + 1 void entries
 * before and after make the six neighbours i +- 1, +- n0p, +- n0p n1 of any
 * cell valid indices. Void cells and padding hold group 0 (all DOFs fixed, no
 * load) and no links; their state stays at rest, so links to them can be
 * evaluated and multiplied by a 0 flag without producing non-finite values. */
#ifndef PX_LATTICE_MODEL_H
#define PX_LATTICE_MODEL_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "partix/status.h"
#include "solvers/lattice/lattice_grid.h"

/* Link flag bits of an element: bit a = link to the plus neighbour along
 * axis a (x, y, z) intact, bit 3 + a = link to the minus neighbour intact. */
#define PX_LATTICE_LINK_PLUS(a) (1u << (a))
#define PX_LATTICE_LINK_MINUS(a) (1u << (3 + (a)))

/* Reals per boundary-condition group (== LT_GROUP_STRIDE of the kernel). */
#define PX_LATTICE_GROUP_STRIDE 18
/* Group 0: void cells; group 1: free interior elements; 2..: BC sets. */
#define PX_LATTICE_MAX_GROUPS 256

enum px_lattice_tfun_kind {
  PX_LATTICE_TFUN_CONSTANT = 0, /* 1 */
  PX_LATTICE_TFUN_RAMP = 1,     /* 0 before t0, linear to 1 at t1, 1 after */
  PX_LATTICE_TFUN_HARMONIC = 2, /* sin(2 pi freq t + phase) */
  PX_LATTICE_TFUN_TABLE = 3     /* piecewise linear through (t[i], v[i]),
                                   constant beyond the ends */
};

/* A scalar function of time that scales a boundary value. */
struct px_lattice_tfun {
  enum px_lattice_tfun_kind kind;
  double t0, t1; /* ramp [s] */
  double freq;   /* harmonic [Hz] */
  double phase;  /* harmonic [rad] */
  size_t n;      /* table points */
  double *t, *v; /* table, owned by the model once built (px_mem) */
};

double px_lattice_tfun_eval(const struct px_lattice_tfun *f, double t);

/* A boundary condition on a selection. DOF order: ux uy uz rx ry rz (global
 * frame). Several BCs may touch one element: fixed masks combine with AND on
 * the free DOFs, accelerations and loads add. */
struct px_lattice_bc {
  struct px_lattice_sel sel;
  unsigned fix; /* bit k: DOF k fixed (zero acceleration) */
  int has_accel;
  double accel[6]; /* prescribed acceleration [m/s^2, rad/s^2],
                      added to every element, times accel_f(t) */
  struct px_lattice_tfun accel_f;
  int has_load;
  double load[6]; /* total force [N] and moment [N m] on the
                     set, spread equally, times load_f(t) */
  struct px_lattice_tfun load_f;
  const char *name; /* borrowed; for messages (case key path) */
};

struct px_lattice_params {
  double E;     /* Young's modulus [Pa] */
  double nu;    /* Poisson's ratio [-], in (-1, 0.5); 0: the springs alone
                   (docs/notes/lattice-poisson.md) */
  double rho;   /* density [kg/m^3] */
  double zeta;  /* link dashpot damping ratio [-] (0: none) */
  double alpha; /* global mass damping [1/s] (0: none) */
  /* bond strengths (0: that mode never breaks a bond) */
  double f_nc; /* normal force [N] */
  double f_tc; /* shear force [N] */
  double m_bc; /* bending moment [N m] */
  double m_tc; /* twisting moment [N m] */
};

enum px_lattice_integrator {
  PX_LATTICE_INTEGRATOR_RK4 = 0,     /* classic 4-stage Runge-Kutta */
  PX_LATTICE_INTEGRATOR_LEAPFROG = 1 /* symplectic kick-drift (velocity Verlet) */
};

struct px_lattice_model {
  struct px_lattice_grid grid; /* owned */
  struct px_lattice_params par;
  /* Derived constants (SI): mass, rotational inertia, link constants. */
  double m, I;              /* rho h^3, m h^2/6 */
  double k, cl, kb, kt, cr; /* see lattice_kernel.h */
  double lam;               /* Lame's lambda of the volumetric term [Pa]
                               (0 at nu = 0: no term) */
  int fracture;             /* 1 if any strength is given */
  /* Padded layout (see top). */
  size_t n0p;          /* padded row length */
  size_t pad, nalloc;  /* nalloc = n0p n1 n2 + 2 pad */
  ptrdiff_t stride[3]; /* 1, n0p, n0p n1 */
  uint8_t *links;      /* owned; nalloc; initial link flags */
  uint8_t *group;      /* owned; nalloc; group id per element */
  uint8_t *vfree;      /* owned; nalloc; 1: an element without a fixed DOF,
                          force or moment (a free face for the volumetric
                          term, lattice_kernel.h lt_vol_coef); 0: held or void */
  size_t ngroup;
  /* Boundary conditions (owned copies; table arrays owned) and, per group,
   * the set of BCs that apply. */
  struct px_lattice_bc *bc;
  size_t nbc;
  size_t *bc_count;    /* elements per BC */
  uint64_t *group_bcs; /* ngroup bitsets over BCs (<= 64 BCs) */
  int window;          /* a window of another model (px_lattice_model_window):
                          bc, bc_count and group_bcs are borrowed */
};

/* Build the model; takes ownership of `grid` (also on failure) and copies
 * `bcs` (including table arrays). Errors (PX_STATUS_CONFIG): E or rho <= 0,
 * negative damping or strengths, a disconnected body, a BC selection that
 * matches nothing ("bc NAME: ..."), more than 64 BCs or 254 distinct BC
 * combinations. */
enum px_status px_lattice_model_build(struct px_context *ctx, struct px_lattice_model *m,
                                      struct px_lattice_grid *grid,
                                      const struct px_lattice_params *par,
                                      const struct px_lattice_bc *bcs, size_t nbc);
void px_lattice_model_free(struct px_context *ctx, struct px_lattice_model *m);
/* The model of one rank's window of the grid of m (lattice_ranks.c): the
 * cells (i, j, k) with j in [box[0], box[1]) and k in [box[2], box[3]), x
 * whole, in a padded layout of their own (cell (i, j - box[0], k - box[2])
 * of a grid of n[0] x (box[1] - box[0]) x (box[3] - box[2]) cells whose
 * origin is that cell's corner). The constants, occupancy, groups and free
 * flags are m's; the link flags too, except the links that leave the
 * window (their far end is not there: a window's edge cells are halo,
 * which the rank never updates). The BCs and the per-BC element counts are
 * borrowed from m (the loads spread over the whole body's elements), so m
 * must outlive w; free w with px_lattice_model_free. */
enum px_status px_lattice_model_window(struct px_context *ctx, const struct px_lattice_model *m,
                                       const long box[4], struct px_lattice_model *w);
/* The link flag bits of the window w's row (j, k) (from its corner) whose
 * links leave the window: cleared in its model. */
unsigned px_lattice_window_out(const struct px_lattice_model *w, size_t j, size_t k);

/* The group table at time t: ngroup x PX_LATTICE_GROUP_STRIDE reals
 * (mask[6] | acc[6] | load per element[6]). */
void px_lattice_model_groups(const struct px_lattice_model *m, double t, double *table);
/* 1 if the group table depends on time. */
int px_lattice_model_time_dependent(const struct px_lattice_model *m);
/* The time from which the loads and prescribed accelerations stay constant
 * [s]: 0 for constant ones, the end of the last ramp or table, INFINITY
 * with a harmonic one. A static state exists only after it. */
double px_lattice_model_settle_time(const struct px_lattice_model *m);

/* Largest stable time step [s] of an integrator for this model:
 * (stability radius on the imaginary axis, reduced for damping) / omega_max,
 * omega_max = 3.74 c/h (c = sqrt(E/rho)) the highest natural frequency of the
 * lattice with k_b = E h^3/12 (research/lattice.md section 2; checked by
 * tests/lattice for finite bodies). */
/* Factor (>= 1) by which the highest natural frequency exceeds that of the
 * nu = 0 lattice, omega_max = 3.74 c/h: a bound from the springs' 1/(1+nu)
 * and the volumetric term (exactly 1 at nu = 0). */
double px_lattice_model_stiffen(const struct px_lattice_model *m);
double px_lattice_model_dt_limit(const struct px_lattice_model *m,
                                 enum px_lattice_integrator integ);
/* Default safety factor applied to the limit when the case gives no dt. */
#define PX_LATTICE_DT_SAFETY 0.9

/* Row padding of the dense layout (elements; a multiple of every SIMD width
 * used: 16 floats in 64 bytes). */
#define PX_LATTICE_ROW_ALIGN 16

/* The padded layout (see top) of a grid, known before the model is built:
 * what the memory estimate (lattice.c) and px_lattice_model_build share. */
struct px_lattice_layout {
  int n[3];      /* cells per axis */
  size_t ncell;  /* n[0] n[1] n[2] */
  size_t n0p;    /* padded row length */
  size_t pad;    /* void entries before and after the grid */
  size_t nalloc; /* n0p n[1] n[2] + 2 pad */
};

/* The layout of a grid of n[0] x n[1] x n[2] cells. With the counts of a
 * planned grid (px_lattice_grid_plan: ncell < 2^31) nothing overflows:
 * nalloc < 16 ncell + 2 pad < 2^37. */
void px_lattice_model_layout(const int n[3], struct px_lattice_layout *lay);

/* Index in the padded layout of grid cell c. */
static inline size_t px_lattice_index(const struct px_lattice_model *m, size_t c) {
  size_t n0 = (size_t)m->grid.n[0];
  return m->pad + c % n0 + m->n0p * (c / n0);
}

#endif
