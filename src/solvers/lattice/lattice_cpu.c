/* The cpu lattice engine: SoA state, OpenMP over grid rows or planes, SIMD
 * along x, fused RK4 stages (gather: one pass over the elements per stage;
 * link-once: all four stages in one sweep over the planes), float or double
 * chosen at run time (see lattice_engine.h). */
#include <math.h>
#include <omp.h>
#include <string.h>

#include "partix/memory.h"
#include "solvers/lattice/lattice_cpu.h"
#include "solvers/lattice/lattice_ref.h"

static size_t px_lattice_cpu_real(const struct px_lattice_cpu *e) {
  return e->dbl ? sizeof(double) : sizeof(float);
}

static void px_lattice_cpu_destroy(void *p) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  int b;
  if (!e) return;
  for (b = 0; b < 4; ++b) px_mem_free(e->ctx, e->buf[b]);
  px_mem_free(e->ctx, e->lp);
  px_mem_free(e->ctx, e->lm);
  px_mem_free(e->ctx, e->free);
  px_mem_free(e->ctx, e->bc_list);
  px_mem_free(e->ctx, e->bc_group);
  px_mem_free(e->ctx, e->bc_row);
  px_mem_free(e->ctx, e->row_lo);
  px_mem_free(e->ctx, e->row_hi);
  px_mem_free(e->ctx, e->rowsum);
  px_mem_free(e->ctx, e->table);
  px_mem_free(e->ctx, e->table_d);
  px_mem_free(e->ctx, e->pv);
  for (b = 0; b < 3; ++b) px_mem_free(e->ctx, e->tabs[b]);
  if (e->scratch) {
    int t;
    for (t = 0; t < e->threads; ++t) px_mem_free(e->ctx, e->scratch[t]);
    px_mem_free(e->ctx, e->scratch);
  }
  px_mem_free(e->ctx, e);
}

/* Group table for time t (recomputed only when time-dependent). */
static void px_lattice_cpu_table(struct px_lattice_cpu *e, double t, int force) {
  size_t n = e->m->ngroup * PX_LATTICE_GROUP_STRIDE, i;
  if (!force && (!e->table_tdep || t == e->table_t)) return;
  px_lattice_model_groups(e->m, t, e->table_d);
  if (e->dbl)
    memcpy(e->table, e->table_d, n * sizeof(double));
  else
    for (i = 0; i < n; ++i) ((float *)e->table)[i] = (float)e->table_d[i];
  e->table_t = t;
}

/* Store a double state into buffer b (element i). */
static void px_lattice_cpu_put(struct px_lattice_cpu *e, void *b, size_t i, const struct lt_el *y) {
  double c[PX_LATTICE_NCOMP];
  int k;
  c[0] = y->u.x;
  c[1] = y->u.y;
  c[2] = y->u.z;
  c[3] = y->q.w;
  c[4] = y->q.x;
  c[5] = y->q.y;
  c[6] = y->q.z;
  c[7] = y->v.x;
  c[8] = y->v.y;
  c[9] = y->v.z;
  c[10] = y->W.x;
  c[11] = y->W.y;
  c[12] = y->W.z;
  for (k = 0; k < PX_LATTICE_NCOMP; ++k) {
    if (e->dbl)
      ((double *)b)[(size_t)k * e->ns + i] = c[k];
    else
      ((float *)b)[(size_t)k * e->ns + i] = (float)c[k];
  }
}

static void px_lattice_cpu_get1(const struct px_lattice_cpu *e, const void *b, size_t i,
                                struct lt_el *y) {
  double c[PX_LATTICE_NCOMP];
  int k;
  for (k = 0; k < PX_LATTICE_NCOMP; ++k)
    c[k] = e->dbl ? ((const double *)b)[(size_t)k * e->ns + i]
                  : (double)((const float *)b)[(size_t)k * e->ns + i];
  y->u = lt_v3_make(c[0], c[1], c[2]);
  y->q.w = c[3];
  y->q.x = c[4];
  y->q.y = c[5];
  y->q.z = c[6];
  y->v = lt_v3_make(c[7], c[8], c[9]);
  y->W = lt_v3_make(c[10], c[11], c[12]);
}

/* RK4 with the link-once scheme runs as one fused sweep per step
 * (px_lattice_cpu_rk4_l1_*) on one or two threads; with more, as four passes.
 * With the volumetric term the sweep computes each stage's coefficients a
 * plane ahead of its links (lattice_cpu_vol_impl.h). */
static int px_lattice_cpu_fused(const struct px_lattice_cpu *e) {
  return e->integ == PX_LATTICE_INTEGRATOR_RK4 && e->scheme == PX_LATTICE_SCHEME_LINK_ONCE &&
         e->threads <= 2;
}

/* The volumetric coefficients of state y, rows [ra, rb) (nu != 0). */
static void px_lattice_cpu_vol(struct px_lattice_cpu *e, const void *y, long ra, long rb) {
  if (!e->pv || ra >= rb) return;
  if (e->dbl)
    px_lattice_cpu_vol_f64(e, (const double *)y, ra, rb);
  else
    px_lattice_cpu_vol_f32(e, (const float *)y, ra, rb);
}

static void *px_lattice_cpu_state(const struct px_lattice_cpu *e) {
  return e->integ == PX_LATTICE_INTEGRATOR_RK4 ? e->buf[0] : e->buf[e->cur];
}

