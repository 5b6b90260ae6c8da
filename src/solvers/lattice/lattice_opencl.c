/* The opencl lattice engine: the whole state lives in device buffers; the
 * host sends only the small boundary-condition table (when it depends on
 * time) and reads the state only for outputs, checkpoints and the few
 * scalars a step needs (a blow-up flag every PX_LATTICE_OCL_CHECK steps, the
 * Rayleigh sums of the quasi-static relaxation, the broken-link counter).
 * Kernels: lattice.cl. Compiled only with the opencl backend (CMakeLists.txt;
 * lattice.c lists the engine with PX_IF_OPENCL). */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/lattice/lattice_opencl.h"
#include "solvers/lattice/lattice_ref.h"

extern const char px_cl_source_lattice[];

static void px_lattice_ocl_destroy(void *p) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  int b;
  if (!e) return;
  for (b = 0; b < 4; ++b) px_buffer_free(e->buf[b]);
  px_buffer_free(e->lp);
  px_buffer_free(e->lm);
  px_buffer_free(e->lk);
  px_buffer_free(e->pv);
  px_buffer_free(e->fr);
  px_buffer_free(e->vf);
  px_buffer_free(e->grp);
  px_buffer_free(e->list);
  px_buffer_free(e->tab);
  px_buffer_free(e->bad);
  px_buffer_free(e->ends);
  px_buffer_free(e->out);
  px_buffer_free(e->rowbuf);
  px_mem_free(e->ctx, e->rowsum);
  px_mem_free(e->ctx, e->rowh);
  px_mem_free(e->ctx, e->mirror);
  px_mem_free(e->ctx, e->table_d);
  px_mem_free(e->ctx, e->table);
  px_mem_free(e->ctx, e);
}

/* The launch constants LT_PARAMS of lattice.cl (the first 14 arguments of
 * every kernel) with n work items. */
static void px_lattice_ocl_params(struct px_lattice_ocl *e, struct px_opencl_args *a, cl_uint n) {
  const struct px_lattice_model *m = e->m;
  struct lt_lpar p;
  px_lattice_lpar_d(m, &p);
  px_opencl_args_u32(a, "n", n);
  px_opencl_args_u32(a, "pad", e->at);
  px_opencl_args_u32(a, "ns", e->ns);
  px_opencl_args_u32(a, "s1", e->s1);
  px_opencl_args_u32(a, "s2", e->s2);
  px_opencl_args_real(a, "h2", p.h2);          /* [m] */
  px_opencl_args_real(a, "k", p.k);            /* [N/m] */
  px_opencl_args_real(a, "cl", p.cl);          /* [N s/m] */
  px_opencl_args_real(a, "kb", p.kb);          /* [N m] */
  px_opencl_args_real(a, "dk", p.dk);          /* [N m] */
  px_opencl_args_real(a, "cr", p.cr);          /* [N m s] */
  px_opencl_args_real(a, "inv_m", 1.0 / m->m); /* [1/kg] */
  px_opencl_args_real(a, "inv_i", 1.0 / m->I); /* [1/(kg m^2)] */
  px_opencl_args_real(a, "alpha", e->alpha);   /* [1/s] */
}

/* Kernel `name` with its launch constants bound (n work items). */
enum px_status px_lattice_ocl_begin(struct px_lattice_ocl *e, const char *name, cl_uint n,
                                    struct px_opencl_args *a) {
  cl_kernel k;
  PX_TRY(px_opencl_kernel(e->be, e->prog, name, &k));
  px_opencl_args_begin(a, e->be, k);
  px_lattice_ocl_params(e, a, n);
  return PX_STATUS_OK;
}

/* Group table for time t, uploaded when it changed. */
enum px_status px_lattice_ocl_table(struct px_lattice_ocl *e, double t, int force) {
  size_t n = e->m->ngroup * PX_LATTICE_GROUP_STRIDE, i;
  if (!force && (!e->table_tdep || t == e->table_t)) return PX_STATUS_OK;
  px_lattice_model_groups(e->m, t, e->table_d);
  for (i = 0; i < n; ++i) {
    if (e->prec == PX_PRECISION_DOUBLE)
      ((double *)e->table)[i] = e->table_d[i];
    else
      ((float *)e->table)[i] = (float)e->table_d[i];
  }
  e->table_t = t;
  return px_buffer_write(e->tab, 0, n * e->real, e->table);
}

static enum px_status px_lattice_ocl_upload_state(struct px_lattice_ocl *e, struct px_buffer *b,
                                                  const struct lt_el *y) {
  size_t ns = e->ns, i, bytes = PX_LATTICE_NCOMP * ns * e->real;
  void *h = px_mem_alloc(e->ctx, "lattice.ocl.host", bytes);
  enum px_status st;
  if (!h) return PX_STATUS_NOMEM;
  memset(h, 0, bytes);
  for (i = 0; i < ns; ++i) {
    double c[PX_LATTICE_NCOMP];
    int k;
    if (i < e->m->nalloc) {
      const struct lt_el *x = &y[i];
      c[0] = x->u.x, c[1] = x->u.y, c[2] = x->u.z, c[3] = x->q.w, c[4] = x->q.x, c[5] = x->q.y;
      c[6] = x->q.z, c[7] = x->v.x, c[8] = x->v.y, c[9] = x->v.z, c[10] = x->W.x;
      c[11] = x->W.y, c[12] = x->W.z;
    } else {
      memset(c, 0, sizeof c);
      c[3] = 1.0;
    }
    for (k = 0; k < PX_LATTICE_NCOMP; ++k) {
      if (e->prec == PX_PRECISION_DOUBLE)
        ((double *)h)[(size_t)k * ns + i] = c[k];
      else
        ((float *)h)[(size_t)k * ns + i] = (float)c[k];
    }
  }
  st = px_buffer_write(b, 0, bytes, h);
  px_mem_free(e->ctx, h);
  return st;
}

