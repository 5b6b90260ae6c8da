/* The ranks of one run (internal): a thin layer over MPI that every solver's
 * decomposition uses, so no solver file includes <mpi.h> or #ifdefs MPI.
 *
 * A context has a communicator: the one the CLI set with px_context_set_comm
 * when `mpirun -np K partix run` started it, else a single rank (rank 0 of 1),
 * on which every call below is a copy or nothing. A build without MPI has
 * only the single rank.
 *
 * All functions are collective over the communicator's ranks unless said
 * otherwise: every rank calls them in the same order. Sizes are in bytes.
 * They return PX_STATUS_OK, or PX_STATUS_IO with the context's message set
 * (an MPI error); PX_STATUS_INVALID for a misuse (a negative rank, more than
 * PX_COMM_BATCH_MAX messages).
 *
 * Reproducibility: px_comm_allreduce_* with PX_COMM_SUM adds the ranks' values
 * in an order MPI chooses, so a sum can differ in its last bits between rank
 * counts. A solver that must give the 1-rank answer to the bit sums fixed
 * blocks instead (px_comm_allgatherv of per-block partials, added in block
 * order on every rank). MIN and MAX are exact. */
#ifndef PX_CORE_COMM_H
#define PX_CORE_COMM_H

#include <stddef.h>
#include <stdint.h>

#include "partix/context.h"
#include "partix/status.h"

struct px_comm;

/* The context's communicator (never NULL: a single rank by default). Not
 * collective. */
struct px_comm *px_context_comm(struct px_context *ctx);
/* Make comm (borrowed: it outlives ctx) the context's communicator; NULL
 * restores the single rank. Not collective. */
void px_context_set_comm(struct px_context *ctx, struct px_comm *comm);

/* MPI_COMM_WORLD of a process that called MPI_Init (the CLI), on ctx (for
 * messages). PX_STATUS_UNSUPPORTED in a build without MPI. */
enum px_status px_comm_world(struct px_context *ctx, struct px_comm **out);
void px_comm_free(struct px_comm *comm);

/* Called by every rank whose run failed, before MPI_Finalize: 1 when every
 * rank came within wait_s seconds (they failed together, as after a
 * px_comm_agree that returned the failure: finalize as usual), or a single
 * rank; 0 when some rank did not come: it waits in a collective of the run
 * that this rank will never join (a failure inside a solver's create on one
 * rank pairs the ranks' later collectives wrongly), and MPI_Finalize would
 * hang the job: px_comm_abort. Uses its own duplicate of the communicator,
 * so it never matches a collective of the run. */
int px_comm_settle(struct px_comm *comm, double wait_s);
/* End every rank of the job (MPI_Abort) with exit code `code`; exit(code)
 * without MPI. Does not return. */
void px_comm_abort(struct px_comm *comm, int code);

/* Not collective. */
int px_comm_rank(const struct px_comm *comm);
int px_comm_size(const struct px_comm *comm);
/* This rank's index among the ranks on its node (sharing its memory, as
 * MPI_COMM_TYPE_SHARED groups them), and their number: 0 and 1 for a
 * single rank. */
int px_comm_local_rank(const struct px_comm *comm);
int px_comm_local_size(const struct px_comm *comm);
/* MPI_Wtime-like wall clock [s] and the seconds this rank has spent inside
 * px_comm calls since the comm was made (communication time per step). */
double px_comm_seconds(const struct px_comm *comm);
/* What this rank has sent since the comm was made: operations (a
 * point-to-point message or this rank's part in a collective) and bytes
 * (its messages, and its contribution to each collective: for a model of
 * the traffic per step, docs/running.md). Not collective. */
void px_comm_traffic(const struct px_comm *comm, double *operations, double *bytes);

enum px_status px_comm_barrier(struct px_comm *comm);
/* bytes of buf from root to every rank. */
enum px_status px_comm_bcast(struct px_comm *comm, void *buf, size_t bytes, int root);

/* Every rank contributes `bytes` (which may differ between ranks, 0 allowed);
 * recv (on every rank for allgatherv, on root only for gatherv; may be NULL
 * elsewhere) receives the contributions in rank order, back to back.
 * counts: NULL, or room for size entries receiving each rank's bytes.
 * recv must hold the sum of all ranks' bytes: ask with px_comm_allgather_size
 * first when it is not known. */
enum px_status px_comm_allgatherv(struct px_comm *comm, const void *send, size_t bytes, void *recv,
                                  size_t *counts);
enum px_status px_comm_gatherv(struct px_comm *comm, const void *send, size_t bytes, void *recv,
                               size_t *counts, int root);
/* px_comm_allgatherv when every rank knows every rank's bytes (counts[r],
 * the same array on every rank; this rank sends counts[rank] bytes): no
 * exchange of the sizes first (one collective instead of two). */
enum px_status px_comm_allgatherv_known(struct px_comm *comm, const void *send, void *recv,
                                        const size_t *counts);
/* counts[r] = the `bytes` of rank r, on every rank (counts: size entries). */
enum px_status px_comm_allgather_size(struct px_comm *comm, size_t bytes, size_t *counts);

enum px_comm_op { PX_COMM_SUM, PX_COMM_MIN, PX_COMM_MAX };
/* In place, n values, the same result on every rank. */
enum px_status px_comm_allreduce_double(struct px_comm *comm, double *v, size_t n,
                                        enum px_comm_op op);
enum px_status px_comm_allreduce_long(struct px_comm *comm, long *v, size_t n, enum px_comm_op op);

/* Point-to-point messages of a halo or ghost exchange, posted together
 * without blocking: px_comm_start posts n sends and receives (each to or
 * from `peer`, matched by `tag` >= 0 between a pair of ranks); the buffers
 * must not be touched until px_comm_wait returns. One batch at a time per
 * communicator; at most PX_COMM_BATCH_MAX messages. Collective only among the
 * ranks that exchange (not all). A message to oneself is copied. */
#define PX_COMM_BATCH_MAX 64
struct px_comm_msg {
  void *buf;    /* data to send, or room to receive */
  size_t bytes; /* exact size (a receive of another size is PX_STATUS_IO) */
  int peer;     /* the other rank */
  int tag;      /* >= 0 */
  int recv;     /* 1: receive into buf, 0: send buf */
};
enum px_status px_comm_start(struct px_comm *comm, const struct px_comm_msg *msg, size_t n);
enum px_status px_comm_wait(struct px_comm *comm);
/* px_comm_start then px_comm_wait. */
enum px_status px_comm_exchange(struct px_comm *comm, const struct px_comm_msg *msg, size_t n);

/* Agree on how a stretch of work ended: every rank passes its status (ctx's
 * message set when not OK); every rank returns the status of the
 * lowest-numbered failing rank with its message copied into its own context
 * ("rank R: message" when R > 0), else OK. interrupted (may be NULL): in,
 * this rank's interrupt flag; out, 1 if any rank's was set. */
enum px_status px_comm_agree(struct px_comm *comm, struct px_context *ctx, enum px_status status,
                             int *interrupted);

#endif