/* Threads of an engine: all by default, at most one per 16k cells (small
 * bodies: fork/join and barriers would cost more than the work; results do
 * not depend on the count). */
static int px_lattice_cpu_threads(const struct px_lattice_engine_opts *o, size_t n0p, int n1,
                                  int n2) {
  size_t cells = n0p * (size_t)n1 * (size_t)n2;
  int threads = o->threads > 0 ? o->threads : omp_get_max_threads(), most;
  most = (int)(cells / 16384) + 1;
  return threads > most ? most : threads;
}

/* Every allocation of px_lattice_cpu_create, from the layout. */
static void px_lattice_cpu_need(const struct px_lattice_layout *lay,
                                const struct px_lattice_engine_opts *o,
                                struct px_lattice_need *need) {
  double real = o->precision == PX_PRECISION_DOUBLE ? sizeof(double) : sizeof(float);
  double ns = (double)((lay->nalloc + 15) & ~(size_t)15);
  double nbuf = o->integ == PX_LATTICE_INTEGRATOR_RK4 ? 4 : 2;
  double nrow = (double)lay->n[1] * (double)lay->n[2];
  enum px_lattice_scheme scheme =
      o->scheme == PX_LATTICE_SCHEME_AUTO ? PX_LATTICE_SCHEME_LINK_ONCE : o->scheme;
  int threads = px_lattice_cpu_threads(o, lay->n0p, lay->n[1], lay->n[2]);
  double sets =
      o->integ == PX_LATTICE_INTEGRATOR_RK4 && scheme == PX_LATTICE_SCHEME_LINK_ONCE && threads <= 2
          ? 4
          : 1;
  double words = sets * (double)LT_L1_WORDS(lay->n0p, (size_t)lay->n[1]) +
                 7.0 * (double)lay->n0p; /* LT_ROW_FLAGS */
  memset(need, 0, sizeof *need);
  need->scheme = scheme;
  /* state buffers; lp, lm, free; bc_list and bc_group (at most every
   * cell); row ranges, sums and bc_row; the threads' scratch */
  need->host = nbuf * PX_LATTICE_NCOMP * real * ns + 3.0 * (double)lay->nalloc +
               9.0 * (double)lay->ncell + nrow * (2 * sizeof(long) + 4 * sizeof(double)) +
               (double)threads * words * real + (o->vol ? 3.0 * ns * real : 0.0);
}

