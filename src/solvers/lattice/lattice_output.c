/* Outputs of the lattice solver: VTK snapshots (.vti ImageData, cell data on
 * the grid, for box-shaped bodies; .vtu voxels of the body otherwise; plus a
 * .pvd series), the time series probes.csv (probes, the body's largest von
 * Mises stress and displacement and where, broken links, damping, the
 * quasi-static convergence estimate), pictures of von Mises stress on the
 * deformed body (PNG); the end-of-run plots and the summary.json quantities
 * are lattice_plots.c. Fields are computed by the engine where the state
 * lives and fetched once per output step. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/ioutil.h"
#include "partix/file.h"
#include "partix/memory.h"
#include "solvers/lattice/lattice.h"
#include "solvers/summary.h"

static void px_lattice_voxels_free(struct px_lattice *L) {
  px_mem_free(L->ctx, L->vx_conn);
  px_mem_free(L->ctx, L->vx_xyz);
  px_mem_free(L->ctx, L->vx_count);
  px_mem_free(L->ctx, L->vx_cell);
  L->vx_conn = NULL;
  L->vx_xyz = L->vx_count = NULL;
  L->vx_cell = NULL;
}

void px_lattice_output_free(struct px_lattice *L) {
  px_vtk_free(L->vtk);
  px_vtk_series_close(L->pvd);
  px_csv_close(L->csv);
  px_figure_free(L->fig);
  px_mem_free(L->ctx, L->fu);
  px_mem_free(L->ctx, L->fv);
  px_mem_free(L->ctx, L->fs);
  px_mem_free(L->ctx, L->fvm);
  px_mem_free(L->ctx, L->flinks);
  px_mem_free(L->ctx, L->sacc);
  L->sacc = NULL;
  px_mem_free(L->ctx, L->pic_x);
  px_mem_free(L->ctx, L->pic_y);
  px_mem_free(L->ctx, L->pic_v);
  L->pic_x = L->pic_y = L->pic_v = NULL;
  L->pic_cap = 0;
  px_lattice_voxels_free(L);
  L->vtk = NULL;
  L->pvd = NULL;
  L->csv = NULL;
  L->fig = NULL;
}

/* A resumed run: delete the picture an earlier segment drew only because it
 * ended off the picture schedule (struct px_sim_output), once, from
 * whichever output comes first. */
enum px_status px_lattice_resume_clean(struct px_lattice *L, const struct px_sim_output *o) {
  char name[64], path[PX_LATTICE_PATH_MAX];
  if (!o->resumed || o->render || L->cleaned) return PX_STATUS_OK;
  L->cleaned = 1;
  if (o->drop_picture < 0) return PX_STATUS_OK;
  snprintf(name, sizeof name, "von_mises_%06ld.png", o->drop_picture);
  PX_TRY(px_file_join(L->ctx, path, sizeof path, o->dir, name));
  if (remove(path) != 0 && errno != ENOENT)
    return px_context_fail(L->ctx, PX_STATUS_IO, "cannot delete %s: %s", path, strerror(errno));
  return PX_STATUS_OK;
}

/* Fields at the output step (cached: several outputs fall on one step). */
enum px_status px_lattice_fields_room(struct px_lattice *L) {
  size_t n = L->m.nalloc;
  if (L->fu) return PX_STATUS_OK;
  L->fu = (double *)px_mem_alloc(L->ctx, "lattice.fields", 3 * n * sizeof(double));
  L->fv = (double *)px_mem_alloc(L->ctx, "lattice.fields", 3 * n * sizeof(double));
  L->fs = (double *)px_mem_alloc(L->ctx, "lattice.fields", 6 * n * sizeof(double));
  L->fvm = (double *)px_mem_alloc(L->ctx, "lattice.fields", n * sizeof(double));
  L->flinks = (uint8_t *)px_mem_alloc(L->ctx, "lattice.fields", n);
  if (!L->fu || !L->fv || !L->fs || !L->fvm || !L->flinks) return PX_STATUS_NOMEM;
  return PX_STATUS_OK;
}

