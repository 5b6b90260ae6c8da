/* The serial parts of a step that the host engines share, the cpu engine
 * (vortex_cpu.c, vortex_diffusive.c) and the reference (vortex_ref.c): each
 * engine finds the neighbours, panels and pair sums its own way (trees, FMM
 * and OpenMP; plain loops over all of them) and hands them to these, so that
 * the physics of a block around the sums is written once (the per-pair and
 * per-panel formulas are vortex_kernel.h's). Private to the vortex solver. */
#ifndef PX_VORTEX_HOST_H
#define PX_VORTEX_HOST_H

#include "solvers/vortex/vortex_core.h"

/* The step's start (ops->begin): room for the step's newborns; a non-finite
 * vortex stops the run here, named, before its velocity spreads. */
enum px_status px_vortex_host_begin(struct px_vortex_engine *e);

/* Block 1: the two Gauss points of each panel k, where the far field of the
 * wake is summed, into e->rhs_u[2k, 2k+1] (x) and e->rhs_v (y). */
void px_vortex_gauss_points(struct px_vortex_engine *e);
/* Block 1 after the engine's right-hand side: e->sol[0..n) holds minus the
 * tangential velocity of the free stream and the wake at each panel; adds the
 * bodies' rows (the circulation `absorbed` returns, NULL: none), solves for
 * the sheet (checks: finite, no runaway) and sheds it as newborn vortices
 * (e->born_first, e->n_born). */
enum px_status px_vortex_sheet_shed(struct px_vortex_engine *e, double vx, double vy,
                                    const double *absorbed);

/* Block 1's count of newborns is capped at VX_NEWBORN_MAX per panel
 * (vortex_kernel.h): once a run, when a panel of sheet intensities sol[0..n)
 * is capped, a warning with the effective gamma_max there (the largest
 * capped |gamma L| / 64). The host engines call it from their shed, the
 * opencl engine when its count kernel flags a capped panel. */
void px_vortex_newborn_cap_warn(struct px_vortex_engine *e, const double *sol);

/* Block 2, the sheet near the wall: px_vortex_sheet_term (vortex_sheet.h). */
/* Block 2's newborns (the last e->n_born): the mean of the inner (0) and
 * outer (gamma tau) limits of the sheet; then every velocity checked finite. */
enum px_status px_vortex_newborn_convective(struct px_vortex_engine *e);

/* Block 3's end: the first vortex with a non-finite diffusive velocity
 * stops the run, named (PX_STATUS_NUMERIC); PX_STATUS_OK when all are finite. */
enum px_status px_vortex_diffusive_finite(struct px_vortex_engine *e);
/* Block 3 for one vortex: its diffusive velocity [m/s] from its np
 * neighbours (offsets x_i - x_j in pdx, pdy, circulations in pg; 8 entries of
 * slack past np) and the pc panels within reach pl (vortex_diffusive.c). */
void px_vortex_vvd_velocity(const struct px_vortex_engine *e, double *pdx, double *pdy, double *pg,
                            size_t np, const uint32_t *pl, size_t pc, double gi, double ei,
                            double xi, double yi, int32_t born, double vcap, double *wx,
                            double *wy);

/* Block 4, before the wall vorticity: each panel's domain radius e->pe (the
 * mean eps* of its newborns, eps_min without). After it (e->omega filled):
 * the forces, moments, coefficients and impulse diagnostics of every body. */
void px_vortex_panel_radius(struct px_vortex_engine *e);
void px_vortex_forces(struct px_vortex_engine *e);

/* The first panel the path (x0, y0) -> (x1, y1) crosses, or -1 (an engine's
 * own search; *oom set when out of memory). */
typedef int32_t (*px_vortex_crossed_fn)(struct px_vortex_engine *e, double x0, double y0, double x1,
                                        double y1, int *oom);

/* Block 5 into e->xn, e->yn: explicit Euler, or with rk2 Heun's method, whose
 * second stage runs the engine's own blocks (the sheet of the predicted wake
 * with absorbed NULL, the convective and diffusive velocities). */
struct px_vortex_stages {
  enum px_status (*generation)(struct px_vortex_engine *e, double vx, double vy,
                               const double *absorbed);
  enum px_status (*convective)(struct px_vortex_engine *e, double vx, double vy);
  enum px_status (*diffusive)(struct px_vortex_engine *e);
  px_vortex_crossed_fn crossed;
  /* NULL, or crossed for the paths (x0, y0)_i -> (x1, y1)_i, i in [lo, hi),
   * into hit[i] on the engine's threads: the same results, found faster */
  void (*crossings)(struct px_vortex_engine *e, const double *x0, const double *y0,
                    const double *x1, const double *y1, size_t lo, size_t hi, int32_t *hit,
                    int *oom);
};
enum px_status px_vortex_move(struct px_vortex_engine *e, const struct px_vortex_stages *st);

/* Block 6 after the engine's e->hit: the circulation each panel absorbed. */
void px_vortex_absorb(struct px_vortex_engine *e);

/* Block 7. drop: the moved positions (xn, yn) of the vortices left, those not
 * absorbed, far or empty, into w->x, w->y (stable) and w->n; returns the
 * count left. Their other fields stay where they were: survivor k's at
 * index e->hit[k] (the absorption has read e->hit), until px_vortex_merge
 * gathers them (or px_vortex_drop_finish, where a step fails between the
 * two). Over all threads (each a contiguous share, at most 64) from
 * VX_HOST_PARALLEL vortices. merge: with e->tree built over the positions left
 * and e->partner holding each vortex's nearest eligible partner by sorted
 * position (-1: none), the merges applied in sorted order (none that
 * carries circulation into a body) and the wake compacted in sorted order,
 * its fields gathered through e->hit. (Until 2026-11-28 the drop moved all
 * nine fields and the merge moved four of them again: on one thread, 2% of
 * a step at 55k vortices on 2 cores.) */
size_t px_vortex_drop(struct px_vortex_engine *e);
void px_vortex_drop_finish(struct px_vortex_engine *e);
enum px_status px_vortex_merge(struct px_vortex_engine *e, px_vortex_crossed_fn crossed);

#endif
