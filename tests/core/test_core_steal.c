/* The work-stealing queues (core/steal.h): the cut balances the weights and
 * keeps the tasks in order; every task of a phase is handed out exactly
 * once, whatever the team size (smaller than the cut, a thread stalled, or
 * many threads racing), and a thread runs its own chunk front to back
 * before it steals. */
#include <omp.h>
#include <string.h>

#include "core/steal.h"
#include "px_test.h"

static void test_cut(void) {
  int b[5];
  const double w[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  const double heavy[8] = {7, 1, 1, 1, 1, 1, 1, 1};
  px_steal_cut(NULL, 10, 4, b);
  PX_CHECK(b[0] == 0 && b[1] == 2 && b[2] == 5 && b[3] == 7 && b[4] == 10);
  px_steal_cut(w, 8, 2, b);
  PX_CHECK(b[0] == 0 && b[1] == 4 && b[2] == 8);
  /* the first task carries half the weight: it is a chunk of its own */
  px_steal_cut(heavy, 8, 2, b);
  PX_CHECK(b[0] == 0 && b[1] == 1 && b[2] == 8);
  /* more threads than tasks: empty chunks, still ordered */
  px_steal_cut(w, 2, 4, b);
  PX_CHECK(b[0] == 0 && b[4] == 2);
  PX_CHECK(b[0] <= b[1] && b[1] <= b[2] && b[2] <= b[3] && b[3] <= b[4]);
  /* no tasks */
  px_steal_cut(w, 0, 3, b);
  PX_CHECK(b[0] == 0 && b[1] == 0 && b[3] == 0);
}

/* One thread alone: its own chunk front to back, then the others' chunks
 * from their backs. */
static void test_order_one_thread(void) {
  struct px_steal w;
  const int b[4] = {0, 3, 5, 8};
  int got[8], k = 0, t;
  px_steal_init(&w, b, 3);
  while ((t = px_steal_next(&w, 1)) >= 0 && k < 8) got[k++] = t;
  PX_CHECK(k == 8);
  PX_CHECK(got[0] == 3 && got[1] == 4);                /* own chunk [3, 5) */
  PX_CHECK(got[2] == 7 && got[3] == 6 && got[4] == 5); /* chunk 2 from its back */
  PX_CHECK(got[5] == 2 && got[6] == 1 && got[7] == 0); /* then chunk 0 */
  PX_CHECK(px_steal_next(&w, 0) == -1 && px_steal_next(&w, 2) == -1);
}

/* Teams of 1 to 4 threads over queues cut for 2, 4 or 8 threads; thread 0
 * stalls a while before it starts. Every task must be run once, and a
 * thread's own tasks come front first. */
static void test_exactly_once(void) {
  enum { N = 997, ROUNDS = 200 };
  static int runs[N];
  int team, cut;
  for (cut = 2; cut <= 8; cut *= 2)
    for (team = 1; team <= 4; team *= 2) {
      int round, bad = 0, own_first = 1;
      for (round = 0; round < ROUNDS; ++round) {
        struct px_steal w;
        int b[PX_STEAL_MAX + 1];
        px_steal_cut(NULL, N, cut, b);
        px_steal_init(&w, b, cut);
        memset(runs, 0, sizeof runs);
#pragma omp parallel num_threads(team) reduction(min : own_first)
        {
          const int me = omp_get_thread_num();
          int k, first = 1;
          if (me == 0 && round % 3 == 0) { /* a stall before it starts */
            volatile double spin = 0;
            for (k = 0; k < 20000; ++k) spin = spin + k;
            (void)spin;
          }
          for (k = px_steal_next(&w, me); k >= 0; k = px_steal_next(&w, me)) {
            /* a thread's first task, when it is of its own chunk, is the
             * chunk's first (thieves take the backs; a late thread may
             * find its chunk eaten, and then steals) */
            if (first && me < cut && k >= b[me] && k < b[me + 1])
              own_first = own_first && k == b[me];
            first = 0;
#pragma omp atomic
            ++runs[k];
          }
        }
        for (int i = 0; i < N; ++i) bad += runs[i] != 1;
      }
      PX_CHECK_MSG(bad == 0, "cut %d, team %d: %d tasks not run exactly once", cut, team, bad);
      PX_CHECK_MSG(own_first, "cut %d, team %d: a thread did not start on its own chunk", cut,
                   team);
    }
}

int main(void) {
  test_cut();
  test_order_one_thread();
  test_exactly_once();
  return px_test_report("test_core_steal");
}
