/* Part of the template fmm_cpu.h, included by it once per precision after
 * fmm_cpu_ops.h: the interaction lists, the dual-tree traversal of one
 * target cell, and the upward and downward passes over the trees. */
#ifndef PX_FMM_VW
#error "nbody/fmm_cpu_passes.h is a part of nbody/fmm_cpu.h"
#endif

/* ------------------------------- passes -------------------------------- */

static int px_fmm_push(struct px_fmm *fmm, struct px_fmm_thread *th, size_t *len, uint32_t c) {
  if (*len >= th->stack_cap / sizeof(uint32_t) &&
      px_fmm_reserve(fmm->ctx, "fmm traversal stack", (void **)&th->stack, &th->stack_cap,
                     (*len + 1) * sizeof(uint32_t)))
    return -1;
  th->stack[(*len)++] = c;
  return 0;
}

static int px_fmm_list_add(struct px_fmm *fmm, struct px_fmm_thread *th, size_t *len, uint32_t kind,
                           uint32_t c) {
  if (2 * (*len + 1) > th->list_cap / sizeof(uint32_t) &&
      px_fmm_reserve(fmm->ctx, "fmm interaction lists", (void **)&th->list, &th->list_cap,
                     2 * (*len + 1) * sizeof(uint32_t)))
    return -1;
  th->list[2 * *len] = kind;
  th->list[2 * *len + 1] = c;
  ++*len;
  return 0;
}

static int px_fmm_pass_add(struct px_fmm *fmm, struct px_fmm_thread *th, int pool, uint32_t c) {
  if (th->pass_len[pool] >= th->pass_cap[pool] / sizeof(uint32_t) &&
      px_fmm_reserve(fmm->ctx, "fmm hand-down lists", (void **)&th->pass[pool], &th->pass_cap[pool],
                     (th->pass_len[pool] + 1) * sizeof(uint32_t)))
    return -1;
  th->pass[pool][th->pass_len[pool]++] = c;
  return 0;
}

/* Order of an interaction with convergence ratio rho: the smallest q in
 * [2, p] with rho^q <= E = ρ_ref^p, i.e. q = ceil(ln E / ln rho). */
static int px_fmm_order(const struct px_fmm_run *R, double rho) {
  const double q = rho > 0.0 ? ceil(R->lnE / log(rho) - 1e-9) : 2.0;
  return q >= (double)R->p ? R->p : (q <= 2.0 ? 2 : (int)q);
}

/* The far field of target cell t: M2L (sorted by order, in blocks) and P2L
 * into its local expansion. Returns 1 if the local received anything. */