static enum px_status px_lattice_cpu_create(struct px_context *ctx,
                                            const struct px_lattice_model *m,
                                            const struct px_lattice_engine_opts *o, void **out) {
  struct px_lattice_cpu *e;
  size_t nrow, r, i, real;
  int b;
  struct lt_el rest;
  e = (struct px_lattice_cpu *)px_mem_calloc(ctx, "lattice.cpu", 1, sizeof *e);
  if (!e) return PX_STATUS_NOMEM;
  e->ctx = ctx;
  e->m = m;
  e->integ = o->integ;
  e->scheme = o->scheme == PX_LATTICE_SCHEME_AUTO ? PX_LATTICE_SCHEME_LINK_ONCE : o->scheme;
  e->dbl = o->precision == PX_PRECISION_DOUBLE;
  e->threads = px_lattice_cpu_threads(o, m->n0p, m->grid.n[1], m->grid.n[2]);
  px_tuner_init(&e->tuner, ctx, "lattice", e->threads, o->tune);
  e->active = e->threads;
  e->alpha = m->par.alpha;
  e->group = m->group;
  e->ns = (m->nalloc + 15) & ~(size_t)15;
  e->nbuf = o->integ == PX_LATTICE_INTEGRATOR_RK4 ? 4 : 2;
  real = px_lattice_cpu_real(e);
  nrow = (size_t)m->grid.n[1] * (size_t)m->grid.n[2];
  for (b = 0; b < e->nbuf; ++b) {
    e->buf[b] = px_mem_alloc(ctx, "lattice.state", PX_LATTICE_NCOMP * e->ns * real);
    if (!e->buf[b]) goto nomem;
  }
  e->lp = (uint8_t *)px_mem_alloc(ctx, "lattice.links", m->nalloc);
  e->lm = (uint8_t *)px_mem_alloc(ctx, "lattice.links", m->nalloc);
  e->row_lo = (long *)px_mem_alloc(ctx, "lattice.rows", nrow * sizeof(long));
  e->row_hi = (long *)px_mem_alloc(ctx, "lattice.rows", nrow * sizeof(long));
  e->rowsum = (double *)px_mem_alloc(ctx, "lattice.rows", 3 * nrow * sizeof(double));
  e->table = px_mem_alloc(ctx, "lattice.groups", m->ngroup * PX_LATTICE_GROUP_STRIDE * real);
  e->table_d = (double *)px_mem_alloc(ctx, "lattice.groups",
                                      m->ngroup * PX_LATTICE_GROUP_STRIDE * sizeof(double));
  if (!e->lp || !e->lm || !e->row_lo || !e->row_hi || !e->rowsum || !e->table || !e->table_d)
    goto nomem;
  e->free = (uint8_t *)px_mem_alloc(ctx, "lattice.links", m->nalloc);
  if (!e->free) goto nomem;
  if (m->lam != 0.0) {
    /* zero: void cells and padding keep P = 0 */
    e->pv = px_mem_calloc(ctx, "lattice.volumetric", 3 * e->ns, real);
    if (!e->pv) goto nomem;
    e->lh2 = m->lam * m->grid.h * m->grid.h;
  }
  for (i = 0; i < m->nalloc; ++i) {
    e->lp[i] = m->links[i] & 7u;
    e->lm[i] = m->links[i] & 56u;
    e->free[i] = m->group[i] <= 1;
    e->nbc += m->group[i] > 1;
  }
  e->bc_list = (size_t *)px_mem_alloc(ctx, "lattice.links", (e->nbc ? e->nbc : 1) * sizeof(size_t));
  e->bc_group = (uint8_t *)px_mem_alloc(ctx, "lattice.links", e->nbc ? e->nbc : 1);
  if (!e->bc_list || !e->bc_group) goto nomem;
  e->nbc = 0;
  for (i = 0; i < m->nalloc; ++i)
    if (m->group[i] > 1) {
      e->bc_group[e->nbc] = m->group[i];
      e->bc_list[e->nbc++] = i;
    }
  e->bc_row = (size_t *)px_mem_alloc(ctx, "lattice.links", (nrow + 1) * sizeof(size_t));
  if (!e->bc_row) goto nomem;
  {
    size_t k = 0; /* bc_list is in element order, rows too */
    for (r = 0; r < nrow; ++r) {
      e->bc_row[r] = k;
      while (k < e->nbc && e->bc_list[k] < m->pad + (r + 1) * m->n0p) ++k;
    }
    e->bc_row[nrow] = k;
  }
  for (r = 0; r < nrow; ++r) {
    const uint8_t *occ = m->grid.occ + r * (size_t)m->grid.n[0];
    long lo = -1, hi = -1, x;
    for (x = 0; x < m->grid.n[0]; ++x)
      if (occ[x]) {
        if (lo < 0) lo = x;
        hi = x + 1;
      }
    /* whole SIMD blocks (the padded row holds them; extra cells are void) */
    e->row_lo[r] = lo < 0 ? 0 : lo / PX_LATTICE_ROW_ALIGN * PX_LATTICE_ROW_ALIGN;
    e->row_hi[r] =
        lo < 0 ? 0 : (hi + PX_LATTICE_ROW_ALIGN - 1) / PX_LATTICE_ROW_ALIGN * PX_LATTICE_ROW_ALIGN;
  }
  /* every buffer at rest, padding included */
  memset(&rest, 0, sizeof rest);
  rest.q.w = 1.0;
  for (b = 0; b < e->nbuf; ++b) {
    memset(e->buf[b], 0, PX_LATTICE_NCOMP * e->ns * real);
    for (i = 0; i < e->ns; ++i) px_lattice_cpu_put(e, e->buf[b], i, &rest);
  }
  {
    struct lt_lpar lp;
    struct lt_fpar fp;
    double ld[6], fd[4];
    px_lattice_lpar_d(m, &lp);
    px_lattice_fpar_d(m, &fp);
    ld[0] = lp.h2, ld[1] = lp.k, ld[2] = lp.cl, ld[3] = lp.kb, ld[4] = lp.dk, ld[5] = lp.cr;
    fd[0] = fp.ifn, fd[1] = fp.ift, fd[2] = fp.imb, fd[3] = fp.imt;
    (e->dbl ? px_lattice_cpu_params_f64 : px_lattice_cpu_params_f32)(e, ld, fd);
  }
  {
    /* link-once scratch sets (one per RK4 stage for the fused sweep), then
     * the flag rows of one row (both schemes; lt_cpu_row_flags) */
    size_t n0 = m->n0p, n1 = (size_t)m->grid.n[1];
    size_t sets = px_lattice_cpu_fused(e) ? 4 : 1;
    size_t pw = px_lattice_cpu_fused(e) && e->pv ? 4 * LT_PW_WORDS(n0, n1) : 0;
    size_t words = sets * LT_L1_WORDS(n0, n1) + pw + LT_ROW_FLAGS * n0;
    e->pw_off = sets * LT_L1_WORDS(n0, n1);
    e->flag_off = words - LT_ROW_FLAGS * n0;
    e->scratch_words = words;
    if (px_lattice_cpu_fused(e))
      for (b = 0; b < 3; ++b) {
        e->tabs[b] =
            px_mem_alloc(ctx, "lattice.groups", m->ngroup * PX_LATTICE_GROUP_STRIDE * real);
        if (!e->tabs[b]) goto nomem;
      }
    int t;
    e->scratch = (void **)px_mem_calloc(ctx, "lattice.scratch", (size_t)e->threads, sizeof(void *));
    if (!e->scratch) goto nomem;
    for (t = 0; t < e->threads; ++t) {
      e->scratch[t] = px_mem_calloc(ctx, "lattice.scratch", words, real);
      if (!e->scratch[t]) goto nomem;
    }
  }
  e->table_tdep = px_lattice_model_time_dependent(m);
  px_lattice_cpu_table(e, 0.0, 1);
  *out = e;
  return PX_STATUS_OK;
nomem:
  px_lattice_cpu_destroy(e);
  return PX_STATUS_NOMEM;
}