struct px_buffer *px_lattice_ocl_state(struct px_lattice_ocl *e) {
  return e->integ == PX_LATTICE_INTEGRATOR_RK4 ? e->buf[0] : e->buf[e->cur];
}

/* Most padded elements the kernels can index: they address component c of
 * element i as c ns + i in 32-bit uint, c < 18 (the link-once results; 13
 * state components), so 18 ns must stay below 2^32 (ns = nalloc rounded up
 * to 16). */
#define PX_LATTICE_OCL_NALLOC_MAX (((size_t)0xffffffffu / 18) & ~(size_t)15)

/* The blow-up flags at "nothing yet" (lt_flag: first step, 4 i + what). */
static enum px_status px_lattice_ocl_flags_reset(struct px_lattice_ocl *e) {
  cl_int none[2] = {INT_MAX, INT_MAX};
  return px_buffer_write(e->bad, 0, sizeof none, none);
}

/* Every device buffer and host transient of px_lattice_ocl_create and of
 * the state transfers (get/set: one host copy of a state buffer), from the
 * layout; the device's memory and largest allocation from the backend. */
static void px_lattice_ocl_need(const struct px_lattice_layout *lay,
                                const struct px_lattice_engine_opts *o,
                                struct px_lattice_need *need) {
  double real = o->precision == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  double ns = (double)((lay->nalloc + 15) & ~(size_t)15);
  double nbuf = o->integ == PX_LATTICE_INTEGRATOR_RK4 ? 4 : 2;
  double n = (double)lay->n0p * (double)lay->n[1] * (double)lay->n[2];
  double rows = (double)lay->n[1] * (double)lay->n[2];
  int l1 = o->scheme == PX_LATTICE_SCHEME_LINK_ONCE;
  memset(need, 0, sizeof *need);
  need->scheme = l1 ? PX_LATTICE_SCHEME_LINK_ONCE : PX_LATTICE_SCHEME_GATHER;
  /* state buffers, lp lm free group, link-once results, the bc list (at
   * most every cell), the fields output, the Rayleigh sums per row; nu !=
   * 0: the coefficients P_a and the vfree bytes */
  need->device = nbuf * PX_LATTICE_NCOMP * ns * real + 4.0 * (double)lay->nalloc +
                 (l1 ? 18.0 * ns * real : 0.0) + 4.0 * (double)lay->ncell +
                 PX_LATTICE_NCOMP * n * real + 3.0 * rows * real +
                 (o->vol ? 3.0 * ns * real + (double)lay->nalloc : 0.0);
  need->buffer = (l1 ? 18.0 : (double)PX_LATTICE_NCOMP) * ns * real;
  /* create: the rest state in double, a byte per element, one upload; on
   * a block, a host copy of a state buffer (its edge and halo planes); the
   * Rayleigh sums per row in device reals and in double */
  need->host = (double)lay->nalloc * (sizeof(struct lt_el) + 1) +
               2.0 * PX_LATTICE_NCOMP * ns * real + 3.0 * rows * (real + sizeof(double));
  need->nalloc_max = (double)PX_LATTICE_OCL_NALLOC_MAX;
  need->index_why = "the OpenCL kernels index elements with 32-bit integers";
  if (o->backend) {
    px_opencl_memory(o->backend, &need->device_have, &need->buffer_max);
  }
}

