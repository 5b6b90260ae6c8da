/* The lattice model on the host (see lattice_model.h). */
#include "solvers/lattice/lattice_model.h"

#include <math.h>
#include <string.h>

#include "partix/memory.h"

/* Highest natural frequency of the lattice in units of c/h (k_b = E h^3/12,
 * k_t = G J/h, I = m h^2/6): 3.74 for the periodic lattice
 * (research/lattice.md section 2, check/omega.py); tests/lattice checks that
 * finite bodies do not exceed it. */
#define PX_LATTICE_OMEGA_MAX 3.74
/* Damping ratio of the highest mode per unit link damping ratio zeta: link
 * dashpots act like stiffness-proportional damping, zeta_mode = zeta omega
 * sqrt(m/(2k)) = zeta (omega h/c)/sqrt(2) = 2.65 zeta at omega_max. */
#define PX_LATTICE_ZETA_HIGH (PX_LATTICE_OMEGA_MAX / 1.41421356237309505)
/* Saint-Venant torsion constant of a square section, J = 0.1406 a^4
 * (Roark's Formulas for Stress and Strain, Table 10.7 case 4). */
#define PX_LATTICE_J_SQUARE 0.1406

double px_lattice_tfun_eval(const struct px_lattice_tfun *f, double t) {
  switch (f->kind) {
    case PX_LATTICE_TFUN_RAMP:
      if (t <= f->t0) return 0.0;
      if (t >= f->t1) return 1.0;
      return (t - f->t0) / (f->t1 - f->t0);
    case PX_LATTICE_TFUN_HARMONIC:
      return sin(2.0 * 3.14159265358979323846 * f->freq * t + f->phase);
    case PX_LATTICE_TFUN_TABLE: {
      size_t lo = 0, hi;
      if (f->n == 0) return 0.0;
      if (t <= f->t[0]) return f->v[0];
      if (t >= f->t[f->n - 1]) return f->v[f->n - 1];
      hi = f->n - 1;
      while (hi - lo > 1) {
        size_t mid = (lo + hi) / 2;
        if (f->t[mid] <= t)
          lo = mid;
        else
          hi = mid;
      }
      return f->v[lo] + (f->v[hi] - f->v[lo]) * (t - f->t[lo]) / (f->t[hi] - f->t[lo]);
    }
    case PX_LATTICE_TFUN_CONSTANT:
    default: return 1.0;
  }
}

static enum px_status px_lattice_tfun_check(struct px_context *ctx, const struct px_lattice_tfun *f,
                                            const char *what) {
  size_t i;
  if (f->kind == PX_LATTICE_TFUN_RAMP && !(f->t1 > f->t0))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: ramp end t1 = %g must exceed start t0 = %g",
                           what, f->t1, f->t0);
  if (f->kind == PX_LATTICE_TFUN_TABLE) {
    if (f->n < 1 || !f->t || !f->v)
      return px_context_fail(ctx, PX_STATUS_CONFIG, "%s: the table has no points", what);
    for (i = 1; i < f->n; ++i)
      if (!(f->t[i] > f->t[i - 1]))
        return px_context_fail(ctx, PX_STATUS_CONFIG,
                               "%s: table times must increase (t[%zu] = %g after t[%zu] = %g)",
                               what, i, f->t[i], i - 1, f->t[i - 1]);
  }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_tfun_copy(struct px_context *ctx, struct px_lattice_tfun *dst,
                                           const struct px_lattice_tfun *src) {
  *dst = *src;
  dst->t = dst->v = NULL;
  if (src->kind == PX_LATTICE_TFUN_TABLE && src->n > 0) {
    dst->t = (double *)px_mem_alloc(ctx, "lattice.bc", src->n * sizeof(double));
    dst->v = (double *)px_mem_alloc(ctx, "lattice.bc", src->n * sizeof(double));
    if (!dst->t || !dst->v) return PX_STATUS_NOMEM;
    memcpy(dst->t, src->t, src->n * sizeof(double));
    memcpy(dst->v, src->v, src->n * sizeof(double));
  }
  return PX_STATUS_OK;
}