/* Locate the non-finite value after a step reported one. */
static enum px_status px_lattice_cpu_blowup(struct px_lattice_cpu *e, long step) {
  const struct px_lattice_model *m = e->m;
  struct lt_el *y = (struct lt_el *)px_mem_alloc(e->ctx, "lattice.check", m->nalloc * sizeof *y);
  enum px_status st;
  size_t i;
  if (!y) return PX_STATUS_NOMEM;
  for (i = 0; i < m->nalloc; ++i) px_lattice_cpu_get1(e, px_lattice_cpu_state(e), i, &y[i]);
  st = px_lattice_check_finite_d(e->ctx, m, y, step);
  px_mem_free(e->ctx, y);
  if (st == PX_STATUS_OK)
    st = px_context_fail(e->ctx, PX_STATUS_NUMERIC,
                         "the lattice state overflowed at step %ld (no single element located)",
                         step);
  return st;
}

/* One pass over the rows [ra, rb) (row r = j + n[1] k; link-once: whole
 * planes, ra and rb multiples of n[1]): RK4 stage st (ys its stage state, yn
 * the next; y0 = buf[0], acc = buf[3]) or, st < 0, a leapfrog step from ys
 * to yn; link-once or gather. With nu != 0 it reads the coefficients of ys
 * (px_lattice_cpu_vol) of the rows and of their neighbours: the caller
 * computes them first. Nonzero: a non-finite value was written. */
static int px_lattice_cpu_pass(struct px_lattice_cpu *e, const void *ys, void *yn, int st,
                               double dt, long ra, long rb) {
  const long n1 = e->m->grid.n[1];
  void *y0 = st < 0 ? NULL : e->buf[0], *acc = st < 0 ? NULL : e->buf[3];
  if (ra >= rb) return 0;
  if (e->scheme == PX_LATTICE_SCHEME_LINK_ONCE)
    return e->dbl ? px_lattice_cpu_pass_l1_f64(e, (const double *)ys, (double *)yn, (double *)y0,
                                               (double *)acc, st, dt, ra / n1, rb / n1)
                  : px_lattice_cpu_pass_l1_f32(e, (const float *)ys, (float *)yn, (float *)y0,
                                               (float *)acc, st, (float)dt, ra / n1, rb / n1);
  if (st < 0)
    return e->dbl
               ? px_lattice_cpu_leapfrog_f64(e, (const double *)ys, (double *)yn, dt, ra, rb)
               : px_lattice_cpu_leapfrog_f32(e, (const float *)ys, (float *)yn, (float)dt, ra, rb);
  return e->dbl ? px_lattice_cpu_rk4_stage_f64(e, (const double *)ys, (double *)yn, (double *)y0,
                                               (double *)acc, st, dt, ra, rb)
                : px_lattice_cpu_rk4_stage_f32(e, (const float *)ys, (float *)yn, (float *)y0,
                                               (float *)acc, st, (float)dt, ra, rb);
}

/* Fracture of the elements of planes [za, zb) at state y: link ends cleared. */
static long px_lattice_cpu_break(struct px_lattice_cpu *e, const void *y, long ra, long rb) {
  if (ra >= rb) return 0;
  return e->dbl ? px_lattice_cpu_fracture_f64(e, (const double *)y, ra, rb)
                : px_lattice_cpu_fracture_f32(e, (const float *)y, ra, rb);
}

/* RK4 stage times (fractions of dt) and buffers: stage st reads ys, writes
 * yn (y0 = buf[0], ya = buf[1], yb = buf[2]). */
static const double px_lattice_cpu_cst[4] = {0.0, 0.5, 0.5, 1.0};
static const void *px_lattice_cpu_ys(const struct px_lattice_cpu *e, int st) {
  return st == 0 ? e->buf[0] : (st == 2 ? e->buf[2] : e->buf[1]);
}
static void *px_lattice_cpu_yn(const struct px_lattice_cpu *e, int st) {
  return st == 1 ? e->buf[2] : e->buf[1];
}

/* ---------------------------------------------------------------------------
 * A block of a decomposition over ranks (struct px_lattice_block): every pass
 * reads the halo rows (n1 on each side) of its stage state, so each pass
 * first posts their exchange, computes the rows that do not touch them,
 * waits, then computes the two edges (the n1 rows next to the halo). A
 * block of a 2-D (y, z) rank grid (j1 > 0) runs its row loops plane by
 * plane over its j range: the interior first, then the four bands along its
 * faces. A link across the cut is evaluated by both ranks from the same
 * states (canonical form: the same bits), so both decide alike whether it
 * breaks. With nu != 0 a link's volumetric force reads the coefficients
 * P_a of both ends, and P of an element reads its neighbours' states: so
 * each pass computes P of its own rows (the interior while the state's
 * halo travels, then the edges), posts the exchange of the halo's P
 * (vol_start: one component per halo element, the axis of the links that
 * reach it), computes the interior's links meanwhile, then the edges'.
 * Every P is computed by its owner from the same state and flags as on one
 * rank: the same bits. (Exchanging two planes of state instead and
 * computing the first halo plane's P would send 13 reals per element of a
 * second plane, and its flags, which fracture on the other rank sets.) */

/* The halo's flags of the z-links across the cut from this block's own
 * decisions (fracture changes the flags of own elements only): the
 * link-once sweep (whole-plane blocks) weights the z-links below plane z0
 * by the z-plus flags of plane z0 - 1; the upper halo's z-minus flags are
 * set alike. The gather scheme reads own elements' flags only. */