enum px_status px_lattice_fetch(struct px_lattice *L, const struct px_sim_output *o) {
  struct px_lattice_fields f;
  if (L->fields_step == o->step && L->fu) return PX_STATUS_OK;
  /* over ranks the gather brought them (rank 0; the engine holds a window) */
  if (L->ranks)
    return px_context_fail(L->ctx, PX_STATUS_INVALID,
                           "lattice: the fields of step %ld were not gathered", o->step);
  PX_TRY(px_lattice_fields_room(L));
  f.u = L->fu;
  f.v = L->fv;
  f.sigma = L->fs;
  f.vm = L->fvm;
  f.links = L->flinks;
  PX_TRY(L->vt->fields(L->e, o->time, px_sim_dt(L->sim), &f));
  L->fields_step = o->step;
  L->fields_time = o->time;
  return PX_STATUS_OK;
}

/* What a probes.csv row reads, u and von Mises, into L->fu and L->fvm: the
 * fields fetched for this step already, or those two alone (the others,
 * and the link evaluations that the velocities need, are skipped; the
 * fields stay marked stale for the snapshot and picture). One rank. */
static enum px_status px_lattice_fetch_row(struct px_lattice *L, const struct px_sim_output *o) {
  struct px_lattice_fields f;
  if (L->fields_step == o->step && L->fu) return PX_STATUS_OK;
  if (L->ranks) return px_lattice_fetch(L, o);
  PX_TRY(px_lattice_fields_room(L));
  memset(&f, 0, sizeof f);
  f.u = L->fu;
  f.vm = L->fvm;
  return L->vt->fields(L->e, o->time, px_sim_dt(L->sim), &f);
}

static int px_lattice_popcount(unsigned x) {
  int n = 0;
  for (; x; x &= x - 1) ++n;
  return n;
}

/* The occupied cells as VTK voxels on their shared corner points
 * (undeformed), for bodies that do not fill their bounding box, into
 * L->vx_*: the grid does not change during a run, so this is built at the
 * first snapshot only. */
static enum px_status px_lattice_voxels(struct px_lattice *L) {
  const struct px_lattice_grid *g = &L->m.grid;
  size_t c0 = (size_t)g->n[0] + 1, c1 = (size_t)g->n[1] + 1, c2 = (size_t)g->n[2] + 1;
  size_t ncorner = c0 * c1 * c2, np = 0, e = 0, c;
  int64_t *id;
  if (L->vx_count) return PX_STATUS_OK; /* allocated last: all built */
  id = (int64_t *)px_mem_alloc(L->ctx, "lattice.vtk", ncorner * sizeof(int64_t));
  L->vx_conn = (int64_t *)px_mem_alloc(L->ctx, "lattice.vtk", 8 * g->count * sizeof(int64_t));
  L->vx_cell = (size_t *)px_mem_alloc(L->ctx, "lattice.vtk", g->count * sizeof(size_t));
  if (!id || !L->vx_conn || !L->vx_cell) goto nomem;
  for (c = 0; c < ncorner; ++c) id[c] = -1;
  for (c = 0; c < g->ncell; ++c) {
    size_t i = c % (size_t)g->n[0], j = c / (size_t)g->n[0] % (size_t)g->n[1];
    size_t k = c / ((size_t)g->n[0] * (size_t)g->n[1]);
    int q;
    if (!g->occ[c]) continue;
    for (q = 0; q < 8; ++q) {
      size_t corner =
          (i + (size_t)(q & 1)) + c0 * ((j + (size_t)(q >> 1 & 1)) + c1 * (k + (size_t)(q >> 2)));
      if (id[corner] < 0) id[corner] = (int64_t)np++;
      L->vx_conn[8 * e + (size_t)q] = id[corner];
    }
    L->vx_cell[e++] = c;
  }
  L->vx_xyz = (float *)px_mem_alloc(L->ctx, "lattice.vtk", 3 * (np ? np : 1) * sizeof(float));
  L->vx_count = (float *)px_mem_calloc(L->ctx, "lattice.vtk", np ? np : 1, sizeof(float));
  if (!L->vx_xyz || !L->vx_count) goto nomem;
  for (c = 0; c < ncorner; ++c) {
    if (id[c] < 0) continue;
    L->vx_xyz[3 * id[c]] = (float)(g->origin[0] + g->h * (double)(c % c0));
    L->vx_xyz[3 * id[c] + 1] = (float)(g->origin[1] + g->h * (double)(c / c0 % c1));
    L->vx_xyz[3 * id[c] + 2] = (float)(g->origin[2] + g->h * (double)(c / (c0 * c1)));
  }
  for (c = 0; c < 8 * g->count; ++c) L->vx_count[L->vx_conn[c]] += 1.0f;
  px_mem_free(L->ctx, id);
  L->vx_npoint = np;
  return PX_STATUS_OK;
nomem:
  px_mem_free(L->ctx, id);
  px_lattice_voxels_free(L);
  return PX_STATUS_NOMEM;
}

