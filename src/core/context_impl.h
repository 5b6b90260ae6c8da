/* Private layout of struct px_context (never installed). */
#ifndef PX_CONTEXT_IMPL_H
#define PX_CONTEXT_IMPL_H

#include <stddef.h>
#include <threads.h>

#include "partix/context.h"

#define PX_CONTEXT_MESSAGE_MAX 4096

/* Accounting of one allocation label. */
struct px_mem_label {
  char *name;     /* owned */
  size_t current; /* bytes */
  size_t peak;    /* bytes */
};

struct px_context {
  enum px_status status;
  char message[PX_CONTEXT_MESSAGE_MAX];
  px_log_fn log_fn; /* NULL = default stderr logger */
  void *log_user;   /* borrowed */
  enum px_log_level log_level;
  const volatile sig_atomic_t *interrupt; /* borrowed, may be NULL */

  mtx_t mem_lock;
  struct px_mem_label *labels; /* owned (plain malloc: not itself accounted) */
  size_t nlabels, labels_cap;
  size_t mem_current, mem_peak;
  size_t mem_limit; /* bytes a run may plan to use, 0 = the machine's memory */
  struct px_comm *comm; /* borrowed; NULL: a single rank (core/comm.h) */
};

#endif