static enum px_status px_lattice_ocl_create(struct px_context *ctx,
                                            const struct px_lattice_model *m,
                                            const struct px_lattice_engine_opts *o, void **out) {
  struct px_lattice_ocl *e;
  struct lt_el *rest = NULL;
  size_t i, ngr;
  uint8_t *tmp = NULL;
  cl_uint *list = NULL;
  enum px_status st = PX_STATUS_OK;
  int b, zero = 0;
  if (!o->backend)
    return px_context_fail(ctx, PX_STATUS_INVALID, "the opencl lattice engine needs a backend");
  if (m->nalloc > PX_LATTICE_OCL_NALLOC_MAX)
    return px_context_fail(ctx, PX_STATUS_UNSUPPORTED,
                           "the body's grid (%zu cells with padding) is too large for 32-bit "
                           "device indices (at most %zu)",
                           m->nalloc, PX_LATTICE_OCL_NALLOC_MAX);
  e = (struct px_lattice_ocl *)px_mem_calloc(ctx, "lattice.ocl", 1, sizeof *e);
  if (!e) return PX_STATUS_NOMEM;
  e->ctx = ctx;
  e->m = m;
  e->be = o->backend;
  e->integ = o->integ;
  e->prec = o->precision == PX_PRECISION_DOUBLE ? PX_PRECISION_DOUBLE : PX_PRECISION_SINGLE;
  e->real = e->prec == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  e->alpha = m->par.alpha;
  e->nbuf = o->integ == PX_LATTICE_INTEGRATOR_RK4 ? 4 : 2;
  e->ns = (cl_uint)((m->nalloc + 15) & ~(size_t)15);
  e->pad = (cl_uint)m->pad;
  e->n = (cl_uint)(m->n0p * (size_t)m->grid.n[1] * (size_t)m->grid.n[2]);
  e->s1 = (cl_uint)m->stride[1];
  e->s2 = (cl_uint)m->stride[2];
  e->at = e->pad;
  e->cnt = e->n;
  ngr = m->ngroup * PX_LATTICE_GROUP_STRIDE;
  if ((st = px_opencl_program_real(e->be, "lattice", px_cl_source_lattice, e->prec, "",
                                   &e->prog)) != PX_STATUS_OK)
    goto fail;
  for (b = 0; b < e->nbuf && st == PX_STATUS_OK; ++b)
    st = px_buffer_create(e->be, "lattice.state", PX_LATTICE_NCOMP * (size_t)e->ns * e->real,
                          &e->buf[b]);
  if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.links", m->nalloc, &e->lp);
  if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.links", m->nalloc, &e->lm);
  if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.free", m->nalloc, &e->fr);
  if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.group", m->nalloc, &e->grp);
  if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.table", ngr * e->real, &e->tab);
  if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.flags", 2 * sizeof(int), &e->bad);
  if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.flags", sizeof(int), &e->ends);
  /* link-once only when asked for: auto keeps the gather form on devices
   * (docs/lattice.md: measured on POCL's cpu device; no GPU was available) */
  e->l1 = o->scheme == PX_LATTICE_SCHEME_LINK_ONCE;
  if (st == PX_STATUS_OK && e->l1)
    st = px_buffer_create(e->be, "lattice.links", 18 * (size_t)e->ns * e->real, &e->lk);
  if (st == PX_STATUS_OK && m->lam != 0.0) {
    st = px_buffer_create(e->be, "lattice.volumetric", 3 * (size_t)e->ns * e->real, &e->pv);
    if (st == PX_STATUS_OK) st = px_buffer_create(e->be, "lattice.free", m->nalloc, &e->vf);
    if (st == PX_STATUS_OK) st = px_buffer_write(e->vf, 0, m->nalloc, m->vfree);
    e->lh2 = m->lam * m->grid.h * m->grid.h;
  }
  if (st != PX_STATUS_OK) goto fail;
  e->table_d = (double *)px_mem_alloc(ctx, "lattice.ocl", ngr * sizeof(double));
  e->table = px_mem_alloc(ctx, "lattice.ocl", ngr * e->real);
  rest = (struct lt_el *)px_mem_calloc(ctx, "lattice.ocl", m->nalloc, sizeof *rest);
  tmp = (uint8_t *)px_mem_alloc(ctx, "lattice.ocl", m->nalloc);
  if (!e->table_d || !e->table || !rest || !tmp) {
    st = PX_STATUS_NOMEM;
    goto fail;
  }
  for (i = 0; i < m->nalloc; ++i) rest[i].q.w = 1.0;
  for (b = 0; b < e->nbuf && st == PX_STATUS_OK; ++b)
    st = px_lattice_ocl_upload_state(e, e->buf[b], rest);
  for (i = 0; i < m->nalloc; ++i) tmp[i] = m->links[i] & 7u;
  if (st == PX_STATUS_OK) st = px_buffer_write(e->lp, 0, m->nalloc, tmp);
  for (i = 0; i < m->nalloc; ++i) tmp[i] = m->links[i] & 56u;
  if (st == PX_STATUS_OK) st = px_buffer_write(e->lm, 0, m->nalloc, tmp);
  for (i = 0; i < m->nalloc; ++i) {
    tmp[i] = m->group[i] <= 1;
    e->nbc += m->group[i] > 1;
  }
  if (st == PX_STATUS_OK) st = px_buffer_write(e->fr, 0, m->nalloc, tmp);
  if (st == PX_STATUS_OK) st = px_buffer_write(e->grp, 0, m->nalloc, m->group);
  if (st == PX_STATUS_OK && e->l1) { /* padding entries are read as links of value 0 */
    void *z = px_mem_calloc(ctx, "lattice.ocl", 18 * (size_t)e->ns, e->real);
    st = z ? px_buffer_write(e->lk, 0, 18 * (size_t)e->ns * e->real, z) : PX_STATUS_NOMEM;
    px_mem_free(ctx, z);
  }
  if (st == PX_STATUS_OK && e->pv) { /* padding and void cells: P = 0, read as links of flag 0 */
    void *z = px_mem_calloc(ctx, "lattice.ocl", 3 * (size_t)e->ns, e->real);
    st = z ? px_buffer_write(e->pv, 0, 3 * (size_t)e->ns * e->real, z) : PX_STATUS_NOMEM;
    px_mem_free(ctx, z);
  }
  if (st == PX_STATUS_OK) st = px_lattice_ocl_flags_reset(e);
  if (st == PX_STATUS_OK) st = px_buffer_write(e->ends, 0, sizeof zero, &zero);
  if (st != PX_STATUS_OK) goto fail;
  list = (cl_uint *)px_mem_alloc(ctx, "lattice.ocl", (e->nbc ? e->nbc : 1) * sizeof *list);
  if (!list) {
    st = PX_STATUS_NOMEM;
    goto fail;
  }
  e->nbc = 0;
  for (i = 0; i < m->nalloc; ++i)
    if (m->group[i] > 1) list[e->nbc++] = (cl_uint)i;
  if ((st = px_buffer_create(e->be, "lattice.bc", (e->nbc ? e->nbc : 1) * sizeof *list,
                             &e->list)) != PX_STATUS_OK ||
      (e->nbc && (st = px_buffer_write(e->list, 0, e->nbc * sizeof *list, list)) != PX_STATUS_OK))
    goto fail;
  e->table_tdep = px_lattice_model_time_dependent(m);
  if ((st = px_lattice_ocl_table(e, 0.0, 1)) != PX_STATUS_OK) goto fail;
  px_mem_free(ctx, rest);
  px_mem_free(ctx, tmp);
  px_mem_free(ctx, list);
  *out = e;
  return PX_STATUS_OK;
fail:
  px_mem_free(ctx, rest);
  px_mem_free(ctx, tmp);
  px_mem_free(ctx, list);
  px_lattice_ocl_destroy(e);
  return st;
}