void px_lattice_model_free(struct px_context *ctx, struct px_lattice_model *m) {
  size_t i;
  if (!m) return;
  px_lattice_grid_free(ctx, &m->grid);
  px_mem_free(ctx, m->links);
  px_mem_free(ctx, m->group);
  px_mem_free(ctx, m->vfree);
  if (m->window) {
    memset(m, 0, sizeof *m);
    return;
  }
  for (i = 0; i < m->nbc && m->bc; ++i) {
    px_mem_free(ctx, m->bc[i].accel_f.t);
    px_mem_free(ctx, m->bc[i].accel_f.v);
    px_mem_free(ctx, m->bc[i].load_f.t);
    px_mem_free(ctx, m->bc[i].load_f.v);
  }
  px_mem_free(ctx, m->bc);
  px_mem_free(ctx, m->bc_count);
  px_mem_free(ctx, m->group_bcs);
  memset(m, 0, sizeof *m);
}

void px_lattice_model_layout(const int n[3], struct px_lattice_layout *lay) {
  size_t n0 = (size_t)n[0], n1 = (size_t)n[1], n2 = (size_t)n[2];
  lay->n[0] = n[0];
  lay->n[1] = n[1];
  lay->n[2] = n[2];
  lay->ncell = n0 * n1 * n2;
  lay->n0p = (n0 + PX_LATTICE_ROW_ALIGN - 1) / PX_LATTICE_ROW_ALIGN * PX_LATTICE_ROW_ALIGN;
  lay->pad = (lay->n0p * n1 + lay->n0p + 1 + PX_LATTICE_ROW_ALIGN - 1) / PX_LATTICE_ROW_ALIGN *
             PX_LATTICE_ROW_ALIGN;
  lay->nalloc = lay->n0p * n1 * n2 + 2 * lay->pad;
}

unsigned px_lattice_window_out(const struct px_lattice_model *w, size_t j, size_t k) {
  unsigned out = 0;
  if (!w->window) return 0;
  if (j == 0) out |= PX_LATTICE_LINK_MINUS(1);
  if (j + 1 == (size_t)w->grid.n[1]) out |= PX_LATTICE_LINK_PLUS(1);
  if (k == 0) out |= PX_LATTICE_LINK_MINUS(2);
  if (k + 1 == (size_t)w->grid.n[2]) out |= PX_LATTICE_LINK_PLUS(2);
  return out;
}

enum px_status px_lattice_model_window(struct px_context *ctx, const struct px_lattice_model *m,
                                       const long box[4], struct px_lattice_model *w) {
  const size_t n0 = (size_t)m->grid.n[0], n1 = (size_t)m->grid.n[1];
  struct px_lattice_layout lay;
  size_t j, k, i;
  *w = *m;
  w->window = 1;
  w->grid.n[1] = (int)(box[1] - box[0]);
  w->grid.n[2] = (int)(box[3] - box[2]);
  w->grid.origin[1] = m->grid.origin[1] + (double)box[0] * m->grid.h;
  w->grid.origin[2] = m->grid.origin[2] + (double)box[2] * m->grid.h;
  px_lattice_model_layout(w->grid.n, &lay);
  w->grid.ncell = lay.ncell;
  w->grid.count = 0;
  w->n0p = lay.n0p;
  w->pad = lay.pad;
  w->nalloc = lay.nalloc;
  w->stride[1] = (ptrdiff_t)w->n0p;
  w->stride[2] = (ptrdiff_t)(w->n0p * (size_t)w->grid.n[1]);
  w->grid.occ = (uint8_t *)px_mem_alloc(ctx, "lattice.window", lay.ncell ? lay.ncell : 1);
  w->links = (uint8_t *)px_mem_calloc(ctx, "lattice.window", w->nalloc, 1);
  w->group = (uint8_t *)px_mem_calloc(ctx, "lattice.window", w->nalloc, 1);
  w->vfree = (uint8_t *)px_mem_calloc(ctx, "lattice.window", w->nalloc, 1);
  if (!w->grid.occ || !w->links || !w->group || !w->vfree) {
    px_lattice_model_free(ctx, w);
    return PX_STATUS_NOMEM;
  }
  for (k = 0; k < (size_t)w->grid.n[2]; ++k)
    for (j = 0; j < (size_t)w->grid.n[1]; ++j) {
      const size_t gr = (size_t)box[0] + j + n1 * ((size_t)box[2] + k);
      const size_t wr = j + (size_t)w->grid.n[1] * k;
      const size_t gi = m->pad + gr * m->n0p, wi = w->pad + wr * w->n0p;
      const unsigned out = px_lattice_window_out(w, j, k);
      memcpy(w->grid.occ + wr * n0, m->grid.occ + gr * n0, n0);
      memcpy(w->group + wi, m->group + gi, m->n0p);
      memcpy(w->vfree + wi, m->vfree + gi, m->n0p);
      for (i = 0; i < m->n0p; ++i) w->links[wi + i] = (uint8_t)(m->links[gi + i] & ~out);
      for (i = 0; i < n0; ++i) w->grid.count += w->grid.occ[wr * n0 + i];
    }
  return PX_STATUS_OK;
}