/* A snapshot: a box-shaped body as ImageData (lattice_NNNNNN.vti, cell data
 * on its grid), any other as UnstructuredGrid (lattice_NNNNNN.vtu: only the
 * body's voxels, cell data as in the .vti plus a point-data displacement
 * averaged over the voxels sharing each corner, so that ParaView's Warp By
 * Vector applies directly). */
enum px_status px_lattice_snapshot(void *state, const struct px_sim_output *o) {
  struct px_lattice *L = (struct px_lattice *)state;
  const struct px_lattice_model *m = &L->m;
  const struct px_lattice_grid *g = &m->grid;
  int box = g->count == g->ncell;
  size_t nc = box ? g->ncell : g->count, c, dims[3];
  double origin[3], spacing[3];
  float *u = NULL, *v = NULL, *s = NULL, *vm = NULL, *pu = NULL;
  uint8_t *occ = NULL, *broken = NULL;
  char name[64], path[PX_LATTICE_PATH_MAX];
  enum px_status st = PX_STATUS_OK;
  int a;
  if (o->render) return PX_STATUS_OK;
  PX_TRY(px_lattice_resume_clean(L, o));
  PX_TRY(px_lattice_fetch(L, o));
  if (!L->vtk) PX_TRY(px_vtk_create(L->ctx, &L->vtk));
  if (!L->pvd) {
    PX_TRY(px_file_join(L->ctx, path, sizeof path, o->dir, "lattice.pvd"));
    if (o->resumed)
      PX_TRY(px_vtk_series_open_resume(L->ctx, path, o->keep_snapshot, &L->pvd));
    else
      PX_TRY(px_vtk_series_open(L->ctx, path, &L->pvd));
  }
  u = (float *)px_mem_alloc(L->ctx, "lattice.vtk", 3 * nc * sizeof(float));
  v = (float *)px_mem_alloc(L->ctx, "lattice.vtk", 3 * nc * sizeof(float));
  s = (float *)px_mem_alloc(L->ctx, "lattice.vtk", 6 * nc * sizeof(float));
  vm = (float *)px_mem_alloc(L->ctx, "lattice.vtk", nc * sizeof(float));
  occ = (uint8_t *)px_mem_alloc(L->ctx, "lattice.vtk", nc);
  broken = (uint8_t *)px_mem_alloc(L->ctx, "lattice.vtk", nc);
  if (!u || !v || !s || !vm || !occ || !broken) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  if (!box && (st = px_lattice_voxels(L)) != PX_STATUS_OK) goto done;
  for (c = 0; c < nc; ++c) {
    size_t cell = box ? c : L->vx_cell[c], i = px_lattice_index(m, cell);
    int k;
    for (k = 0; k < 3; ++k) {
      u[3 * c + (size_t)k] = (float)L->fu[3 * i + (size_t)k];
      v[3 * c + (size_t)k] = (float)L->fv[3 * i + (size_t)k];
    }
    /* VTK symmetric tensor order: XX YY ZZ XY YZ XZ */
    for (k = 0; k < 6; ++k) s[6 * c + (size_t)k] = (float)L->fs[6 * i + (size_t)k];
    vm[c] = (float)L->fvm[i];
    occ[c] = g->occ[cell];
    broken[c] = (uint8_t)px_lattice_popcount((unsigned)(m->links[i] & ~L->flinks[i]));
  }
  px_vtk_reset(L->vtk);
  if (box) {
    for (a = 0; a < 3; ++a) {
      dims[a] = (size_t)g->n[a] + 1;
      origin[a] = g->origin[a];
      spacing[a] = g->h;
    }
    st = px_vtk_set_image(L->vtk, dims, origin, spacing);
  } else {
    /* corner displacement: mean over the voxels sharing the corner */
    size_t npoint = L->vx_npoint;
    pu = (float *)px_mem_calloc(L->ctx, "lattice.vtk", 3 * (npoint ? npoint : 1), sizeof(float));
    if (!pu) {
      st = PX_STATUS_NOMEM;
      goto done;
    }
    for (c = 0; c < nc; ++c)
      for (a = 0; a < 8; ++a) {
        size_t p = (size_t)L->vx_conn[8 * c + (size_t)a];
        pu[3 * p] += u[3 * c];
        pu[3 * p + 1] += u[3 * c + 1];
        pu[3 * p + 2] += u[3 * c + 2];
      }
    for (c = 0; c < npoint; ++c)
      for (a = 0; a < 3; ++a) pu[3 * c + (size_t)a] /= L->vx_count[c];
    if ((st = px_vtk_set_points_aos(L->vtk, PX_DTYPE_F32, npoint, 3, L->vx_xyz)) == PX_STATUS_OK &&
        (st = px_vtk_set_cells_uniform(L->vtk, nc, PX_VTK_CELL_VOXEL, 8, L->vx_conn)) ==
            PX_STATUS_OK)
      st = px_vtk_add_array_aos(L->vtk, PX_VTK_ASSOC_POINT, "displacement", PX_DTYPE_F32, npoint, 3,
                                pu);
  }
  if (st != PX_STATUS_OK) goto done;
  if ((st = px_vtk_add_scalar(L->vtk, PX_VTK_ASSOC_CELL, "occupancy", PX_DTYPE_U8, nc, occ)) ||
      (st = px_vtk_add_array_aos(L->vtk, PX_VTK_ASSOC_CELL, "displacement", PX_DTYPE_F32, nc, 3,
                                 u)) ||
      (st = px_vtk_add_array_aos(L->vtk, PX_VTK_ASSOC_CELL, "velocity", PX_DTYPE_F32, nc, 3, v)) ||
      (st = px_vtk_add_array_aos(L->vtk, PX_VTK_ASSOC_CELL, "stress", PX_DTYPE_F32, nc, 6, s)) ||
      (st = px_vtk_add_scalar(L->vtk, PX_VTK_ASSOC_CELL, "von_mises", PX_DTYPE_F32, nc, vm)) ||
      (st = px_vtk_add_scalar(L->vtk, PX_VTK_ASSOC_CELL, "broken_links", PX_DTYPE_U8, nc, broken)))
    goto done;
  px_vtk_set_time(L->vtk, o->time, (int64_t)o->step);
  snprintf(name, sizeof name, "lattice_%06ld.%s", o->step, box ? "vti" : "vtu");
  if ((st = px_file_join(L->ctx, path, sizeof path, o->dir, name)) != PX_STATUS_OK) goto done;
  if ((st = px_vtk_write(L->vtk, path)) != PX_STATUS_OK) goto done;
  st = px_vtk_series_add(L->pvd, o->time, name);
done:
  px_mem_free(L->ctx, u);
  px_mem_free(L->ctx, v);
  px_mem_free(L->ctx, s);
  px_mem_free(L->ctx, vm);
  px_mem_free(L->ctx, occ);
  px_mem_free(L->ctx, broken);
  px_mem_free(L->ctx, pu);
  return st;
}

