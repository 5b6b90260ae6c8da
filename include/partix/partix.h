/* partix: particle (mesh-free) mechanics on CPUs and OpenCL devices.
 * Umbrella header: includes the whole public API. */
#ifndef PARTIX_H
#define PARTIX_H

#include "partix/version.h"
#include "partix/export.h"
#include "partix/status.h"
#include "partix/context.h"
#include "partix/memory.h"
#include "partix/timer.h"
#include "partix/progress.h"
#include "partix/rng.h"
#include "partix/types.h"
#include "partix/file.h"
#include "partix/checkpoint.h"
#include "partix/vtk.h"
#include "partix/csv.h"
#include "partix/colormap.h"
#include "partix/figure.h"
#include "partix/case.h"
#include "partix/backend.h"
#include "partix/neighbors.h"
#include "partix/nbody.h"
#include "partix/integrate.h"
#include "partix/sim.h"
#include "partix/results.h"

#endif
