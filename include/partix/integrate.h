/* Time integrators over backend buffers. The state is one buffer of n
 * elements (f32 or f64) on any backend; the integrator's vector arithmetic
 * runs on that backend (px_buffer_lincomb), and the right-hand side is the
 * caller's callback, which usually launches the solver's force kernels on
 * the same backend. Nothing is copied to the host.
 *
 * Methods (order of the global error):
 *   euler   explicit Euler                                       1
 *   rk2     explicit midpoint rule (y + dt f(t + dt/2, y + dt/2 f(t, y)))  2
 *   rk4     classic Runge–Kutta                                  4
 *   abm4    Adams–Bashforth–Moulton 4 predictor–corrector, PECE   4
 *           (AB4 predictor, evaluate, AM4 corrector, evaluate; two
 *           right-hand sides per step), started by RK4 for the first 3
 *           steps; the history of past derivatives stays on the device
 *   verlet  velocity Verlet for x'' = a(t, x): one acceleration per step 2
 *
 * ABM4 needs equally spaced steps: a call with a dt different from the
 * previous one restarts the start-up (3 RK4 steps), keeping only the
 * derivative at the current point. Anything that changes the state from
 * outside (particles added/removed/merged, positions projected) invalidates
 * the history: call px_integrator_reset (ABM4's start-up and Verlet's cached
 * acceleration are then redone).
 *
 * Callbacks are passed to every step, never stored, so a restored integrator
 * needs no function pointers restored. A step that fails (a callback's
 * status, a device error) leaves the state partly advanced and resets the
 * history: continue from the last checkpoint. */
#ifndef PARTIX_INTEGRATE_H
#define PARTIX_INTEGRATE_H

#include <stddef.h>
#include <stdint.h>

#include "partix/backend.h"
#include "partix/context.h"
#include "partix/export.h"
#include "partix/types.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Values are stable (case files, checkpoints). */
enum px_integrator_method {
  PX_INTEGRATOR_EULER = 0,
  PX_INTEGRATOR_RK2 = 1,
  PX_INTEGRATOR_RK4 = 2,
  PX_INTEGRATOR_ABM4 = 3,
  PX_INTEGRATOR_VERLET = 4
};

/* Right-hand side of y' = f(t, y): write f(t, y) into dydt (n elements).
 * Must not modify y. Return PX_STATUS_OK or a failure (recorded in the
 * context); the step then fails with it. */
typedef enum px_status (*px_rhs_fn)(void *user, double t, struct px_buffer *y,
                                    struct px_buffer *dydt);
/* Acceleration of x'' = a(t, x): write a(t, x) into a. Must not modify x. */
typedef enum px_status (*px_accel_fn)(void *user, double t, struct px_buffer *x,
                                      struct px_buffer *a);

PX_API const char *px_integrator_method_name(enum px_integrator_method method);
/* "euler", "rk2", "rk4", "abm4", "verlet"; PX_STATUS_INVALID otherwise. */
PX_API enum px_status px_integrator_method_parse(const char *name, enum px_integrator_method *out);
/* Order of the global error (1, 2 or 4). */
PX_API int px_integrator_method_order(enum px_integrator_method method);

struct px_integrator;

/* An integrator for states of n elements of `type` (PX_DTYPE_F32 or
 * PX_DTYPE_F64) on backend be. Allocates its work buffers there. */
PX_API enum px_status px_integrator_create(struct px_backend *be, enum px_integrator_method method,
                                           enum px_dtype type, size_t n,
                                           struct px_integrator **out);
/* NULL-safe. */
PX_API void px_integrator_free(struct px_integrator *it);
PX_API enum px_integrator_method px_integrator_method(const struct px_integrator *it);
PX_API size_t px_integrator_size(const struct px_integrator *it);
/* Change n (the work buffers follow); resets the history. */
PX_API enum px_status px_integrator_resize(struct px_integrator *it, size_t n);

/* Advance y' = f(t, y) from t to t + dt in place (y: n elements). For every
 * method but verlet. dt must be finite and non-zero. */
PX_API enum px_status px_integrator_step(struct px_integrator *it, px_rhs_fn f, void *user,
                                         double t, double dt, struct px_buffer *y);
/* Advance x'' = a(t, x) (x, v: n elements each) from t to t + dt by
 * velocity Verlet:  x += dt v + dt²/2 a_n;  a_{n+1} = a(t + dt, x);
 * v += dt/2 (a_n + a_{n+1}).  a_n is kept from the previous step. */
PX_API enum px_status px_integrator_step_verlet(struct px_integrator *it, px_accel_fn a, void *user,
                                                double t, double dt, struct px_buffer *x,
                                                struct px_buffer *v);
/* Forget the history (see above). The step counter is kept. */
PX_API void px_integrator_reset(struct px_integrator *it);

/* Checkpoint state: steps taken, the dt of the history and the history
 * vectors, newest first (abm4: k = 0 is f(t_n, y_n), 1 is f_{n−1}, ...,
 * up to 4 vectors; verlet: k = 0 is a(t_n, x_n); other methods: none).
 * To restore: px_integrator_set_state, then px_integrator_history_write for
 * every k < history_length; the continuation is then bitwise identical on
 * the cpu backend with the same thread count. */
PX_API uint64_t px_integrator_steps(const struct px_integrator *it);
PX_API double px_integrator_dt(const struct px_integrator *it);
PX_API int px_integrator_history_length(const struct px_integrator *it);
/* n elements of vector k (0 <= k < history_length) to / from host memory. */
PX_API enum px_status px_integrator_history_read(struct px_integrator *it, int k, void *host);
PX_API enum px_status px_integrator_history_write(struct px_integrator *it, int k,
                                                  const void *host);
PX_API enum px_status px_integrator_set_state(struct px_integrator *it, uint64_t steps, double dt,
                                              int history_length);

#ifdef __cplusplus
}
#endif
#endif
