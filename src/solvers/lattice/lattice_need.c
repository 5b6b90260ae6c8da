/* The lattice's memory before it is built (px_lattice_need): the host and
 * device bytes of a case's grid for the engine, outputs and checkpoints,
 * over ranks those of a rank's window, refused at lattice.h when the
 * machine or device cannot hold them. */
#include <stdio.h>

#include "core/comm.h"
#include "core/text.h"
#include "partix/memory.h"
#include "solvers/lattice/lattice.h"
#include "solvers/lattice/lattice_c.h"

/* Host memory of a run on the layout lay [B], the engine's (engine_host)
 * included: the larger of the setup's peak (occupancy, its cropped copy,
 * the connectivity check's two size_t per cell; then the model's link,
 * group and vfree bytes, the BC signatures and a selection, 8 B per cell
 * each) and the run's (model; fields of every padded entry, 13 doubles and
 * the link flags; per element the snapshot's floats (54 B), the voxels of a
 * .vtu (72 B) and the picture's discs (40 B); per corner point 24 B; a host
 * copy of the state in double for checkpoints and initial velocities). */
static double px_lattice_host_bytes(const struct px_lattice_layout *lay, double engine_host) {
  double ncell = (double)lay->ncell, nalloc = (double)lay->nalloc;
  double corners = ((double)lay->n[0] + 1) * ((double)lay->n[1] + 1) * ((double)lay->n[2] + 1);
  double setup = fmax(18.0 * ncell, 17.0 * ncell + 3.0 * nalloc);
  double model = ncell + 3.0 * nalloc; /* occupancy, links, group, vfree */
  double outputs =
      nalloc * (13.0 * sizeof(double) + 1.0) + ncell * (54.0 + 72.0 + 40.0) + 24.0 * corners;
  double state = nalloc * (sizeof(struct lt_el) + 1.0);
  return fmax(setup, model + engine_host + outputs + state);
}

/* Over `ranks` ranks, the layout of the largest engine window, estimated
 * before the grid is evaluated (the cuts balance elements, the estimate
 * cells): the rank grid the scheme takes (link-once: 1 x ranks, else the
 * extents' choice), a block's share of each cut extent rounded up and its
 * halo: one cell on each side, or for row blocks, which may start inside a
 * plane, three planes (lattice_ranks.c, px_lattice_ranks_window). */
static void px_lattice_window_estimate(const struct px_lattice_layout *lay,
                                       enum px_lattice_scheme scheme, int ranks,
                                       struct px_lattice_layout *w) {
  int py = 1, pz = ranks, n[3];
  if (scheme == PX_LATTICE_SCHEME_LINK_ONCE ||
      px_lattice_ranks_grid(lay->n, ranks, &py, &pz) != 0) {
    py = 1;
    pz = ranks;
  }
  n[0] = lay->n[0];
  n[1] = py > 1 ? (lay->n[1] + py - 1) / py + 2 : lay->n[1];
  n[2] = (lay->n[2] + pz - 1) / pz + (py > 1 ? 2 : 3);
  if (n[1] > lay->n[1]) n[1] = lay->n[1];
  if (n[2] > lay->n[2]) n[2] = lay->n[2];
  px_lattice_model_layout(n, w);
}

/* Refuse, before anything of the size of the grid is allocated, a lattice
 * that this machine (or its device) cannot hold or the engine cannot index:
 * at lattice.h, the key that sets the size, with the figures. Records the
 * host estimate in L->need_host (the probes add to it). */
enum px_status px_lattice_need(struct px_lattice *L, struct px_case *c,
                               const struct px_lattice_grid *g,
                               const struct px_lattice_engine_opts *o) {
  struct px_lattice_layout lay, win;
  struct px_lattice_need en;
  char what[384], need[32], have[32], *value = NULL;
  enum px_status st = PX_STATUS_OK;
  const int ranks = px_comm_size(px_context_comm(L->ctx));
  double gather = 0.0;
  px_lattice_model_layout(g->n, &lay);
  L->vt->need(&lay, o, &en);
  if (ranks > 1 && L->vt->set_block) {
    /* each engine holds its window; rank 0 also the whole state and
     * fields, and the gather's window copies and piece (lattice_gather.c) */
    px_lattice_window_estimate(&lay, en.scheme, ranks, &win);
    L->vt->need(&win, o, &en);
    gather = (double)win.nalloc * (2.0 * sizeof(struct lt_el) + 1.0) + 216.0 * 65536.0;
  }
  snprintf(what, sizeof what,
           "the lattice of %d x %d x %d cells of h = %g m (the body's bounding box; %zu entries "
           "with padding): model, %s engine state in %s precision%s, output fields and "
           "checkpoint buffers",
           g->n[0], g->n[1], g->n[2], g->h, lay.nalloc, L->vt->name,
           o->precision == PX_PRECISION_SINGLE ? "single" : "double",
           gather > 0.0 ? " (rank 0's window of the grid)" : "");
  if (en.nalloc_max > 0 && (double)lay.nalloc > en.nalloc_max)
    return px_case_fail(c, "lattice.h",
                        "the lattice of %d x %d x %d cells of h = %g m (the body's bounding box) "
                        "has %zu entries with padding; %s: at most %.0f (use a larger h)",
                        g->n[0], g->n[1], g->n[2], g->h, lay.nalloc,
                        en.index_why ? en.index_why : "the engine", en.nalloc_max);
  L->need_host = px_lattice_host_bytes(&lay, en.host + gather);
  PX_TRY(px_sim_require_memory(L->sim, L->need_host, "lattice.h", what));
  if (px_case_value_text(c, "lattice.h", &value) != PX_STATUS_OK) value = NULL;
  if (en.device > 0 && en.device_have > 0 && en.device > en.device_have) {
    px_text_bytes(en.device, 0, need, sizeof need);
    px_text_bytes(en.device_have, 1, have, sizeof have);
    st = px_case_fail(c, "lattice.h",
                      "lattice.h = %s needs %s of device memory for %s; the %s device has %s",
                      value ? value : "?", need, what, L->vt->name, have);
  } else if (en.buffer_max > 0 && en.buffer > en.buffer_max) {
    px_text_bytes(en.buffer, 0, need, sizeof need);
    px_text_bytes(en.buffer_max, 1, have, sizeof have);
    st = px_case_fail(c, "lattice.h",
                      "lattice.h = %s needs a device buffer of %s for %s; the %s device "
                      "allocates at most %s at once",
                      value ? value : "?", need, what, L->vt->name, have);
  }
  px_mem_free(L->ctx, value);
  return st;
}