size_t px_lattice_columns(const struct px_lattice *L) {
  return 1 + 4 * L->nprobe + PX_LATTICE_COL_END - (L->quasi_static ? 0 : 1);
}

/* Headers of probes.csv ("name [unit]") into names[ncol]. */
static void px_lattice_column_names(const struct px_lattice *L, struct px_sim_columns *c) {
  static const char *const probe[4] = {"ux [m]", "uy [m]", "uz [m]", "von_mises [Pa]"};
  static const char *const tail[PX_LATTICE_COL_END] = {
      "broken_links [-]",       "damping [1/s]",          "max_von_mises [Pa]",
      "max_von_mises_x [m]",    "max_von_mises_y [m]",    "max_von_mises_z [m]",
      "max_displacement [m]",   "max_displacement_x [m]", "max_displacement_y [m]",
      "max_displacement_z [m]", "static_error [-]"};
  size_t i, k, base = 1 + 4 * L->nprobe, ncol = px_lattice_columns(L);
  px_sim_columns_set(c, 0, "t [s]");
  for (i = 0; i < L->nprobe; ++i)
    for (k = 0; k < 4; ++k)
      px_sim_columns_set(c, 1 + 4 * i + k, "%s.%s", L->probes[i].name, probe[k]);
  for (k = 0; base + k < ncol; ++k) px_sim_columns_set(c, base + k, "%s", tail[k]);
}