static enum px_status px_lattice_check_params(struct px_context *ctx,
                                              const struct px_lattice_params *p) {
  if (!(p->E > 0.0) || !isfinite(p->E))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "Young's modulus E must be > 0 Pa, got %g", p->E);
  if (!(p->nu > -1.0 && p->nu < 0.5))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "Poisson's ratio must lie in (-1, 0.5), got %g",
                           p->nu);
  if (!(p->rho > 0.0) || !isfinite(p->rho))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "density rho must be > 0 kg/m^3, got %g", p->rho);
  if (!(p->zeta >= 0.0) || !isfinite(p->zeta))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "damping ratio must be >= 0, got %g", p->zeta);
  if (!(p->alpha >= 0.0) || !isfinite(p->alpha))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "global damping must be >= 0 1/s, got %g",
                           p->alpha);
  if (!(p->f_nc >= 0.0 && p->f_tc >= 0.0 && p->m_bc >= 0.0 && p->m_tc >= 0.0))
    return px_context_fail(ctx, PX_STATUS_CONFIG, "bond strengths must be >= 0 (0 = unbreakable)");
  return PX_STATUS_OK;
}

enum px_status px_lattice_model_build(struct px_context *ctx, struct px_lattice_model *m,
                                      struct px_lattice_grid *grid,
                                      const struct px_lattice_params *par,
                                      const struct px_lattice_bc *bcs, size_t nbc) {
  const struct px_lattice_grid *g;
  size_t n0, n1, n2, c, i;
  uint64_t *sig = NULL;
  enum px_status st = PX_STATUS_OK;
  double h;

  memset(m, 0, sizeof *m);
  m->grid = *grid;
  memset(grid, 0, sizeof *grid);
  g = &m->grid;
  if ((st = px_lattice_check_params(ctx, par)) != PX_STATUS_OK) goto fail;
  if ((st = px_lattice_grid_check_connected(ctx, g)) != PX_STATUS_OK) goto fail;
  if (nbc > 64) {
    st = px_context_fail(ctx, PX_STATUS_CONFIG,
                         "%zu boundary conditions given; at most 64 are supported", nbc);
    goto fail;
  }
  m->par = *par;
  h = g->h;
  m->m = par->rho * h * h * h;
  m->I = m->m * h * h / 6.0;
  /* k = 2 mu h, kt = mu J/h with mu = E/(2(1+nu)) and the volumetric term
   * lambda = E nu/((1+nu)(1-2nu)): C11 = 2 mu + lambda, C12 = lambda,
   * C44 = mu for uniform strain (docs/notes/lattice-poisson.md); at nu = 0
   * exactly the E h and E/2 of the springs alone. */
  m->k = par->E * h / (1.0 + par->nu);
  m->kb = par->E * h * h * h / 12.0;
  m->kt = 0.5 * par->E / (1.0 + par->nu) * PX_LATTICE_J_SQUARE * h * h * h;
  m->lam = par->E * par->nu / ((1.0 + par->nu) * (1.0 - 2.0 * par->nu));
  m->cl = 2.0 * par->zeta * sqrt(m->k * 0.5 * m->m);
  m->cr = 2.0 * par->zeta * sqrt(m->kb * 0.5 * m->I);
  m->fracture = par->f_nc > 0.0 || par->f_tc > 0.0 || par->m_bc > 0.0 || par->m_tc > 0.0;

  n0 = (size_t)g->n[0];
  n1 = (size_t)g->n[1];
  n2 = (size_t)g->n[2];
  {
    struct px_lattice_layout lay;
    px_lattice_model_layout(g->n, &lay);
    m->n0p = lay.n0p;
    m->pad = lay.pad;
    m->nalloc = lay.nalloc;
  }
  m->stride[0] = 1;
  m->stride[1] = (ptrdiff_t)m->n0p;
  m->stride[2] = (ptrdiff_t)(m->n0p * n1);
  m->links = (uint8_t *)px_mem_calloc(ctx, "lattice.links", m->nalloc, 1);
  m->group = (uint8_t *)px_mem_calloc(ctx, "lattice.group", m->nalloc, 1);
  m->vfree = (uint8_t *)px_mem_calloc(ctx, "lattice.group", m->nalloc, 1);
  m->bc = (struct px_lattice_bc *)px_mem_calloc(ctx, "lattice.bc", nbc ? nbc : 1, sizeof *m->bc);
  m->bc_count = (size_t *)px_mem_calloc(ctx, "lattice.bc", nbc ? nbc : 1, sizeof(size_t));
  sig = (uint64_t *)px_mem_calloc(ctx, "lattice.bc", g->ncell, sizeof *sig);
  if (!m->links || !m->group || !m->vfree || !m->bc || !m->bc_count || !sig) {
    st = PX_STATUS_NOMEM;
    goto fail;
  }
  /* links present between occupied face neighbours */
  for (c = 0; c < g->ncell; ++c) {
    size_t ijk[3], dims[3], gs[3];
    int a;
    uint8_t f = 0;
    if (!g->occ[c]) continue;
    ijk[0] = c % n0;
    ijk[1] = (c / n0) % n1;
    ijk[2] = c / (n0 * n1);
    dims[0] = n0;
    dims[1] = n1;
    dims[2] = n2;
    gs[0] = 1;
    gs[1] = n0;
    gs[2] = n0 * n1;
    for (a = 0; a < 3; ++a) {
      if (ijk[a] + 1 < dims[a] && g->occ[c + gs[a]]) f |= PX_LATTICE_LINK_PLUS(a);
      if (ijk[a] > 0 && g->occ[c - gs[a]]) f |= PX_LATTICE_LINK_MINUS(a);
    }
    m->links[px_lattice_index(m, c)] = f;
  }
  /* boundary conditions: copy, select, sign each element */
  m->nbc = nbc;
  for (i = 0; i < nbc; ++i) {
    size_t *cells = NULL, count = 0, j;
    const char *name = bcs[i].name ? bcs[i].name : "boundary condition";
    m->bc[i] = bcs[i];
    m->bc[i].accel_f.t = m->bc[i].accel_f.v = NULL;
    m->bc[i].load_f.t = m->bc[i].load_f.v = NULL;
    if ((st = px_lattice_tfun_copy(ctx, &m->bc[i].accel_f, &bcs[i].accel_f)) != PX_STATUS_OK ||
        (st = px_lattice_tfun_copy(ctx, &m->bc[i].load_f, &bcs[i].load_f)) != PX_STATUS_OK)
      goto fail;
    if ((bcs[i].has_accel &&
         (st = px_lattice_tfun_check(ctx, &bcs[i].accel_f, name)) != PX_STATUS_OK) ||
        (bcs[i].has_load &&
         (st = px_lattice_tfun_check(ctx, &bcs[i].load_f, name)) != PX_STATUS_OK))
      goto fail;
    if ((st = px_lattice_select(ctx, g, &bcs[i].sel, &cells, &count)) != PX_STATUS_OK) {
      px_context_prefix(ctx, "%s", name);
      goto fail;
    }
    m->bc_count[i] = count;
    for (j = 0; j < count; ++j) sig[cells[j]] |= (uint64_t)1 << i;
    px_mem_free(ctx, cells);
  }
  /* groups: 0 void, 1 no BC, then one per distinct BC combination */
  m->group_bcs =
      (uint64_t *)px_mem_calloc(ctx, "lattice.bc", PX_LATTICE_MAX_GROUPS, sizeof(uint64_t));
  if (!m->group_bcs) {
    st = PX_STATUS_NOMEM;
    goto fail;
  }
  m->ngroup = 2;
  for (c = 0; c < g->ncell; ++c) {
    size_t gi;
    if (!g->occ[c]) continue;
    if (sig[c] == 0) {
      m->group[px_lattice_index(m, c)] = 1;
      continue;
    }
    for (gi = 2; gi < m->ngroup; ++gi)
      if (m->group_bcs[gi] == sig[c]) break;
    if (gi == m->ngroup) {
      if (m->ngroup == PX_LATTICE_MAX_GROUPS) {
        st = px_context_fail(ctx, PX_STATUS_CONFIG,
                             "the boundary conditions overlap in more than %d distinct ways",
                             PX_LATTICE_MAX_GROUPS - 2);
        goto fail;
      }
      m->group_bcs[m->ngroup++] = sig[c];
    }
    m->group[px_lattice_index(m, c)] = (uint8_t)gi;
  }
  /* free for the volumetric term: no BC, or prescribed accelerations only
   * (a body force leaves a face free; a fixed DOF or a load holds it) */
  for (c = 0; c < g->ncell; ++c) {
    size_t b;
    int held = 0;
    if (!g->occ[c]) continue;
    for (b = 0; b < nbc; ++b)
      if ((sig[c] >> b) & 1u) held |= m->bc[b].fix != 0 || m->bc[b].has_load;
    m->vfree[px_lattice_index(m, c)] = (uint8_t)!held;
  }
  px_mem_free(ctx, sig);
  return PX_STATUS_OK;
fail:
  px_mem_free(ctx, sig);
  px_lattice_model_free(ctx, m);
  return st;
}