static void px_lattice_cpu_mirror(struct px_lattice_cpu *e) {
  const struct px_lattice_model *m = e->m;
  const size_t plane = m->n0p * (size_t)m->grid.n[1], s2 = (size_t)m->stride[2];
  size_t i, b;
  if (e->blk.r0 > 0)
    for (b = m->pad + (size_t)e->blk.r0 * m->n0p, i = b; i < b + plane; ++i)
      e->lp[i - s2] = (uint8_t)((e->lp[i - s2] & ~4u) | (((unsigned)e->lm[i] >> 3) & 4u));
  if (e->blk.r1 < (long)m->grid.n[1] * m->grid.n[2])
    for (b = m->pad + (size_t)e->blk.r1 * m->n0p - plane, i = b; i < b + plane; ++i)
      e->lm[i + s2] = (uint8_t)((e->lm[i + s2] & ~32u) | (((unsigned)e->lp[i] << 3) & 32u));
}

/* The block's rows [r0, r1) as the lower edge [r0, *a), the interior
 * [*a, *c) and the upper edge [*c, r1) (each may be empty): the edges are
 * the n1 rows next to the halo. */
static void px_lattice_cpu_split(const struct px_lattice_block *b, long n1, long *a, long *c) {
  *a = b->r0 + n1 < b->r1 ? b->r0 + n1 : b->r1;
  *c = b->r1 - n1 > *a ? b->r1 - n1 : *a;
}

static void px_lattice_cpu_row_sums(struct px_lattice_cpu *e, long ra, long rb);

/* What px_lattice_cpu_rect does to each row range. */
enum px_lattice_cpu_op { PX_LT_PASS, PX_LT_BREAK, PX_LT_SUMS, PX_LT_VOL };

/* op on the rows j + n1 k, j in [ja, jb), k in [ka, kb) (a rectangle of a
 * 2-D block: one row range per plane). Returns the non-finite flag of the
 * passes; *ends += the broken link ends. */
static int px_lattice_cpu_rect(struct px_lattice_cpu *e, enum px_lattice_cpu_op op, const void *ys,
                               void *yn, int st, double dt, const long r[4], long *ends) {
  const long n1 = e->m->grid.n[1];
  long k;
  int bad = 0;
  if (r[0] >= r[1]) return 0;
  for (k = r[2]; k < r[3]; ++k) {
    const long ra = r[0] + n1 * k, rb = r[1] + n1 * k;
    if (op == PX_LT_PASS)
      bad |= px_lattice_cpu_pass(e, ys, yn, st, dt, ra, rb);
    else if (op == PX_LT_BREAK)
      *ends += px_lattice_cpu_break(e, ys, ra, rb);
    else if (op == PX_LT_VOL)
      px_lattice_cpu_vol(e, ys, ra, rb);
    else
      px_lattice_cpu_row_sums(e, ra, rb);
  }
  return bad;
}

/* op on a 2-D block's elements that do not read its halo (edge = 0: the
 * interior, j in [j0 + 1, j1 - 1), k in [k0 + 1, k1 - 1)) or on the others
 * (edge = 1: the four bands along its faces, which partition the rest). */
static int px_lattice_cpu_blk2(struct px_lattice_cpu *e, enum px_lattice_cpu_op op, int edge,
                               const void *ys, void *yn, int st, double dt, long *ends) {
  long rect[4];
  int bad = 0, q;
  for (q = edge ? 1 : 0; q < (edge ? 5 : 1); ++q) {
    px_lattice_block_rect(&e->blk, q, rect);
    bad |= px_lattice_cpu_rect(e, op, ys, yn, st, dt, rect, ends);
  }
  return bad;
}

/* op (PX_LT_VOL or PX_LT_SUMS) on the block's rows at state y while the
 * halo posted before travels: the rows that do not read it, halo_wait, then
 * the others (a, c: px_lattice_cpu_split's, for a block of rows). */
static enum px_status px_lattice_cpu_blk_each(struct px_lattice_cpu *e, enum px_lattice_cpu_op op,
                                              const void *y, long a, long c) {
  const struct px_lattice_block *b = &e->blk;
  if (b->j1 > 0) {
    px_lattice_cpu_blk2(e, op, 0, y, NULL, 0, 0.0, NULL);
    PX_TRY(b->halo_wait(b->arg));
    px_lattice_cpu_blk2(e, op, 1, y, NULL, 0, 0.0, NULL);
  } else {
    const long in[4] = {a, c, 0, 1}, lo[4] = {b->r0, a, 0, 1}, hi[4] = {c, b->r1, 0, 1};
    px_lattice_cpu_rect(e, op, y, NULL, 0, 0.0, in, NULL);
    PX_TRY(b->halo_wait(b->arg));
    px_lattice_cpu_rect(e, op, y, NULL, 0, 0.0, lo, NULL);
    px_lattice_cpu_rect(e, op, y, NULL, 0, 0.0, hi, NULL);
  }
  return PX_STATUS_OK;
}

/* px_lattice_cpu_blk_pass on a 2-D block (the gather scheme: no flags to
 * mirror, each element reads its own flags only). */