/* The element (grid cell) with the largest value of von Mises stress
 * (which = 0) or of |u| (which = 1) in the fetched fields; ties go to the
 * first cell. */
size_t px_lattice_argmax(const struct px_lattice *L, int which, double *value) {
  const struct px_lattice_grid *g = &L->m.grid;
  size_t c, best = 0;
  double vmax = -1.0;
  for (c = 0; c < g->ncell; ++c) {
    size_t i = px_lattice_index(&L->m, c);
    const double *u = L->fu + 3 * i;
    double v;
    if (!g->occ[c]) continue;
    v = which == 0 ? L->fvm[i] : sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    if (v > vmax) {
      vmax = v;
      best = c;
    }
  }
  *value = vmax < 0.0 ? 0.0 : vmax;
  return best;
}

/* The centre of grid cell c [m], rounded to 15 significant digits: the
 * products of h come out a few ulps off (0.0032500000000000003), the
 * reported positions read as written (0.00325). */
void px_lattice_centre_tidy(const struct px_lattice *L, size_t c, double x[3]) {
  char buf[32];
  int a;
  px_lattice_grid_centre(&L->m.grid, c, x);
  for (a = 0; a < 3; ++a) {
    snprintf(buf, sizeof buf, "%.15g", x[a]);
    x[a] = strtod(buf, NULL);
  }
}