void px_lattice_model_groups(const struct px_lattice_model *m, double t, double *table) {
  size_t gi, i;
  int k;
  memset(table, 0, m->ngroup * PX_LATTICE_GROUP_STRIDE * sizeof(double));
  for (gi = 1; gi < m->ngroup; ++gi) {
    double *row = table + gi * PX_LATTICE_GROUP_STRIDE;
    unsigned fixed = 0;
    for (i = 0; i < m->nbc; ++i) {
      const struct px_lattice_bc *b = &m->bc[i];
      if (!((m->group_bcs[gi] >> i) & 1u)) continue;
      fixed |= b->fix;
      if (b->has_accel) {
        double s = px_lattice_tfun_eval(&b->accel_f, t);
        for (k = 0; k < 6; ++k) row[6 + k] += b->accel[k] * s;
      }
      if (b->has_load) {
        double s = px_lattice_tfun_eval(&b->load_f, t) / (double)m->bc_count[i];
        for (k = 0; k < 6; ++k) row[12 + k] += b->load[k] * s;
      }
    }
    for (k = 0; k < 6; ++k) row[k] = ((fixed >> k) & 1u) ? 0.0 : 1.0;
  }
}

int px_lattice_model_time_dependent(const struct px_lattice_model *m) {
  size_t i;
  for (i = 0; i < m->nbc; ++i) {
    if (m->bc[i].has_accel && m->bc[i].accel_f.kind != PX_LATTICE_TFUN_CONSTANT) return 1;
    if (m->bc[i].has_load && m->bc[i].load_f.kind != PX_LATTICE_TFUN_CONSTANT) return 1;
  }
  return 0;
}