static int px_fmm_far(const struct px_fmm_run *R, struct px_fmm_thread *th,
                      const struct px_fmm_cell *ct, size_t nl, px_real *lre, px_real *lim) {
  const struct px_fmm_tree *S = R->S;
  size_t count[PX_FMM_MAX_ORDER + 2], k, nm = 0;
  int q, l, any = 0;
  memset(count, 0, sizeof count);
  for (k = 0; k < nl; ++k) {
    const uint32_t kind = th->list[2 * k] & 0xffu, s = th->list[2 * k + 1];
    q = (int)(th->list[2 * k] >> 8);
    if (kind == PX_FMM_P2L) {
      px_fmm_p2l(R, S->cell[s].begin, S->cell[s].end, ct, q, lre, lim);
      any = 1;
      ++th->p2l;
      th->p2l_sources += (double)(S->cell[s].end - S->cell[s].begin);
    } else if (kind == PX_FMM_M2L) {
      ++count[R->p - q + 1]; /* counting sort, largest order first */
      ++nm;
    }
  }
  if (nm > 0) {
    const int qmax = R->p; /* row bound of the lane sums */
    px_real *X = th->buf, *Y = X + (size_t)qmax * 2 * PX_FMM_VW;
    px_real *Ar = Y + (size_t)qmax * 2 * PX_FMM_VW, *Ai = Ar + (size_t)qmax * PX_FMM_VW;
    uint32_t *sorted = th->sorted;
    int top = 0;
    for (k = 1; k < PX_FMM_MAX_ORDER + 2; ++k) count[k] += count[k - 1];
    for (k = 0; k < nl; ++k)
      if ((th->list[2 * k] & 0xffu) == PX_FMM_M2L) {
        q = (int)(th->list[2 * k] >> 8);
        sorted[2 * count[R->p - q]] = th->list[2 * k + 1];
        sorted[2 * count[R->p - q]++ + 1] = (uint32_t)q;
      }
    top = (int)sorted[1];
    for (k = 0; k < (size_t)top * PX_FMM_VW; ++k) Ar[k] = Ai[k] = PX_R(0.0);
    for (k = 0; k < nm; k += PX_FMM_VW) {
      const int m = nm - k < (size_t)PX_FMM_VW ? (int)(nm - k) : PX_FMM_VW;
      uint32_t src[PX_FMM_VW];
      int j;
      q = (int)sorted[2 * k + 1];
      for (j = 0; j < m; ++j) src[j] = sorted[2 * (k + (size_t)j)];
      px_fmm_m2l_block(R, ct, src, m, q, X, Y, Ar, Ai);
      th->m2l_terms += (double)m * (double)q * (double)q;
    }
    for (l = 0; l < top; ++l) {
      px_real sr = PX_R(0.0), si = PX_R(0.0);
      int j;
      for (j = 0; j < PX_FMM_VW; ++j) {
        sr += Ar[l * PX_FMM_VW + j];
        si += Ai[l * PX_FMM_VW + j];
      }
      if (l & 1) {
        lre[l] -= sr;
        lim[l] -= si;
      } else {
        lre[l] += sr;
        lim[l] += si;
      }
    }
    th->m2l += nm;
    any = 1;
  }
  return any;
}

/* One target cell t: its local expansion (L2L + the accepted far field),
 * its hand-down list (appended to the thread's pool `pool`; the parent's
 * list is read from wherever pass_info says), and for a leaf the velocities
 * of its targets. */