enum px_status px_lattice_series(void *state, const struct px_sim_output *o) {
  struct px_lattice *L = (struct px_lattice *)state;
  size_t ncol = px_lattice_columns(L), base = 1 + 4 * L->nprobe, i, k, col, cell;
  double *row;
  enum px_status st = PX_STATUS_OK;
  /* over ranks without the whole gather: the row's inputs reduced
   * (px_lattice_gather_series) */
  const int reduced = L->ranks && L->series_step == o->step && L->fields_step != o->step;
  if (o->render) return PX_STATUS_OK;
  PX_TRY(px_lattice_resume_clean(L, o));
  if (!reduced) PX_TRY(px_lattice_fetch_row(L, o));
  if (!L->csv) {
    struct px_sim_columns cols;
    PX_TRY(px_sim_columns_alloc(L->ctx, &cols, ncol));
    px_lattice_column_names(L, &cols);
    st = px_sim_csv_open(L->ctx, o, "probes.csv", ncol, cols.name, o->keep_series, &L->csv);
    px_sim_columns_free(L->ctx, &cols);
    /* 17 digits: the times read back exactly, as px_csv_open_resume compares
     * them with the resume time (12 digits can round a row past it) */
    if (st == PX_STATUS_OK) st = px_csv_set_precision(L->csv, 17);
    PX_TRY(st);
  }
  row = (double *)px_mem_alloc(L->ctx, "lattice.csv", ncol * sizeof(double));
  if (!row) return PX_STATUS_NOMEM;
  row[0] = o->time;
  col = 1;
  for (i = 0; i < L->nprobe; ++i) {
    const struct px_lattice_probe *p = &L->probes[i];
    double acc[4] = {0, 0, 0, 0};
    for (k = 0; !reduced && k < p->count; ++k) {
      size_t j = p->cells[k];
      acc[0] += L->fu[3 * j];
      acc[1] += L->fu[3 * j + 1];
      acc[2] += L->fu[3 * j + 2];
      acc[3] += L->fvm[j];
    }
    for (k = 0; k < 4; ++k) row[col++] = (reduced ? L->sacc[4 * i + k] : acc[k]) / (double)p->count;
  }
  row[base + PX_LATTICE_COL_BROKEN] = (double)L->vt->broken(L->e);
  row[base + PX_LATTICE_COL_DAMPING] = L->alpha;
  if (reduced) {
    const double *m = L->sacc + 4 * L->nprobe;
    row[base + PX_LATTICE_COL_VM] = m[0];
    px_lattice_centre_tidy(L, (size_t)m[1], &row[base + PX_LATTICE_COL_VM + 1]);
    row[base + PX_LATTICE_COL_U] = m[2];
    px_lattice_centre_tidy(L, (size_t)m[3], &row[base + PX_LATTICE_COL_U + 1]);
  } else {
    cell = px_lattice_argmax(L, 0, &row[base + PX_LATTICE_COL_VM]);
    px_lattice_centre_tidy(L, cell, &row[base + PX_LATTICE_COL_VM + 1]);
    cell = px_lattice_argmax(L, 1, &row[base + PX_LATTICE_COL_U]);
    px_lattice_centre_tidy(L, cell, &row[base + PX_LATTICE_COL_U + 1]);
  }
  if (L->quasi_static) row[base + PX_LATTICE_COL_STATIC] = L->static_error;
  st = px_csv_row(L->csv, row);
  px_mem_free(L->ctx, row);
  return st;
}

/* Picture: von Mises stress on the deformed body. The surface elements (a
 * missing neighbour) are projected (isometric, or along an axis) with the
 * displacement magnified and drawn far to near as discs of the element size,
 * coloured by von Mises stress. */
struct px_lattice_dot {
  double depth;
  size_t i;
};

static int px_lattice_dot_cmp(const void *a, const void *b) {
  double x = ((const struct px_lattice_dot *)a)->depth,
         y = ((const struct px_lattice_dot *)b)->depth;
  size_t i = ((const struct px_lattice_dot *)a)->i, j = ((const struct px_lattice_dot *)b)->i;
  if (x < y) return -1;
  if (x > y) return 1;
  return i < j ? -1 : (i > j ? 1 : 0);
}