/* Read the blow-up flag; on a hit, locate the element on the host. */
enum px_status px_lattice_ocl_check(struct px_lattice_ocl *e, long step) {
  static const char *const what[4] = {"displacement", "velocity", "angular velocity",
                                      "orientation"};
  const struct px_lattice_model *m = e->m;
  cl_int bad[2];
  long k0, nchecked = e->unchecked;
  size_t i, x, r, n0 = (size_t)m->grid.n[0], n1 = (size_t)m->grid.n[1];
  double c[3];
  PX_TRY(px_buffer_read(e->bad, 0, sizeof bad, bad));
  e->unchecked = 0;
  if (bad[0] == INT_MAX) return PX_STATUS_OK;
  /* bad[0] in [1, nchecked] (lt_flag); bad[1] = 4 i + what, i an entry of
   * the padded layout */
  k0 = bad[0] >= 1 && bad[0] <= nchecked ? e->first_unchecked + bad[0] - 1 : step;
  i = (size_t)bad[1] / 4;
  if (bad[1] < 0 || i < m->pad || i >= m->nalloc - m->pad)
    return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                           "the lattice state became non-finite at step %ld (found on the "
                           "device after step %ld; no element recorded)",
                           k0, step);
  x = (i - m->pad) % m->n0p;
  r = (i - m->pad) / m->n0p;
  c[0] = m->grid.origin[0] + ((double)x + 0.5) * m->grid.h;
  c[1] = m->grid.origin[1] + ((double)(r % n1) + 0.5) * m->grid.h;
  c[2] = m->grid.origin[2] + ((double)(r / n1) + 0.5) * m->grid.h;
  (void)n0;
  return px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                         "the %s of element (%zu, %zu, %zu) at (%g, %g, %g) m became non-finite "
                         "at step %ld (t = %.9g s) (time step too large for the "
                         "damping/stiffness, or an unbounded load; the device's flags are read "
                         "every %d steps, here after step %ld)",
                         what[bad[1] % 4], x, r % n1, r / n1, c[0], c[1], c[2], k0,
                         bad[0] >= 1 && bad[0] <= nchecked ? e->t_end[bad[0] - 1] : NAN,
                         PX_LATTICE_OCL_CHECK, step);
}

/* Read the flags of steps run since the last check, before the state is
 * used (outputs, checkpoints): a blow-up of the last steps of a run is
 * reported, not written. */
static enum px_status px_lattice_ocl_pending(struct px_lattice_ocl *e) {
  if (e->unchecked == 0) return PX_STATUS_OK;
  return px_lattice_ocl_check(e, e->first_unchecked + e->unchecked - 1);
}

enum px_status px_lattice_ocl_fracture(struct px_lattice_ocl *e, struct px_buffer *y) {
  struct px_opencl_args a;
  struct lt_fpar f;
  px_lattice_fpar_d(e->m, &f);
  PX_TRY(px_lattice_ocl_begin(e, "lt_fracture", e->cnt, &a));
  px_opencl_args_mem(&a, "y", y);
  px_opencl_args_mem(&a, "lpv", e->lp);
  px_opencl_args_mem(&a, "lmv", e->lm);
  px_opencl_args_real(&a, "ifn", f.ifn); /* [1/N] */
  px_opencl_args_real(&a, "ift", f.ift); /* [1/N] */
  px_opencl_args_real(&a, "imb", f.imb); /* [1/(N m)] */
  px_opencl_args_real(&a, "imt", f.imt); /* [1/(N m)] */
  px_opencl_args_mem(&a, "ends", e->ends);
  return px_opencl_args_launch(&a, e->cnt, 0);
}

/* The last two arguments of the kernels that evaluate link forces: the
 * volumetric flag and coefficients (any buffer at nu = 0: not read). */
static void px_lattice_ocl_vol_args(struct px_lattice_ocl *e, struct px_opencl_args *a) {
  px_opencl_args_i32(a, "vol", e->pv != NULL);
  px_opencl_args_mem(a, "pv", e->pv ? e->pv : e->tab);
}