/* The time from which a time function stays constant [s] (INFINITY: never). */
static double px_lattice_tfun_settle(const struct px_lattice_tfun *f) {
  switch (f->kind) {
    case PX_LATTICE_TFUN_RAMP: return f->t1;
    case PX_LATTICE_TFUN_HARMONIC: return f->freq > 0.0 ? INFINITY : 0.0;
    case PX_LATTICE_TFUN_TABLE: return f->n ? f->t[f->n - 1] : 0.0;
    case PX_LATTICE_TFUN_CONSTANT:
    default: return 0.0;
  }
}

double px_lattice_model_settle_time(const struct px_lattice_model *m) {
  double t = 0.0;
  size_t i;
  for (i = 0; i < m->nbc; ++i) {
    if (m->bc[i].has_accel) t = fmax(t, px_lattice_tfun_settle(&m->bc[i].accel_f));
    if (m->bc[i].has_load) t = fmax(t, px_lattice_tfun_settle(&m->bc[i].load_f));
  }
  return t;
}

/* |R(z)| of classic RK4 at z = x + i y. */
static double px_lattice_rk4_gain(double x, double y) {
  /* R = 1 + z + z^2/2 + z^3/6 + z^4/24 by Horner in complex arithmetic */
  double re = 1.0 / 24.0, im = 0.0, c[4] = {1.0 / 6.0, 0.5, 1.0, 1.0};
  int i;
  for (i = 0; i < 4; ++i) {
    double nre = re * x - im * y + c[i];
    double nim = re * y + im * x;
    re = nre;
    im = nim;
  }
  return sqrt(re * re + im * im);
}