static void px_lattice_view_axes(enum px_lattice_view view, double r[3], double up[3],
                                 double d[3]) {
  double v[3] = {0.35, -0.8, 0.5}, n;
  int k;
  memset(r, 0, 3 * sizeof(double));
  memset(up, 0, 3 * sizeof(double));
  switch (view) {
    case PX_LATTICE_VIEW_TOP:
      r[0] = 1;
      up[1] = 1;
      d[0] = 0, d[1] = 0, d[2] = 1;
      return;
    case PX_LATTICE_VIEW_FRONT:
      r[0] = 1;
      up[2] = 1;
      d[0] = 0, d[1] = -1, d[2] = 0;
      return;
    case PX_LATTICE_VIEW_SIDE:
      r[1] = 1;
      up[2] = 1;
      d[0] = 1, d[1] = 0, d[2] = 0;
      return;
    case PX_LATTICE_VIEW_ISO:
    default: break;
  }
  n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  for (k = 0; k < 3; ++k) d[k] = v[k] / n;
  /* right = z x d, up = d x right */
  r[0] = -d[1];
  r[1] = d[0];
  r[2] = 0;
  n = sqrt(r[0] * r[0] + r[1] * r[1]);
  r[0] /= n;
  r[1] /= n;
  up[0] = d[1] * r[2] - d[2] * r[1];
  up[1] = d[2] * r[0] - d[0] * r[2];
  up[2] = d[0] * r[1] - d[1] * r[0];
}