/* Link-once: every link of state y evaluated once into lk (lattice.cl
 * lt_links), with the P term of pv; queued before the stage kernels that
 * read it. */
enum px_status px_lattice_ocl_links(struct px_lattice_ocl *e, struct px_buffer *y) {
  struct px_opencl_args a;
  PX_TRY(px_lattice_ocl_begin(e, "lt_links", e->cnt, &a));
  px_opencl_args_mem(&a, "y", y);
  px_opencl_args_mem(&a, "lpv", e->lp);
  px_opencl_args_mem(&a, "lk", e->lk);
  px_lattice_ocl_vol_args(e, &a);
  return px_opencl_args_launch(&a, e->cnt, 0);
}

enum px_status px_lattice_ocl_vol(struct px_lattice_ocl *e, struct px_buffer *y) {
  struct px_opencl_args a;
  if (!e->pv) return PX_STATUS_OK;
  PX_TRY(px_lattice_ocl_begin(e, "lt_vol", e->cnt, &a));
  px_opencl_args_mem(&a, "y", y);
  px_opencl_args_mem(&a, "lpv", e->lp);
  px_opencl_args_mem(&a, "lmv", e->lm);
  px_opencl_args_mem(&a, "vfv", e->vf);
  px_opencl_args_real(&a, "lh2", e->lh2); /* [N] */
  px_opencl_args_mem(&a, "pv", e->pv);
  return px_opencl_args_launch(&a, e->cnt, 0);
}

/* The last arguments of the stage kernels: the blow-up flags, the scheme,
 * the link results (any buffer when gathering: not read), this step's
 * number for lt_flag and the volumetric term. */
static void px_lattice_ocl_tail(struct px_lattice_ocl *e, struct px_opencl_args *a, cl_int kstep) {
  px_opencl_args_mem(a, "bad", e->bad);
  px_opencl_args_i32(a, "l1", e->l1);
  px_opencl_args_mem(a, "lk", e->l1 ? e->lk : e->tab);
  px_opencl_args_i32(a, "kstep", kstep);
  px_lattice_ocl_vol_args(e, a);
}

/* The elements with boundary conditions and their group rows (the *_bc
 * kernels). */
static void px_lattice_ocl_bc_args(struct px_lattice_ocl *e, struct px_opencl_args *a) {
  px_opencl_args_mem(a, "list", e->list);
  px_opencl_args_mem(a, "grp", e->grp);
  px_opencl_args_mem(a, "tab", e->tab);
}

/* One RK4 stage kernel (bc = 0: every element; 1: the boundary-condition
 * list): stage state ys, next stage state yn, cs the stage's step [s]. */
enum px_status px_lattice_ocl_rk4_stage(struct px_lattice_ocl *e, int bc, int stage,
                                        struct px_buffer *ys, struct px_buffer *yn, double cs,
                                        double dt, cl_int kstep) {
  struct px_opencl_args a;
  const cl_uint n = bc ? e->nbc : e->cnt;
  PX_TRY(px_lattice_ocl_begin(e, bc ? "lt_rk4_bc" : "lt_rk4_stage", n, &a));
  px_opencl_args_mem(&a, "ys", ys);
  px_opencl_args_mem(&a, "yn", yn);
  px_opencl_args_mem(&a, "y0", e->buf[0]);
  px_opencl_args_mem(&a, "acc", e->buf[3]);
  px_opencl_args_mem(&a, "lpv", e->lp);
  px_opencl_args_mem(&a, "lmv", e->lm);
  if (bc)
    px_lattice_ocl_bc_args(e, &a);
  else
    px_opencl_args_mem(&a, "frv", e->fr);
  px_opencl_args_real(&a, "cs", cs);        /* [s] */
  px_opencl_args_real(&a, "dt6", dt / 6.0); /* [s] */
  px_opencl_args_i32(&a, "stage", stage);
  px_lattice_ocl_tail(e, &a, kstep);
  return px_opencl_args_launch(&a, n, 0);
}

static enum px_status px_lattice_ocl_rk4(struct px_lattice_ocl *e, double t, double dt) {
  static const double cst[4] = {0.0, 0.5, 0.5, 1.0};
  cl_int kstep = (cl_int)e->unchecked + 1; /* this step's number for lt_flag */
  int s;
  if (e->m->fracture) PX_TRY(px_lattice_ocl_fracture(e, e->buf[0]));
  for (s = 0; s < 4; ++s) {
    struct px_buffer *ys = s == 0 ? e->buf[0] : (s == 2 ? e->buf[2] : e->buf[1]);
    struct px_buffer *yn = s == 1 ? e->buf[2] : e->buf[1];
    double cs = s == 2 ? dt : 0.5 * dt;
    PX_TRY(px_lattice_ocl_table(e, t + cst[s] * dt, 0));
    PX_TRY(px_lattice_ocl_vol(e, ys));
    if (e->l1) PX_TRY(px_lattice_ocl_links(e, ys));
    PX_TRY(px_lattice_ocl_rk4_stage(e, 0, s, ys, yn, cs, dt, kstep));
    if (e->nbc) PX_TRY(px_lattice_ocl_rk4_stage(e, 1, s, ys, yn, cs, dt, kstep));
  }
  return PX_STATUS_OK;
}