static void px_fmm_target(const struct px_fmm_run *R, struct px_fmm_thread *th, int tid, int pool,
                          size_t t) {
  struct px_fmm *fmm = R->fmm;
  const struct px_fmm_tree *S = R->S, *T = R->T;
  const struct px_fmm_cell *ct = T->cell + t;
  const int tleaf = ct->nchild == 0;
  const double nt = (double)(ct->end - ct->begin);
  px_real *lre = R->lc + t * R->stride, *lim = lre + R->half;
  size_t sp = 0, nl = 0, nm = 0, k, pass0 = th->pass_len[pool];
  int has = 0, q;
  /* the source cells to examine */
  if (t == 0) {
    if (px_fmm_push(fmm, th, &sp, 0)) goto oom;
    if (R->root2 != UINT32_MAX && px_fmm_push(fmm, th, &sp, R->root2)) goto oom;
  } else {
    const size_t par = ct->parent;
    const uint32_t *info = fmm->pass_info + 3 * par;
    if (info[2] > 0) { /* a parent that handed nothing down may own no list */
      const uint32_t *in = fmm->thr[info[0] / 2].pass[info[0] % 2] + info[1];
      for (k = info[2]; k-- > 0;)
        if (px_fmm_push(fmm, th, &sp, in[k])) goto oom;
    }
    if (fmm->has_local[par]) {
      const px_real *pl = R->lc + par * R->stride;
      px_fmm_l2l(R, T->cell + par, ct, pl, pl + R->half, lre, lim);
      has = 1;
    }
  }
  if (!has)
    for (q = 0; q < R->p; ++q) lre[q] = lim[q] = PX_R(0.0);
  while (sp > 0) {
    const uint32_t s = th->stack[--sp];
    const struct px_fmm_cell *cs = S->cell + s;
    const double dx = ct->cx - cs->cx, dy = ct->cy - cs->cy, d = sqrt(dx * dx + dy * dy);
    const double rsum = ct->R + cs->R, dt = d - ct->R, ds = d - cs->R;
    const double slack =
        4.0 * DBL_EPSILON * (fabs(ct->cx) + fabs(ct->cy) + fabs(cs->cx) + fabs(cs->cy));
    if (cs->R <= R->rho * dt && ct->R <= R->rho * ds && d - rsum >= R->eps_mac + slack) {
      /* convergence ratios of the multipole (a) and local (b) series */
      const double a = cs->R / dt, b = ct->R / ds;
      const double ns = (double)(cs->end - cs->begin);
      const int qm = px_fmm_order(R, a > b ? a : b);
      double best = R->cost_m2l * (double)qm * (double)qm, c;
      uint32_t kind = PX_FMM_M2L;
      q = qm;
      /* P2L and M2P (orders <= qm) only when they can be cheaper */
      if (R->cost_exp * (double)qm * ns < best) {
        const int qb = px_fmm_order(R, b);
        c = R->cost_exp * (double)qb * ns;
        if (c < best) best = c, kind = PX_FMM_P2L, q = qb;
      }
      if (tleaf && R->cost_exp * (double)qm * nt < best) {
        const int qa = px_fmm_order(R, a);
        c = R->cost_exp * (double)qa * nt;
        if (c < best) best = c, kind = PX_FMM_M2P, q = qa;
      }
      if (tleaf && nt * ns < best) kind = PX_FMM_P2P, q = 0;
      if (px_fmm_list_add(fmm, th, &nl, kind | (uint32_t)q << 8, s)) goto oom;
      nm += kind == PX_FMM_M2L;
    } else if (tleaf) {
      if (cs->nchild == 0) {
        if (px_fmm_list_add(fmm, th, &nl, PX_FMM_P2P, s)) goto oom;
      } else {
        for (k = cs->nchild; k-- > 0;)
          if (px_fmm_push(fmm, th, &sp, (uint32_t)(cs->child + k))) goto oom;
      }
    } else if (cs->nchild == 0 || cs->R <= ct->R) {
      if (px_fmm_pass_add(fmm, th, pool, s)) goto oom;
    } else {
      for (k = cs->nchild; k-- > 0;)
        if (px_fmm_push(fmm, th, &sp, (uint32_t)(cs->child + k))) goto oom;
    }
  }
  fmm->pass_info[3 * t] = (uint32_t)(2 * tid + pool);
  fmm->pass_info[3 * t + 1] = (uint32_t)pass0;
  fmm->pass_info[3 * t + 2] = (uint32_t)(th->pass_len[pool] - pass0);
  if (px_fmm_reserve(fmm->ctx, "fmm scratch", &th->buf, &th->buf_cap,
                     px_fmm_m2l_scratch(R->p) * sizeof(px_real)) ||
      px_fmm_reserve(fmm->ctx, "fmm interaction lists", (void **)&th->sorted, &th->sorted_cap,
                     2 * (nm + 1) * sizeof(uint32_t)))
    goto oom;
  has |= px_fmm_far(R, th, ct, nl, lre, lim);
  fmm->has_local[t] = (uint8_t)has;
  if (tleaf) {
    const size_t b = ct->begin, e = ct->end;
    size_t nn = 0, need = 0;
    px_real *gx, *gy, *gg;
    if (has) {
      px_fmm_l2p(R, ct, lre, lim);
    } else {
      for (k = b; k < e; ++k) R->U[k] = R->V[k] = PX_R(0.0);
    }
    for (k = 0; k < nl; ++k) {
      const uint32_t kind = th->list[2 * k] & 0xffu, s = th->list[2 * k + 1];
      if (kind == PX_FMM_M2P) {
        const px_real *a = R->mp + (size_t)s * R->stride;
        px_fmm_m2p(R, b, e, S->cell + s, (int)(th->list[2 * k] >> 8), a, a + R->half);
        ++th->m2p;
        th->m2p_targets += nt;
      } else if (kind == PX_FMM_P2P) {
        need += S->cell[s].end - S->cell[s].begin;
      }
    }
    if (need > 0) {
      if (px_fmm_reserve(fmm->ctx, "fmm scratch", &th->buf, &th->buf_cap,
                         3 * need * sizeof(px_real) + 192))
        goto oom;
      gx = th->buf;
      gy = gx + need;
      gg = gy + need;
      for (k = 0; k < nl; ++k) {
        const uint32_t kind = th->list[2 * k] & 0xffu, s = th->list[2 * k + 1];
        if (kind == PX_FMM_P2P) {
          const size_t sb = S->cell[s].begin, c = S->cell[s].end - sb;
          memcpy(gx + nn, R->sx + sb, c * sizeof(px_real));
          memcpy(gy + nn, R->sy + sb, c * sizeof(px_real));
          memcpy(gg + nn, R->sg + sb, c * sizeof(px_real));
          nn += c;
          ++th->p2p_cells;
        }
      }
      px_fmm_p2p(R, b, e, gx, gy, gg, nn);
      th->p2p_pairs += (double)nn * nt;
    }
  }
  return;
oom:
  th->failed = 1;
}