static enum px_status px_lattice_cpu_blk2_pass(struct px_lattice_cpu *e, const void *ys, void *yn,
                                               int st, double dt, int frac, int *bad) {
  const struct px_lattice_block *b = &e->blk;
  long ends = 0;
  PX_TRY(b->halo_start(b->arg, (void *)ys, px_lattice_cpu_real(e), e->ns));
  if (frac) {
    px_lattice_cpu_blk2(e, PX_LT_BREAK, 0, ys, NULL, st, dt, &ends);
    PX_TRY(b->halo_wait(b->arg));
    px_lattice_cpu_blk2(e, PX_LT_BREAK, 1, ys, NULL, st, dt, &ends);
    PX_TRY(b->count(b->arg, &ends));
    e->broken_ends += ends;
    if (e->pv) {
      px_lattice_cpu_blk2(e, PX_LT_VOL, 0, ys, NULL, st, dt, NULL);
      px_lattice_cpu_blk2(e, PX_LT_VOL, 1, ys, NULL, st, dt, NULL);
    }
  } else if (e->pv) {
    PX_TRY(px_lattice_cpu_blk_each(e, PX_LT_VOL, ys, 0, 0));
  } else {
    *bad = px_lattice_cpu_blk2(e, PX_LT_PASS, 0, ys, yn, st, dt, NULL);
    PX_TRY(b->halo_wait(b->arg));
    *bad |= px_lattice_cpu_blk2(e, PX_LT_PASS, 1, ys, yn, st, dt, NULL);
    return PX_STATUS_OK;
  }
  /* the state's halo is in: the links of the bands also read the
   * neighbours' coefficients (nu != 0), which travel while the interior
   * runs */
  if (e->pv) PX_TRY(b->vol_start(b->arg, e->pv, px_lattice_cpu_real(e), e->ns));
  *bad = px_lattice_cpu_blk2(e, PX_LT_PASS, 0, ys, yn, st, dt, NULL);
  if (e->pv) PX_TRY(b->halo_wait(b->arg));
  *bad |= px_lattice_cpu_blk2(e, PX_LT_PASS, 1, ys, yn, st, dt, NULL);
  return PX_STATUS_OK;
}

/* One pass of the block (px_lattice_cpu_pass) with the halo of ys exchanged
 * meanwhile; frac: fracture at ys first (the broken ends summed over the
 * ranks). *bad: nonzero for a non-finite value. */
static enum px_status px_lattice_cpu_blk_pass(struct px_lattice_cpu *e, const void *ys, void *yn,
                                              int st, double dt, int frac, int *bad) {
  const struct px_lattice_block *b = &e->blk;
  long a, c;
  if (b->j1 > 0) return px_lattice_cpu_blk2_pass(e, ys, yn, st, dt, frac, bad);
  px_lattice_cpu_split(b, e->m->grid.n[1], &a, &c);
  PX_TRY(b->halo_start(b->arg, (void *)ys, px_lattice_cpu_real(e), e->ns));
  if (frac) {
    long ends = px_lattice_cpu_break(e, ys, a, c);
    PX_TRY(b->halo_wait(b->arg));
    ends += px_lattice_cpu_break(e, ys, b->r0, a) + px_lattice_cpu_break(e, ys, c, b->r1);
    PX_TRY(b->count(b->arg, &ends));
    e->broken_ends += ends;
    px_lattice_cpu_mirror(e);
    if (!e->pv) {
      *bad = px_lattice_cpu_pass(e, ys, yn, st, dt, b->r0, b->r1);
      return PX_STATUS_OK;
    }
    px_lattice_cpu_vol(e, ys, b->r0, b->r1);
  } else if (e->pv) {
    PX_TRY(px_lattice_cpu_blk_each(e, PX_LT_VOL, ys, a, c));
  } else {
    *bad = px_lattice_cpu_pass(e, ys, yn, st, dt, a, c);
    PX_TRY(b->halo_wait(b->arg));
    *bad |= px_lattice_cpu_pass(e, ys, yn, st, dt, b->r0, a);
    *bad |= px_lattice_cpu_pass(e, ys, yn, st, dt, c, b->r1);
    return PX_STATUS_OK;
  }
  /* nu != 0: the edges' links also read the coefficients of the halo rows,
   * which travel while the interior runs */
  PX_TRY(b->vol_start(b->arg, e->pv, px_lattice_cpu_real(e), e->ns));
  *bad = px_lattice_cpu_pass(e, ys, yn, st, dt, a, c);
  PX_TRY(b->halo_wait(b->arg));
  *bad |= px_lattice_cpu_pass(e, ys, yn, st, dt, b->r0, a);
  *bad |= px_lattice_cpu_pass(e, ys, yn, st, dt, c, b->r1);
  return PX_STATUS_OK;
}

/* px_lattice_cpu_run on a block: the per-stage passes (the fused RK4 sweep
 * runs all stages without a halo exchange between them; the passes give the
 * same bits). */