/* One leapfrog kernel (bc as for px_lattice_ocl_rk4_stage): ya -> yb. */
enum px_status px_lattice_ocl_lf_kernel(struct px_lattice_ocl *e, int bc, struct px_buffer *ya,
                                        struct px_buffer *yb, double dt, cl_int kstep) {
  struct px_opencl_args a;
  const cl_uint n = bc ? e->nbc : e->cnt;
  PX_TRY(px_lattice_ocl_begin(e, bc ? "lt_leapfrog_bc" : "lt_leapfrog", n, &a));
  px_opencl_args_mem(&a, "ya", ya);
  px_opencl_args_mem(&a, "yb", yb);
  px_opencl_args_mem(&a, "lpv", e->lp);
  px_opencl_args_mem(&a, "lmv", e->lm);
  if (bc) px_lattice_ocl_bc_args(e, &a);
  px_opencl_args_real(&a, "had", 0.5 * e->alpha * dt); /* alpha dt/2 [1] */
  px_opencl_args_real(&a, "dt", dt);                   /* [s] */
  px_lattice_ocl_tail(e, &a, kstep);
  return px_opencl_args_launch(&a, n, 0);
}

static enum px_status px_lattice_ocl_leapfrog(struct px_lattice_ocl *e, double t, double dt) {
  cl_int kstep = (cl_int)e->unchecked + 1; /* this step's number for lt_flag */
  struct px_buffer *ya = e->buf[e->cur], *yb = e->buf[1 - e->cur];
  if (e->m->fracture) PX_TRY(px_lattice_ocl_fracture(e, ya));
  PX_TRY(px_lattice_ocl_table(e, t, 0));
  PX_TRY(px_lattice_ocl_vol(e, ya));
  if (e->l1) PX_TRY(px_lattice_ocl_links(e, ya));
  PX_TRY(px_lattice_ocl_lf_kernel(e, 0, ya, yb, dt, kstep));
  if (e->nbc) PX_TRY(px_lattice_ocl_lf_kernel(e, 1, ya, yb, dt, kstep));
  e->cur = 1 - e->cur;
  return PX_STATUS_OK;
}