/* Bottom-up work of one cell (its children are done): geometry, and for
 * the source tree the multipole (P2M at a leaf, M2M from the children). */
static void px_fmm_up_cell(const struct px_fmm_run *R, const struct px_fmm_tree *t,
                           const px_real *x, const px_real *y, int multipoles, double rmin,
                           size_t c) {
  struct px_fmm_cell *cell = t->cell + c;
  px_real *a = R->mp + c * R->stride;
  if (cell->nchild == 0) {
    px_fmm_geo_leaf(x, y, rmin, cell, t->box + 4 * c);
    if (multipoles) px_fmm_p2m(R, cell, a, a + R->half);
  } else {
    px_fmm_geo_parent(t, c, rmin);
    if (multipoles) {
      const size_t c0 = cell->child, c1 = c0 + cell->nchild;
      size_t k;
      int q;
      for (q = 0; q < R->p; ++q) a[q] = a[R->half + (size_t)q] = PX_R(0.0);
      for (k = c0; k < c1; ++k) {
        const px_real *ac = R->mp + k * R->stride;
        px_fmm_m2m(R, cell, t->cell + k, ac, ac + R->half, a, a + R->half);
      }
    }
  }
}

/* The subtree of cell c bottom-up (post-order), by one thread. */
static void px_fmm_up_tree(const struct px_fmm_run *R, const struct px_fmm_tree *t,
                           const px_real *x, const px_real *y, int multipoles, double rmin,
                           size_t c) {
  const size_t c0 = t->cell[c].child, c1 = c0 + t->cell[c].nchild;
  size_t k;
  for (k = c0; k < c1; ++k) px_fmm_up_tree(R, t, x, y, multipoles, rmin, k);
  px_fmm_up_cell(R, t, x, y, multipoles, rmin, c);
}

/* The target subtree of cell c top-down (pre-order), by one thread; the
 * hand-down lists live on the thread's pool 1 as a stack. */
static void px_fmm_down_tree(const struct px_fmm_run *R, struct px_fmm_thread *th, int tid,
                             size_t c) {
  const size_t mark = th->pass_len[1];
  const size_t c0 = R->T->cell[c].child, c1 = c0 + R->T->cell[c].nchild;
  size_t k;
  px_fmm_target(R, th, tid, 1, c);
  for (k = c0; k < c1 && !th->failed; ++k) px_fmm_down_tree(R, th, tid, k);
  th->pass_len[1] = mark;
}