static enum px_status px_lattice_cpu_run_blk(struct px_lattice_cpu *e, long step, double t,
                                             double dt, long n) {
  long s;
  for (s = 0; s < n; ++s) {
    double ts = t + (double)s * dt;
    int bad = 0, st;
    if (e->integ == PX_LATTICE_INTEGRATOR_RK4) {
      for (st = 0; st < 4; ++st) {
        px_lattice_cpu_table(e, ts + px_lattice_cpu_cst[st] * dt, 0);
        PX_TRY(px_lattice_cpu_blk_pass(e, px_lattice_cpu_ys(e, st), px_lattice_cpu_yn(e, st), st,
                                       dt, st == 0 && e->m->fracture, &bad));
      }
    } else {
      px_lattice_cpu_table(e, ts, 0);
      PX_TRY(px_lattice_cpu_blk_pass(e, e->buf[e->cur], e->buf[1 - e->cur], -1, dt, e->m->fracture,
                                     &bad));
      e->cur = 1 - e->cur;
    }
    if (bad) return px_lattice_cpu_blowup(e, step + s + 1);
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_cpu_set_block(void *p, const struct px_lattice_block *b) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  e->has_blk = b != NULL;
  if (b) e->blk = *b;
  return PX_STATUS_OK;
}

static enum px_status px_lattice_cpu_run(void *p, long step, double t, double dt, long n) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  const long nrow = (long)e->m->grid.n[1] * e->m->grid.n[2];
  long s;
  if (e->has_blk) return px_lattice_cpu_run_blk(e, step, t, dt, n);
  for (s = 0; s < n; ++s) {
    double ts = t + (double)s * dt;
    int bad;
    e->active = px_tuner_begin(&e->tuner);
    if (e->integ == PX_LATTICE_INTEGRATOR_RK4) {
      int st;
      if (e->m->fracture) e->broken_ends += px_lattice_cpu_break(e, e->buf[0], 0, nrow);
      if (px_lattice_cpu_fused(e)) {
        static const double ct[3] = {0.0, 0.5, 1.0};
        size_t tb = e->m->ngroup * PX_LATTICE_GROUP_STRIDE * px_lattice_cpu_real(e);
        for (st = 0; st < 3; ++st) {
          px_lattice_cpu_table(e, ts + ct[st] * dt, 0);
          memcpy(e->tabs[st], e->table, tb);
        }
        if (e->dbl) {
          const double *tabs[3] = {e->tabs[0], e->tabs[1], e->tabs[2]};
          bad = px_lattice_cpu_rk4_l1_f64(e, (double *)e->buf[0], (double *)e->buf[1],
                                          (double *)e->buf[2], (double *)e->buf[3], tabs, dt);
        } else {
          const float *tabs[3] = {e->tabs[0], e->tabs[1], e->tabs[2]};
          bad = px_lattice_cpu_rk4_l1_f32(e, (float *)e->buf[0], (float *)e->buf[1],
                                          (float *)e->buf[2], (float *)e->buf[3], tabs, (float)dt);
        }
      } else {
        for (st = 0; st < 4; ++st) {
          px_lattice_cpu_table(e, ts + px_lattice_cpu_cst[st] * dt, 0);
          px_lattice_cpu_vol(e, px_lattice_cpu_ys(e, st), 0, nrow);
          bad = px_lattice_cpu_pass(e, px_lattice_cpu_ys(e, st), px_lattice_cpu_yn(e, st), st, dt,
                                    0, nrow);
        }
      }
    } else {
      const void *ya = e->buf[e->cur];
      void *yb = e->buf[1 - e->cur];
      if (e->m->fracture) e->broken_ends += px_lattice_cpu_break(e, ya, 0, nrow);
      px_lattice_cpu_table(e, ts, 0);
      px_lattice_cpu_vol(e, ya, 0, nrow);
      bad = px_lattice_cpu_pass(e, ya, yb, -1, dt, 0, nrow);
      e->cur = 1 - e->cur;
    }
    px_tuner_end(&e->tuner, step + s);
    if (bad) return px_lattice_cpu_blowup(e, step + s + 1);
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_cpu_get(void *p, struct lt_el *y, uint8_t *links) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  size_t i;
  if (y)
    for (i = 0; i < e->m->nalloc; ++i) px_lattice_cpu_get1(e, px_lattice_cpu_state(e), i, &y[i]);
  if (links)
    for (i = 0; i < e->m->nalloc; ++i) links[i] = (uint8_t)(e->lp[i] | e->lm[i]);
  return PX_STATUS_OK;
}

static enum px_status px_lattice_cpu_set(void *p, const struct lt_el *y, const uint8_t *links) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  size_t i;
  if (y)
    for (i = 0; i < e->m->nalloc; ++i) px_lattice_cpu_put(e, px_lattice_cpu_state(e), i, &y[i]);
  if (links)
    for (i = 0; i < e->m->nalloc; ++i) {
      e->lp[i] = links[i] & 7u;
      e->lm[i] = links[i] & 56u;
    }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_cpu_fields(void *p, double t, double dt,
                                            const struct px_lattice_fields *f) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  size_t i, n = e->m->nalloc;
  /* void cells and padding: zero */
  if (f->u) memset(f->u, 0, 3 * n * sizeof(double));
  if (f->v) memset(f->v, 0, 3 * n * sizeof(double));
  if (f->sigma) memset(f->sigma, 0, 6 * n * sizeof(double));
  if (f->vm) memset(f->vm, 0, n * sizeof(double));
  px_lattice_cpu_table(e, t, 0);
  if (e->has_blk) {
    /* on a block: its halo current first (the last update wrote own rows
     * only); nu != 0: the coefficients of the halo from their owners */
    const struct px_lattice_block *b = &e->blk;
    PX_TRY(b->halo_start(b->arg, px_lattice_cpu_state(e), px_lattice_cpu_real(e), e->ns));
    PX_TRY(b->halo_wait(b->arg));
  }
  px_lattice_cpu_vol(e, px_lattice_cpu_state(e), 0, (long)e->m->grid.n[1] * e->m->grid.n[2]);
  if (e->has_blk && e->pv) {
    PX_TRY(e->blk.vol_start(e->blk.arg, e->pv, px_lattice_cpu_real(e), e->ns));
    PX_TRY(e->blk.halo_wait(e->blk.arg));
  }
  if (e->dbl)
    px_lattice_cpu_fields_f64(e, (const double *)px_lattice_cpu_state(e), dt, f, 0, 0,
                              (long)e->m->grid.n[1] * e->m->grid.n[2]);
  else
    px_lattice_cpu_fields_f32(e, (const float *)px_lattice_cpu_state(e), dt, f, 0, 0,
                              (long)e->m->grid.n[1] * e->m->grid.n[2]);
  if (f->links)
    for (i = 0; i < n; ++i) f->links[i] = (uint8_t)(e->lp[i] | e->lm[i]);
  return PX_STATUS_OK;
}

