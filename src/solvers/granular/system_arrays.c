/* The table of the granular system's per-particle arrays (pointer, element
 * size, count per particle, kept across rebuilds, checkpoint name): what
 * growing, permuting, saving and loading the particles walk over. */
#include <stdio.h>
#include <string.h>

#include "solvers/granular/system_impl.h"
#include "solvers/granular/wall_kernel.h"

/* "s->slots.seg" -> "granular.p.slots.seg" (checkpoint section names),
 * "s->hist[k][d]" -> "granular.p.histkd.N" (N: the suffix index `ni`) */
static const char *px_gran_arr_name(char (*names)[48], size_t n, size_t ni, const char *expr) {
  const char *p = strncmp(expr, "s->", 3) == 0 ? expr + 3 : expr;
  size_t k = 0, o = 0;
  char *out = names[n];
  o = (size_t)snprintf(out, 48, "granular.p.");
  for (k = 0; p[k] && o < 47; ++k) {
    const char ch = p[k];
    if ((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
        ch == '.' || ch == '_')
      out[o++] = ch;
  }
  if (strchr(p, '[')) o += (size_t)snprintf(out + o, 48 - o, ".%zu", ni);
  out[o < 48 ? o : 47] = '\0';
  return out;
}

size_t px_gran_arrays(struct px_gran_sys *s, struct px_gran_arr *a) {
  size_t n = 0;
  char(*names)[48] = s->arr_names;
  const size_t ss = s->ssize, cs = s->csize, W = PX_GRAN_WSLOTS;
  int k, d;
  /* the suffix of an indexed array's section is its position in this table
   * as it was when the format was set: four arrays that preceded the
   * histories (foy, fvy, now interleaved into fox, fvx; ffy, ftq, now in
   * ff) count still, so that checkpoints written before keep their names */
  size_t name_shift = 0;
  /* ints: the address of the pointer; reals: of the union's raw member.
   * Both name the section after the field expression (checkpoint format) */
#define PX_GRAN_ARR_AT(at, ptr, es, pp, kp)                             \
  (a[n].p = (at), a[n].esize = (es), a[n].per = (pp), a[n].keep = (kp), \
   a[n].name = (kp) ? px_gran_arr_name(names, n, n + name_shift, #ptr) : NULL, ++n)
#define PX_GRAN_ARR(ptr, es, pp, kp) PX_GRAN_ARR_AT((void **)&(ptr), ptr, es, pp, kp)
#define PX_GRAN_REALS(u, es, pp, kp) PX_GRAN_ARR_AT(&(u).p, u, es, pp, kp)
  PX_GRAN_REALS(s->x, ss, 1, 1);
  PX_GRAN_REALS(s->y, ss, 1, 1);
  PX_GRAN_REALS(s->vx, ss, 1, 1);
  PX_GRAN_REALS(s->vy, ss, 1, 1);
  PX_GRAN_REALS(s->w, ss, 1, 1);
  PX_GRAN_REALS(s->fx, ss, 1, 1);
  PX_GRAN_REALS(s->fy, ss, 1, 1);
  PX_GRAN_REALS(s->tq, ss, 1, 1);
  PX_GRAN_REALS(s->ax0, ss, 1, 0);
  PX_GRAN_REALS(s->ay0, ss, 1, 0);
  PX_GRAN_REALS(s->aw0, ss, 1, 0);
  PX_GRAN_REALS(s->r, cs, 1, 1);
  PX_GRAN_REALS(s->m, cs, 1, 1);
  PX_GRAN_REALS(s->im, cs, 1, 1);
  PX_GRAN_REALS(s->iI, cs, 1, 1);
  PX_GRAN_REALS(s->xr, ss, 1, 0);
  a[n - 1].name = "granular.p.xr";
  PX_GRAN_REALS(s->yr, ss, 1, 0);
  a[n - 1].name = "granular.p.yr";
  PX_GRAN_REALS(s->fox, cs, 2, 0);
  PX_GRAN_REALS(s->fvx, cs, 2, 0);
  name_shift = 2;
  PX_GRAN_REALS(s->fvw, cs, 1, 0);
  PX_GRAN_REALS(s->ff, cs, 4, 0);
  name_shift = 4;
  PX_GRAN_ARR(s->id, sizeof(int32_t), 1, 1);
  if (s->with_abm) {
    for (k = 0; k < 3; ++k)
      for (d = 0; d < 5; ++d) PX_GRAN_REALS(s->hist[k][d], ss, 1, 1);
    for (d = 0; d < 5; ++d) PX_GRAN_REALS(s->xp[d], ss, 1, 0);
    for (d = 0; d < 3; ++d) PX_GRAN_REALS(s->fa[d], ss, 1, 0);
  }
  PX_GRAN_ARR(s->slots.seg, sizeof(int), W, 1);
  PX_GRAN_ARR(s->slots.seg0, sizeof(int), W, 1);
  PX_GRAN_ARR(s->slots.step0, sizeof(int), W, 1);
  PX_GRAN_REALS(s->slots.t0, cs, W, 1);
  PX_GRAN_REALS(s->slots.te, cs, W, 1);
  PX_GRAN_REALS(s->slots.xi, cs, W, 1);
  PX_GRAN_REALS(s->slots.th, cs, W, 1);
  PX_GRAN_REALS(s->slots.dm, cs, W, 1);
  PX_GRAN_REALS(s->slots.dp, cs, W, 1);
  PX_GRAN_REALS(s->slots.imp, cs, W, 1);
  PX_GRAN_REALS(s->slots.slw, cs, W, 1);
  PX_GRAN_REALS(s->slots.arc, cs, W, 1);
  PX_GRAN_REALS(s->slots.tim, cs, W, 1);
#undef PX_GRAN_ARR
#undef PX_GRAN_REALS
#undef PX_GRAN_ARR_AT
  return n;
}