/* Largest r with |R(r e)| <= 1 on [0, r] along the direction e of the
 * eigenvalue of the highest mode with damping ratio zeta: scan for the first
 * crossing, then bisect. Overdamped (zeta >= 1), the eigenvalue with the
 * larger |lambda| = (zeta + sqrt(zeta^2 - 1)) omega is real: the radius on
 * the negative real axis (2.785) divided by that factor, so that a large
 * zeta gives a small radius instead of one below the scan's resolution (0)
 * or, where zeta^2 overflows, a NaN gain that the scan took for stable.
 * 0 when the factor overflows. */
static double px_lattice_rk4_radius(double zeta) {
  double lo = 0.0, hi = 0.0, ex, ey, f = 1.0;
  int i;
  if (zeta >= 1.0) {
    /* (zeta - 1)(zeta + 1): no overflow before zeta does */
    f = zeta + sqrt((zeta - 1.0) * (zeta + 1.0));
    ex = -1.0;
    ey = 0.0;
  } else {
    ex = -zeta;
    ey = sqrt(1.0 - zeta * zeta);
  }
  if (!(f < INFINITY)) return 0.0; /* also NaN */
  /* |e| = 1 here: the radius lies in [2.5, 2.9] (2.83 undamped) */
  for (i = 1; i <= 4000; ++i) {
    hi = 1e-3 * i;
    if (!(px_lattice_rk4_gain(hi * ex, hi * ey) <= 1.0 + 1e-12)) break;
    lo = hi;
  }
  for (i = 0; i < 60; ++i) {
    double mid = 0.5 * (lo + hi);
    if (px_lattice_rk4_gain(mid * ex, mid * ey) <= 1.0 + 1e-12)
      lo = mid;
    else
      hi = mid;
  }
  return lo / f;
}

double px_lattice_model_stiffen(const struct px_lattice_model *m) {
  /* K(nu) = K_s(nu) + K_vol: the springs k, kt scale by 1/(1+nu) (k_b does
   * not), so omega_s^2 <= max(1, 1/(1+nu)) omega_0^2; the volumetric part
   * (with the face cubes' half springs) enters as 12 lambda/(rho h^2),
   * half the crude bound of docs/notes/lattice-poisson.md ("Time step"),
   * added as Weyl's inequality adds bounds. Checked against the highest
   * frequency of small bodies by power iteration (test_lattice_poisson
   * omega: at most 0.89 of it at nu = 0.3, 0.45, -0.5). Exactly 1 at
   * nu = 0. */
  double s = m->par.nu < 0.0 ? 1.0 / (1.0 + m->par.nu) : 1.0;
  if (m->lam > 0.0) s += 12.0 * m->lam / (PX_LATTICE_OMEGA_MAX * PX_LATTICE_OMEGA_MAX * m->par.E);
  return sqrt(s);
}

double px_lattice_model_dt_limit(const struct px_lattice_model *m,
                                 enum px_lattice_integrator integ) {
  double c = sqrt(m->par.E / m->par.rho) * px_lattice_model_stiffen(m);
  double omega = PX_LATTICE_OMEGA_MAX * c / m->grid.h;
  double zl = PX_LATTICE_ZETA_HIGH * m->par.zeta; /* link dashpots, highest mode */
  if (integ == PX_LATTICE_INTEGRATOR_LEAPFROG) {
    /* central difference with lagged dashpot velocity: omega dt <=
     * 2 (sqrt(1 + zeta^2) - zeta) and <= 1/zeta; the global damping is
     * semi-implicit (no limit). */
    double r = 2.0 * (sqrt(1.0 + zl * zl) - zl);
    if (zl > 0.0 && 1.0 / zl < r) r = 1.0 / zl;
    return r / omega;
  }
  /* RK4: the global damping shifts the eigenvalues left too */
  return px_lattice_rk4_radius(zl + 0.5 * m->par.alpha / omega) / omega;
}