/* Rayleigh sums of the rows [ra, rb) into e->rowsum (nu != 0: from the
 * coefficients computed before, those of the rows and their neighbours). */
static void px_lattice_cpu_row_sums(struct px_lattice_cpu *e, long ra, long rb) {
  if (ra >= rb) return;
  if (e->dbl)
    px_lattice_cpu_fields_f64(e, (const double *)px_lattice_cpu_state(e), 0.0, NULL, 1, ra, rb);
  else
    px_lattice_cpu_fields_f32(e, (const float *)px_lattice_cpu_state(e), 0.0, NULL, 1, ra, rb);
}

static enum px_status px_lattice_cpu_rayleigh(void *p, double *num, double *den, double *rate) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  const size_t nrow = (size_t)e->m->grid.n[1] * (size_t)e->m->grid.n[2];
  double sn = 0.0, sd = 0.0, sk = 0.0;
  size_t r;
  if (e->has_blk) {
    /* this block's rows (the halo of the state exchanged meanwhile), then
     * every rank's rows */
    const struct px_lattice_block *b = &e->blk;
    void *y = px_lattice_cpu_state(e);
    long a, c;
    px_lattice_cpu_split(b, e->m->grid.n[1], &a, &c);
    PX_TRY(b->halo_start(b->arg, y, px_lattice_cpu_real(e), e->ns));
    /* nu != 0: the coefficients first, as a pass computes them */
    PX_TRY(px_lattice_cpu_blk_each(e, e->pv ? PX_LT_VOL : PX_LT_SUMS, y, a, c));
    if (e->pv) {
      PX_TRY(b->vol_start(b->arg, e->pv, px_lattice_cpu_real(e), e->ns));
      PX_TRY(px_lattice_cpu_blk_each(e, PX_LT_SUMS, y, a, c));
    }
    {
      double sums[3];
      PX_TRY(b->rows(b->arg, e->rowsum, 3, sums));
      *num = sums[0];
      *den = sums[1];
      *rate = sums[2];
      return PX_STATUS_OK;
    }
  }
  px_lattice_cpu_vol(e, px_lattice_cpu_state(e), 0, (long)nrow);
  px_lattice_cpu_row_sums(e, 0, (long)nrow);
  /* in row order: the same sums on any number of ranks */
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

static void px_lattice_cpu_alpha(void *p, double alpha) {
  ((struct px_lattice_cpu *)p)->alpha = alpha;
}

static long px_lattice_cpu_broken(void *p) { return ((struct px_lattice_cpu *)p)->broken_ends / 2; }

static enum px_status px_lattice_cpu_set_broken(void *p, long links) {
  ((struct px_lattice_cpu *)p)->broken_ends = 2 * links;
  return PX_STATUS_OK;
}

static size_t px_lattice_cpu_bytes(void *p) {
  struct px_lattice_cpu *e = (struct px_lattice_cpu *)p;
  /* state buffers + link flags + group id, per box cell, the volumetric
   * coefficients (nu != 0: 3 reals), and the threads' scratch spread over
   * the cells (rounded up) */
  size_t scratch = (size_t)e->threads * e->scratch_words * px_lattice_cpu_real(e);
  return ((size_t)e->nbuf * PX_LATTICE_NCOMP + (e->pv ? 3 : 0)) * px_lattice_cpu_real(e) + 3 +
         (scratch + e->m->nalloc - 1) / e->m->nalloc;
}

static enum px_lattice_scheme px_lattice_cpu_scheme(void *p) {
  return ((struct px_lattice_cpu *)p)->scheme;
}

const struct px_lattice_engine_i px_lattice_engine_cpu = {"cpu",
                                                          px_lattice_cpu_need,
                                                          px_lattice_cpu_create,
                                                          px_lattice_cpu_destroy,
                                                          px_lattice_cpu_run,
                                                          px_lattice_cpu_get,
                                                          px_lattice_cpu_set,
                                                          px_lattice_cpu_fields,
                                                          px_lattice_cpu_rayleigh,
                                                          px_lattice_cpu_alpha,
                                                          px_lattice_cpu_broken,
                                                          px_lattice_cpu_set_broken,
                                                          px_lattice_cpu_bytes,
                                                          px_lattice_cpu_scheme,
                                                          px_lattice_cpu_set_block};