static enum px_status px_lattice_ocl_run(void *p, long step, double t, double dt, long n) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  long s;
  if (e->has_blk) return px_lattice_ocl_run_blk(e, step, t, dt, n);
  for (s = 0; s < n; ++s) {
    double ts = t + (double)s * dt;
    if (e->unchecked == 0) e->first_unchecked = step + s + 1;
    if (e->integ == PX_LATTICE_INTEGRATOR_RK4)
      PX_TRY(px_lattice_ocl_rk4(e, ts, dt));
    else
      PX_TRY(px_lattice_ocl_leapfrog(e, ts, dt));
    e->t_end[e->unchecked] = ts + dt;
    if (++e->unchecked >= PX_LATTICE_OCL_CHECK) PX_TRY(px_lattice_ocl_check(e, step + s + 1));
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_ocl_get(void *p, struct lt_el *y, uint8_t *links) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  const struct px_lattice_model *m = e->m;
  size_t ns = e->ns, i;
  if (y) {
    size_t bytes = PX_LATTICE_NCOMP * ns * e->real;
    PX_TRY(px_lattice_ocl_pending(e));
    void *h = px_mem_alloc(e->ctx, "lattice.ocl.host", bytes);
    enum px_status st;
    if (!h) return PX_STATUS_NOMEM;
    st = px_buffer_read(px_lattice_ocl_state(e), 0, bytes, h);
    if (st != PX_STATUS_OK) {
      px_mem_free(e->ctx, h);
      return st;
    }
    for (i = 0; i < m->nalloc; ++i) {
      double c[PX_LATTICE_NCOMP];
      int k;
      for (k = 0; k < PX_LATTICE_NCOMP; ++k)
        c[k] = e->prec == PX_PRECISION_DOUBLE ? ((double *)h)[(size_t)k * ns + i]
                                              : (double)((float *)h)[(size_t)k * ns + i];
      y[i].u = lt_v3_make(c[0], c[1], c[2]);
      y[i].q.w = c[3];
      y[i].q.x = c[4];
      y[i].q.y = c[5];
      y[i].q.z = c[6];
      y[i].v = lt_v3_make(c[7], c[8], c[9]);
      y[i].W = lt_v3_make(c[10], c[11], c[12]);
    }
    px_mem_free(e->ctx, h);
  }
  if (links) {
    uint8_t *tmp = (uint8_t *)px_mem_alloc(e->ctx, "lattice.ocl.host", m->nalloc);
    enum px_status st;
    if (!tmp) return PX_STATUS_NOMEM;
    st = px_buffer_read(e->lp, 0, m->nalloc, links);
    if (st == PX_STATUS_OK) st = px_buffer_read(e->lm, 0, m->nalloc, tmp);
    for (i = 0; st == PX_STATUS_OK && i < m->nalloc; ++i) links[i] = (uint8_t)(links[i] | tmp[i]);
    px_mem_free(e->ctx, tmp);
    PX_TRY(st);
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_ocl_set(void *p, const struct lt_el *y, const uint8_t *links) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  const struct px_lattice_model *m = e->m;
  if (y) PX_TRY(px_lattice_ocl_upload_state(e, px_lattice_ocl_state(e), y));
  if (links) {
    uint8_t *tmp = (uint8_t *)px_mem_alloc(e->ctx, "lattice.ocl.host", m->nalloc);
    size_t i;
    enum px_status st;
    if (!tmp) return PX_STATUS_NOMEM;
    for (i = 0; i < m->nalloc; ++i) tmp[i] = links[i] & 7u;
    st = px_buffer_write(e->lp, 0, m->nalloc, tmp);
    for (i = 0; i < m->nalloc; ++i) tmp[i] = links[i] & 56u;
    if (st == PX_STATUS_OK) st = px_buffer_write(e->lm, 0, m->nalloc, tmp);
    px_mem_free(e->ctx, tmp);
    PX_TRY(st);
  }
  return PX_STATUS_OK;
}

/* Run the field kernel; out holds 13 x n reals. */
static enum px_status px_lattice_ocl_run_fields(struct px_lattice_ocl *e, double half_dt) {
  struct px_opencl_args a;
  if (!e->out)
    PX_TRY(px_buffer_create(e->be, "lattice.fields", 13 * (size_t)e->n * e->real, &e->out));
  /* on a block: its halo current first (the last update wrote own rows
   * only); the coefficients of the halo come from their owners */
  if (e->has_blk)
    PX_TRY(px_lattice_ocl_blk_current(e));
  else
    PX_TRY(px_lattice_ocl_vol(e, px_lattice_ocl_state(e)));
  PX_TRY(px_lattice_ocl_begin(e, "lt_fields", e->n, &a));
  px_opencl_args_mem(&a, "y", px_lattice_ocl_state(e));
  px_opencl_args_mem(&a, "lpv", e->lp);
  px_opencl_args_mem(&a, "lmv", e->lm);
  px_opencl_args_mem(&a, "grp", e->grp);
  px_opencl_args_mem(&a, "tab", e->tab);
  px_opencl_args_i32(&a, "sync", e->integ == PX_LATTICE_INTEGRATOR_LEAPFROG);
  px_opencl_args_real(&a, "half_dt", half_dt); /* [s] */
  px_opencl_args_mem(&a, "out", e->out);
  px_lattice_ocl_vol_args(e, &a);
  return px_opencl_args_launch(&a, e->n, PX_LATTICE_OCL_WG);
}

static enum px_status px_lattice_ocl_fields(void *p, double t, double dt,
                                            const struct px_lattice_fields *f) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  const struct px_lattice_model *m = e->m;
  size_t n = e->n, i, c, bytes = 13 * (size_t)e->n * e->real;
  void *h;
  enum px_status st;
  PX_TRY(px_lattice_ocl_pending(e));
  PX_TRY(px_lattice_ocl_table(e, t, 0));
  PX_TRY(px_lattice_ocl_run_fields(e, 0.5 * dt));
  h = px_mem_alloc(e->ctx, "lattice.ocl.host", bytes);
  if (!h) return PX_STATUS_NOMEM;
  st = px_buffer_read(e->out, 0, bytes, h);
  if (st != PX_STATUS_OK) {
    px_mem_free(e->ctx, h);
    return st;
  }
  if (f->u) memset(f->u, 0, 3 * m->nalloc * sizeof(double));
  if (f->v) memset(f->v, 0, 3 * m->nalloc * sizeof(double));
  if (f->sigma) memset(f->sigma, 0, 6 * m->nalloc * sizeof(double));
  if (f->vm) memset(f->vm, 0, m->nalloc * sizeof(double));
  for (i = 0; i < n; ++i) {
    size_t j = m->pad + i;
    double v[13];
    for (c = 0; c < 13; ++c)
      v[c] = e->prec == PX_PRECISION_DOUBLE ? ((double *)h)[c * n + i]
                                            : (double)((float *)h)[c * n + i];
    for (c = 0; c < 3; ++c) {
      if (f->u) f->u[3 * j + c] = v[c];
      if (f->v) f->v[3 * j + c] = v[3 + c];
    }
    if (f->sigma)
      for (c = 0; c < 6; ++c) f->sigma[6 * j + c] = v[6 + c] / (m->grid.h * m->grid.h * m->grid.h);
    if (f->vm) f->vm[j] = v[12] / (m->grid.h * m->grid.h * m->grid.h);
  }
  px_mem_free(e->ctx, h);
  if (f->links) PX_TRY(px_lattice_ocl_get(e, NULL, f->links));
  return PX_STATUS_OK;
}

/* The Rayleigh sums per grid row, added in row order on the host: the same
 * sums on any number of ranks (lattice_opencl_block.c). */
