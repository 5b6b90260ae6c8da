/* Work stealing over a fixed list of tasks for the threads of one OpenMP
 * team (internal; not installed).
 *
 * Tasks [0, n) are cut into one contiguous chunk per thread, balanced by a
 * weight per task. A thread runs its own chunk front to back; when it is
 * empty, it takes tasks from the back of the other threads' chunks. So:
 *   - locality: with the same cut in every phase of a step (and every step)
 *     a thread runs the same tasks, and their data stays in its core's
 *     cache. `omp for schedule(dynamic, 1)` hands the tasks out in turn, so
 *     that each phase reads from the other cores' caches what the previous
 *     phase wrote (measured: 3x the cycles of the loops over the state on 2
 *     threads at 10^4 discs);
 *   - balance: a thread that is late or descheduled has its tail taken by
 *     the others, as with dynamic scheduling.
 * Which thread runs a task must not change a result: the callers' tasks
 * write disjoint data, and their sums are per task.
 *
 * Each chunk is a (front, back) pair packed into one 64-bit atomic: the
 * owner takes the front, a thief the back, each by compare-and-swap. A
 * queue set serves one phase: initialize it before the parallel region (a
 * queue per phase), or separate its reuse by a barrier. A team smaller than
 * the queues' thread count (OpenMP may give fewer threads) is correct: the
 * chunks of the missing threads are stolen. */
#ifndef PX_CORE_STEAL_H
#define PX_CORE_STEAL_H

#include <sched.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#define PX_STEAL_MAX 64 /* threads */

struct px_steal_q {
  _Alignas(64) _Atomic uint64_t fb; /* front (low 32 bits), back (high 32 bits) */
};

struct px_steal {
  int nt; /* threads the chunks were cut for */
  struct px_steal_q q[PX_STEAL_MAX];
};

/* Cut n tasks into nt chunks of about equal total weight (weight NULL: equal
 * weights), into bounds[0..nt] (bounds[0] = 0, bounds[nt] = n). */
static inline void px_steal_cut(const double *weight, int n, int nt, int *bounds) {
  double total = 0, cum = 0;
  int t, i = 0;
  if (nt < 1) nt = 1;
  if (!weight) {
    for (t = 0; t <= nt; ++t) bounds[t] = (int)((long)n * t / nt);
    return;
  }
  for (t = 0; t < n; ++t) total += weight[t];
  bounds[0] = 0;
  for (t = 1; t < nt; ++t) {
    const double goal = total * t / nt;
    /* the first task whose start is at or past the goal's nearer side */
    while (i < n && cum + 0.5 * weight[i] < goal) cum += weight[i++];
    bounds[t] = i;
  }
  bounds[nt] = n;
}

/* Queues for the chunks [bounds[t], bounds[t + 1]), t < nt; 1 <= nt <=
 * PX_STEAL_MAX, 0 <= bounds[0] <= ... <= bounds[nt]. */
static inline void px_steal_init(struct px_steal *w, const int *bounds, int nt) {
  int t;
  w->nt = nt;
  for (t = 0; t < nt; ++t)
    atomic_init(&w->q[t].fb,
                (uint64_t)(uint32_t)bounds[t] | (uint64_t)(uint32_t)bounds[t + 1] << 32);
}

/* Take from queue q: its front (own) or its back (steal). -1: empty. */
static inline int px_steal_take(struct px_steal_q *q, int back) {
  uint64_t v = atomic_load_explicit(&q->fb, memory_order_relaxed);
  for (;;) {
    const uint32_t f = (uint32_t)v, b = (uint32_t)(v >> 32);
    uint64_t nv;
    if (f >= b) return -1;
    nv = back ? (uint64_t)f | (uint64_t)(b - 1) << 32 : (uint64_t)(f + 1) | (uint64_t)b << 32;
    if (atomic_compare_exchange_weak_explicit(&q->fb, &v, nv, memory_order_acq_rel,
                                              memory_order_relaxed))
      return (int)(back ? b - 1 : f);
  }
}

/* The next task for thread t of the team: its own chunk's front, else the
 * back of the next non-empty chunk after its own. -1: no task is left. */
static inline int px_steal_next(struct px_steal *w, int t) {
  int u, k;
  if (t < w->nt && (k = px_steal_take(&w->q[t], 0)) >= 0) return k;
  for (u = 1; u <= w->nt; ++u) {
    const int v = (t + u) % w->nt;
    if (v != t && (k = px_steal_take(&w->q[v], 1)) >= 0) return k;
  }
  return -1;
}

/* One turn of a wait loop: a pause; every 256th turn, the core is yielded
 * (the thread waited for may be queued behind this one on the same core
 * when another process took the other). *turns counts the turns. */
static inline void px_steal_pause(unsigned *turns) {
  if ((++*turns & 255u) == 0) {
    sched_yield();
    return;
  }
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

#endif
