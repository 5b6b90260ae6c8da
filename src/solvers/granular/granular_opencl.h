/* The granular solver's opencl engine (granular_opencl.c): device-resident
 * state driven from a host mirror system used for outputs and checkpoints. */
#ifndef PX_GRAN_OPENCL_H
#define PX_GRAN_OPENCL_H

#include "partix/backend.h"
#include "solvers/granular/system.h"

struct px_gran_cl;

#ifdef PX_HAVE_OPENCL
/* Upload a prepared mirror system h (borrowed for the engine's life). */
enum px_status px_gran_cl_create(struct px_backend *be, struct px_gran_sys *h,
                                 struct px_gran_cl **out);
void px_gran_cl_free(struct px_gran_cl *e);
/* Frames of the start on the device. */
enum px_status px_gran_cl_prepare(struct px_gran_cl *e);
/* One velocity Verlet step on the device. */
enum px_status px_gran_cl_step(struct px_gran_cl *e);
/* Bring the state, wall slots and statistics into the mirror (and rebuild
 * its lists for the outputs). */
enum px_status px_gran_cl_download(struct px_gran_cl *e);
/* Device lists and histories in checkpoints (with the mirror's sections). */
enum px_status px_gran_cl_save(struct px_gran_cl *e, struct px_checkpoint_writer *w);
enum px_status px_gran_cl_load(struct px_gran_cl *e, struct px_checkpoint *ck);
/* Replace the device state by the mirror's (positions, velocities,
 * accelerations, wall slots; the lists are rebuilt at the next step). */
enum px_status px_gran_cl_upload(struct px_gran_cl *e);
/* Contacts (pairs of particle ids i < j with overlap > 0) found through the
 * device's neighbour lists, sorted: for tests. */
enum px_status px_gran_cl_contacts(struct px_gran_cl *e, int32_t **pairs, size_t *np);
#endif

#endif