enum px_status px_lattice_ocl_row_sums(struct px_lattice_ocl *e, long ra, long rb) {
  const struct px_lattice_model *m = e->m;
  const size_t nrow = (size_t)m->grid.n[1] * (size_t)m->grid.n[2];
  const size_t r0 = (size_t)ra, nr = (size_t)(rb - ra);
  struct px_opencl_args a;
  size_t r, k;
  enum px_status st;
  if (ra >= rb) return PX_STATUS_OK;
  if (!e->rowbuf) PX_TRY(px_buffer_create(e->be, "lattice.rows", 3 * nrow * e->real, &e->rowbuf));
  if (!e->rowsum)
    e->rowsum = (double *)px_mem_alloc(e->ctx, "lattice.ocl", 3 * nrow * sizeof(double));
  if (!e->rowh) e->rowh = px_mem_alloc(e->ctx, "lattice.ocl", 3 * nrow * e->real);
  if (!e->rowsum || !e->rowh) return PX_STATUS_NOMEM;
  /* the rows [r0, r0 + nr): their first entry as the launch's pad */
  e->at = (cl_uint)(m->pad + r0 * m->n0p);
  st = px_lattice_ocl_begin(e, "lt_rows", (cl_uint)nr, &a);
  e->at = e->pad;
  PX_TRY(st);
  px_opencl_args_mem(&a, "y", px_lattice_ocl_state(e));
  px_opencl_args_mem(&a, "lpv", e->lp);
  px_opencl_args_mem(&a, "lmv", e->lm);
  px_opencl_args_mem(&a, "grp", e->grp);
  px_opencl_args_u32(&a, "n0p", (cl_uint)m->n0p);
  px_opencl_args_real(&a, "mass", m->m);  /* [kg] */
  px_opencl_args_real(&a, "inert", m->I); /* [kg m^2] */
  px_opencl_args_mem(&a, "rows", e->rowbuf);
  px_lattice_ocl_vol_args(e, &a);
  PX_TRY(px_opencl_args_launch(&a, nr, 0));
  PX_TRY(px_buffer_read(e->rowbuf, 0, 3 * nr * e->real, e->rowh));
  for (k = 0; k < 3; ++k)
    for (r = 0; r < nr; ++r)
      e->rowsum[k * nrow + r0 + r] = e->prec == PX_PRECISION_DOUBLE
                                         ? ((double *)e->rowh)[k * nr + r]
                                         : (double)((float *)e->rowh)[k * nr + r];
  return PX_STATUS_OK;
}

static enum px_status px_lattice_ocl_rayleigh(void *p, double *num, double *den, double *rate) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  const size_t nrow = (size_t)e->m->grid.n[1] * (size_t)e->m->grid.n[2];
  double sn = 0.0, sd = 0.0, sk = 0.0;
  size_t r;
  PX_TRY(px_lattice_ocl_pending(e));
  if (e->has_blk) {
    double sums[3];
    PX_TRY(px_lattice_ocl_rayleigh_blk(e, sums));
    *num = sums[0];
    *den = sums[1];
    *rate = sums[2];
    return PX_STATUS_OK;
  }
  PX_TRY(px_lattice_ocl_vol(e, px_lattice_ocl_state(e)));
  PX_TRY(px_lattice_ocl_row_sums(e, 0, (long)nrow));
  for (r = 0; r < nrow; ++r) {
    sn += e->rowsum[r];
    sd += e->rowsum[nrow + r];
    sk += e->rowsum[2 * nrow + r];
  }
  *num = sn;
  *den = sd;
  *rate = sk;
  return PX_STATUS_OK;
}

static void px_lattice_ocl_alpha(void *p, double alpha) {
  ((struct px_lattice_ocl *)p)->alpha = alpha;
}

static long px_lattice_ocl_broken(void *p) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  int ends = 0;
  if (e->has_blk) return px_lattice_ocl_broken_blk(e);
  if (px_buffer_read(e->ends, 0, sizeof ends, &ends) != PX_STATUS_OK) return -1;
  return ends / 2;
}

static enum px_status px_lattice_ocl_set_broken(void *p, long links) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  int ends = (int)(2 * links);
  if (e->has_blk) return px_lattice_ocl_set_broken_blk(e, links);
  return px_buffer_write(e->ends, 0, sizeof ends, &ends);
}

static size_t px_lattice_ocl_bytes(void *p) {
  struct px_lattice_ocl *e = (struct px_lattice_ocl *)p;
  /* state buffers, link flags, free flag, group; link-once: 18 link reals;
   * nu != 0: 3 volumetric coefficients */
  return (size_t)e->nbuf * PX_LATTICE_NCOMP * e->real + 4 + (e->l1 ? 18 * e->real : 0) +
         (e->pv ? 3 * e->real : 0);
}

static enum px_lattice_scheme px_lattice_ocl_scheme(void *p) {
  return ((struct px_lattice_ocl *)p)->l1 ? PX_LATTICE_SCHEME_LINK_ONCE : PX_LATTICE_SCHEME_GATHER;
}

const struct px_lattice_engine_i px_lattice_engine_opencl = {"opencl",
                                                             px_lattice_ocl_need,
                                                             px_lattice_ocl_create,
                                                             px_lattice_ocl_destroy,
                                                             px_lattice_ocl_run,
                                                             px_lattice_ocl_get,
                                                             px_lattice_ocl_set,
                                                             px_lattice_ocl_fields,
                                                             px_lattice_ocl_rayleigh,
                                                             px_lattice_ocl_alpha,
                                                             px_lattice_ocl_broken,
                                                             px_lattice_ocl_set_broken,
                                                             px_lattice_ocl_bytes,
                                                             px_lattice_ocl_scheme,
                                                             px_lattice_ocl_set_block};