enum px_status px_lattice_picture(void *state, const struct px_sim_output *o) {
  struct px_lattice *L = (struct px_lattice *)state;
  const struct px_lattice_model *m = &L->m;
  const struct px_lattice_grid *g = &m->grid;
  struct px_lattice_dot *dots = NULL;
  double *x = NULL, *y = NULL, *val = NULL, r[3], up[3], d[3], umax = 0.0, size = 0.0, scale;
  double vmax = 0.0, at[3];
  size_t c, n = 0, k, hot;
  char path[PX_LATTICE_PATH_MAX], name[64], title[256], label[160];
  enum px_status st = PX_STATUS_OK;
  static const char *const axis_x[4] = {"projected x [m]", "x [m]", "x [m]", "y [m]"};
  static const char *const axis_y[4] = {"projected y [m]", "y [m]", "z [m]", "z [m]"};
  PX_TRY(px_lattice_resume_clean(L, o));
  PX_TRY(px_lattice_fetch(L, o));
  if (!L->fig) {
    PX_TRY(px_figure_create(L->ctx, 1200, 800, &L->fig));
    px_figure_set_colormap(L->fig, PX_COLORMAP_VIRIDIS);
    px_figure_set_field(L->fig, "von Mises", "Pa");
    px_figure_set_background(L->fig, 1.0, 1.0, 1.0);
    px_figure_set_color(L->fig, 0.85, 0.1, 0.1);
    px_figure_set_line_width(L->fig, 2.0);
  }
  px_figure_reset(L->fig);
  px_lattice_view_axes(L->view, r, up, d);
  for (k = 0; k < 3; ++k) size = fmax(size, g->n[k] * g->h);
  for (c = 0; c < g->ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    double u2;
    if (!g->occ[c]) continue;
    u2 = L->fu[3 * i] * L->fu[3 * i] + L->fu[3 * i + 1] * L->fu[3 * i + 1] +
         L->fu[3 * i + 2] * L->fu[3 * i + 2];
    umax = fmax(umax, sqrt(u2));
    if (m->links[i] != 63u) ++n;
  }
  scale = L->picture_scale > 0 ? L->picture_scale : (umax > 0 ? 0.05 * size / umax : 1.0);
  L->drawn_scale = scale;
  if (n > L->pic_cap) {
    px_mem_free(L->ctx, L->pic_x);
    px_mem_free(L->ctx, L->pic_y);
    px_mem_free(L->ctx, L->pic_v);
    L->pic_x = (double *)px_mem_alloc(L->ctx, "lattice.png", n * sizeof(double));
    L->pic_y = (double *)px_mem_alloc(L->ctx, "lattice.png", n * sizeof(double));
    L->pic_v = (double *)px_mem_alloc(L->ctx, "lattice.png", n * sizeof(double));
    L->pic_cap = L->pic_x && L->pic_y && L->pic_v ? n : 0;
  }
  x = L->pic_x;
  y = L->pic_y;
  val = L->pic_v;
  dots = (struct px_lattice_dot *)px_mem_alloc(L->ctx, "lattice.png", (n ? n : 1) * sizeof *dots);
  if (!dots || (n > 0 && L->pic_cap == 0)) {
    st = PX_STATUS_NOMEM;
    goto done;
  }
  n = 0;
  for (c = 0; c < g->ncell; ++c) {
    size_t i = px_lattice_index(m, c);
    double p[3];
    if (!g->occ[c] || m->links[i] == 63u) continue;
    px_lattice_grid_centre(g, c, p);
    for (k = 0; k < 3; ++k) p[k] += scale * L->fu[3 * i + k];
    dots[n].depth = p[0] * d[0] + p[1] * d[1] + p[2] * d[2];
    dots[n].i = c;
    ++n;
  }
  qsort(dots, n, sizeof *dots, px_lattice_dot_cmp);
  for (k = 0; k < n; ++k) {
    size_t i = px_lattice_index(m, dots[k].i);
    double p[3];
    int a;
    px_lattice_grid_centre(g, dots[k].i, p);
    for (a = 0; a < 3; ++a) p[a] += scale * L->fu[3 * i + (size_t)a];
    x[k] = p[0] * r[0] + p[1] * r[1] + p[2] * r[2];
    y[k] = p[0] * up[0] + p[1] * up[1] + p[2] * up[2];
    val[k] = L->fvm[i];
  }
  /* the case title (the colour bar names the field), cut to keep the line
   * inside the picture: about 70 characters */
  snprintf(label, sizeof label, "(displacement x %.3g)", scale);
  if (!L->title[0])
    snprintf(title, sizeof title, "von Mises stress %s", label);
  else if (strlen(L->title) + strlen(label) + 1 > 70)
    snprintf(title, sizeof title, "%.*s... %s", (int)(66 - strlen(label)), L->title, label);
  else
    snprintf(title, sizeof title, "%s %s", L->title, label);
  px_figure_set_title(L->fig, title);
  px_figure_set_time(L->fig, o->time, "s");
  px_figure_set_axis_labels(L->fig, axis_x[L->view], axis_y[L->view]);
  px_figure_fit_view(L->fig, 0.05);
  /* colour range: 0 .. the largest von Mises stress of the whole body (also
   * of an element inside it), marked where it is: the peaks at clamp edges
   * and under point loads are where a part fails, and the scale says so */
  hot = px_lattice_argmax(L, 0, &vmax);
  px_figure_set_range(L->fig, 0.0, vmax > 0.0 ? vmax : 1.0);
  /* radius 0.72 h: a disc covers its cell's square (half diagonal 0.707 h),
   * so an axis view shows the surface without gaps */
  if ((st = px_figure_add_discs(L->fig, PX_DTYPE_F64, n, x, y, NULL, 0.72 * g->h, val)) !=
      PX_STATUS_OK)
    goto done;
  if (vmax > 0.0) {
    size_t i = px_lattice_index(m, hot);
    double p[3];
    int a;
    px_lattice_centre_tidy(L, hot, at);
    for (a = 0; a < 3; ++a) p[a] = at[a] + scale * L->fu[3 * i + (size_t)a];
    snprintf(label, sizeof label, "max %.3g Pa at (%.4g, %.4g, %.4g) m", vmax, at[0], at[1], at[2]);
    if ((st = px_figure_add_marker(L->fig, p[0] * r[0] + p[1] * r[1] + p[2] * r[2],
                                   p[0] * up[0] + p[1] * up[1] + p[2] * up[2], label)) !=
        PX_STATUS_OK)
      goto done;
  }
  snprintf(name, sizeof name, "von_mises_%06ld.png", o->step);
  if ((st = px_file_join(L->ctx, path, sizeof path, o->dir, name)) != PX_STATUS_OK) goto done;
  st = px_figure_write_png(L->fig, path);
done:
  px_mem_free(L->ctx, dots);
  return st;
}
