/* The ranks of a run (comm.h): MPI where the build has it and the CLI made a
 * world communicator, a single rank otherwise. Large messages go in chunks
 * of PX_COMM_CHUNK bytes, so a count never overflows MPI's int. */
#include "core/comm.h"

#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/context_impl.h"
#include "partix/memory.h"
#include "partix/timer.h"

#ifdef PX_HAVE_MPI
#include <mpi.h>
#endif

#define PX_COMM_CHUNK ((size_t)1 << 30)

struct px_comm {
  struct px_context *ctx; /* borrowed: messages */
  int rank, size;
  int local_rank, local_size; /* among the ranks on this rank's node */
  double seconds;             /* spent inside px_comm calls */
  double ops, bytes;          /* sent (px_comm_traffic) */
#ifdef PX_HAVE_MPI
  MPI_Comm mpi;
  MPI_Comm fail; /* a duplicate of mpi for px_comm_settle (MPI_COMM_NULL: none) */
  MPI_Request req[PX_COMM_BATCH_MAX];
  int nreq;
#endif
  /* messages to oneself, copied at px_comm_wait */
  struct px_comm_msg self[PX_COMM_BATCH_MAX];
  size_t nself;
};

static struct px_comm px_comm_single = {.rank = 0, .size = 1, .local_rank = 0, .local_size = 1};

struct px_comm *px_context_comm(struct px_context *ctx) {
  return ctx && ctx->comm ? ctx->comm : &px_comm_single;
}

void px_context_set_comm(struct px_context *ctx, struct px_comm *comm) {
  if (ctx) ctx->comm = comm;
}

int px_comm_rank(const struct px_comm *comm) { return comm ? comm->rank : 0; }
int px_comm_local_rank(const struct px_comm *comm) { return comm ? comm->local_rank : 0; }
int px_comm_local_size(const struct px_comm *comm) { return comm ? comm->local_size : 1; }
int px_comm_size(const struct px_comm *comm) { return comm ? comm->size : 1; }
double px_comm_seconds(const struct px_comm *comm) { return comm ? comm->seconds : 0.0; }

void px_comm_traffic(const struct px_comm *comm, double *operations, double *bytes) {
  *operations = comm ? comm->ops : 0.0;
  *bytes = comm ? comm->bytes : 0.0;
}

/* Count one operation of `bytes` sent by this rank. */
static inline void px_comm_count(struct px_comm *comm, size_t bytes) {
  comm->ops += 1.0;
  comm->bytes += (double)bytes;
}

#ifdef PX_HAVE_MPI

static int px_comm_mpi(const struct px_comm *comm) { return comm->size > 1; }

static enum px_status px_comm_check(struct px_comm *comm, int err, const char *what) {
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  if (err == MPI_SUCCESS) return PX_STATUS_OK;
  if (MPI_Error_string(err, text, &len) != MPI_SUCCESS)
    snprintf(text, sizeof text, "error %d", err);
  return px_context_fail(comm->ctx, PX_STATUS_IO, "MPI %s on rank %d of %d: %s", what, comm->rank,
                         comm->size, text);
}

enum px_status px_comm_world(struct px_context *ctx, struct px_comm **out) {
  struct px_comm *c;
  int init = 0;
  *out = NULL;
  MPI_Initialized(&init);
  if (!init)
    return px_context_fail(ctx, PX_STATUS_INVALID, "px_comm_world: MPI is not initialized");
  c = calloc(1, sizeof *c);
  if (!c) return px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
  c->ctx = ctx;
  c->mpi = MPI_COMM_WORLD;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  MPI_Comm_rank(c->mpi, &c->rank);
  MPI_Comm_size(c->mpi, &c->size);
  {
    /* the ranks sharing this node's memory: a node-local index to share
       out the node's devices (backend.node_devices) */
    MPI_Comm node;
    c->local_rank = 0, c->local_size = 1;
    if (MPI_Comm_split_type(c->mpi, MPI_COMM_TYPE_SHARED, c->rank, MPI_INFO_NULL, &node) ==
        MPI_SUCCESS) {
      MPI_Comm_rank(node, &c->local_rank);
      MPI_Comm_size(node, &c->local_size);
      MPI_Comm_free(&node);
    }
  }
  if (MPI_Comm_dup(c->mpi, &c->fail) != MPI_SUCCESS) c->fail = MPI_COMM_NULL;
  *out = c;
  return PX_STATUS_OK;
}

int px_comm_settle(struct px_comm *comm, double wait_s) {
  MPI_Request req;
  int done = 0;
  double t0 = px_time_now();
  if (!px_comm_mpi(comm)) return 1;
  if (comm->fail == MPI_COMM_NULL || MPI_Ibarrier(comm->fail, &req) != MPI_SUCCESS) return 0;
  /* the ranks that failed together meet here at once; one stuck in a
     collective of the run never does (its own communicator is left alone) */
  while (MPI_Test(&req, &done, MPI_STATUS_IGNORE) == MPI_SUCCESS && !done &&
         px_time_now() - t0 < wait_s) {
    struct timespec ms = {0, 1000000L};
    nanosleep(&ms, NULL);
  }
  return done;
}

void px_comm_abort(struct px_comm *comm, int code) {
  (void)comm;
  MPI_Abort(MPI_COMM_WORLD, code);
}

#else

enum px_status px_comm_world(struct px_context *ctx, struct px_comm **out) {
  *out = NULL;
  return px_context_fail(ctx, PX_STATUS_UNSUPPORTED, "this build of partix has no MPI");
}

int px_comm_settle(struct px_comm *comm, double wait_s) {
  (void)comm, (void)wait_s;
  return 1;
}

void px_comm_abort(struct px_comm *comm, int code) {
  (void)comm;
  exit(code);
}

#endif

void px_comm_free(struct px_comm *comm) {
  if (!comm || comm == &px_comm_single) return;
#ifdef PX_HAVE_MPI
  if (comm->fail != MPI_COMM_NULL) MPI_Comm_free(&comm->fail);
#endif
  free(comm);
}

enum px_status px_comm_barrier(struct px_comm *comm) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) {
    double t0 = px_time_now();
    enum px_status s;
    px_comm_count(comm, 0);
    s = px_comm_check(comm, MPI_Barrier(comm->mpi), "barrier");
    comm->seconds += px_time_now() - t0;
    return s;
  }
#endif
  (void)comm;
  return PX_STATUS_OK;
}

#ifdef PX_HAVE_MPI
/* The MPI parts of the collectives, neither timed nor counted: the public
 * functions that call them time and count themselves once (a collective
 * built of others must not add its wait twice to px_comm_seconds). */
static enum px_status px_comm_bcast_mpi(struct px_comm *comm, void *buf, size_t bytes, int root) {
  size_t off;
  enum px_status s = PX_STATUS_OK;
  for (off = 0; off < bytes && s == PX_STATUS_OK; off += PX_COMM_CHUNK) {
    size_t n = bytes - off < PX_COMM_CHUNK ? bytes - off : PX_COMM_CHUNK;
    s = px_comm_check(comm, MPI_Bcast((char *)buf + off, (int)n, MPI_BYTE, root, comm->mpi),
                      "broadcast");
  }
  return s;
}

/* counts[r] = the `bytes` of rank r. */
static enum px_status px_comm_sizes_mpi(struct px_comm *comm, size_t bytes, size_t *counts) {
  unsigned long long mine = bytes, *all = malloc((size_t)comm->size * sizeof *all);
  enum px_status s;
  int r;
  if (!all) return px_context_fail(comm->ctx, PX_STATUS_NOMEM, "out of memory");
  s = px_comm_check(
      comm,
      MPI_Allgather(&mine, 1, MPI_UNSIGNED_LONG_LONG, all, 1, MPI_UNSIGNED_LONG_LONG, comm->mpi),
      "allgather");
  for (r = 0; r < comm->size && s == PX_STATUS_OK; ++r) counts[r] = (size_t)all[r];
  free(all);
  return s;
}

/* The ranks' sizes into counts, or into *own (allocated, the caller frees
 * it) when counts is NULL; *c points to whichever holds them. */
static enum px_status px_comm_sizes(struct px_comm *comm, size_t bytes, size_t *counts, size_t **c,
                                    size_t **own) {
  *own = counts ? NULL : malloc((size_t)comm->size * sizeof **own);
  *c = counts ? counts : *own;
  if (!*c) return px_context_fail(comm->ctx, PX_STATUS_NOMEM, "out of memory");
  return px_comm_sizes_mpi(comm, bytes, *c);
}
#endif

enum px_status px_comm_bcast(struct px_comm *comm, void *buf, size_t bytes, int root) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) {
    double t0 = px_time_now();
    enum px_status s;
    px_comm_count(comm, comm->rank == root ? bytes : 0);
    s = px_comm_bcast_mpi(comm, buf, bytes, root);
    comm->seconds += px_time_now() - t0;
    return s;
  }
#endif
  (void)comm, (void)buf, (void)bytes, (void)root;
  return PX_STATUS_OK;
}

enum px_status px_comm_allgather_size(struct px_comm *comm, size_t bytes, size_t *counts) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) {
    double t0 = px_time_now();
    enum px_status s = px_comm_sizes_mpi(comm, bytes, counts);
    comm->seconds += px_time_now() - t0;
    return s;
  }
#endif
  (void)comm;
  counts[0] = bytes;
  return PX_STATUS_OK;
}

#ifdef PX_HAVE_MPI
/* Gather to root by point-to-point messages in chunks (any size). */
static enum px_status px_comm_gather_p2p(struct px_comm *comm, const void *send, size_t bytes,
                                         void *recv, const size_t *counts, int root) {
  enum px_status s = PX_STATUS_OK;
  size_t off;
  if (comm->rank != root) {
    for (off = 0; off < bytes && s == PX_STATUS_OK; off += PX_COMM_CHUNK) {
      size_t n = bytes - off < PX_COMM_CHUNK ? bytes - off : PX_COMM_CHUNK;
      s = px_comm_check(comm,
                        MPI_Send((const char *)send + off, (int)n, MPI_BYTE, root, 7001, comm->mpi),
                        "send");
    }
    return s;
  } else {
    char *at = recv;
    int r;
    for (r = 0; r < comm->size && s == PX_STATUS_OK; ++r) {
      if (r == root) {
        if (bytes) memcpy(at, send, bytes);
      } else {
        for (off = 0; off < counts[r] && s == PX_STATUS_OK; off += PX_COMM_CHUNK) {
          size_t n = counts[r] - off < PX_COMM_CHUNK ? counts[r] - off : PX_COMM_CHUNK;
          s = px_comm_check(
              comm, MPI_Recv(at + off, (int)n, MPI_BYTE, r, 7001, comm->mpi, MPI_STATUS_IGNORE),
              "receive");
        }
      }
      at += counts[r];
    }
    return s;
  }
}
#endif

enum px_status px_comm_gatherv(struct px_comm *comm, const void *send, size_t bytes, void *recv,
                               size_t *counts, int root) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) {
    double t0 = px_time_now();
    size_t *c, *own;
    enum px_status s = px_comm_sizes(comm, bytes, counts, &c, &own);
    px_comm_count(comm, comm->rank == root ? 0 : bytes);
    if (s == PX_STATUS_OK) s = px_comm_gather_p2p(comm, send, bytes, recv, c, root);
    free(own);
    comm->seconds += px_time_now() - t0;
    return s;
  }
#endif
  (void)comm, (void)root;
  if (counts) counts[0] = bytes;
  if (bytes && recv != send) memmove(recv, send, bytes);
  return PX_STATUS_OK;
}

#ifdef PX_HAVE_MPI
/* Allgatherv of contributions whose sizes c[r] every rank knows. */
static enum px_status px_comm_allgatherv_c(struct px_comm *comm, const void *send, size_t bytes,
                                           void *recv, const size_t *c) {
  size_t total = 0;
  int r;
  enum px_status s = PX_STATUS_OK;
  px_comm_count(comm, bytes);
  for (r = 0; r < comm->size; ++r) total += c[r];
  if (total <= (size_t)INT_MAX) {
    int *cnt = malloc(2 * (size_t)comm->size * sizeof *cnt), *dis = cnt + comm->size;
    size_t at = 0;
    if (!cnt) return px_context_fail(comm->ctx, PX_STATUS_NOMEM, "out of memory");
    for (r = 0; r < comm->size; ++r) {
      cnt[r] = (int)c[r];
      dis[r] = (int)at;
      at += c[r];
    }
    s = px_comm_check(
        comm, MPI_Allgatherv(send, (int)bytes, MPI_BYTE, recv, cnt, dis, MPI_BYTE, comm->mpi),
        "allgatherv");
    free(cnt);
  } else {
    /* over 2 GiB in all: through rank 0 in chunks */
    s = px_comm_gather_p2p(comm, send, bytes, recv, c, 0);
    if (s == PX_STATUS_OK) s = px_comm_bcast_mpi(comm, recv, total, 0);
  }
  return s;
}
#endif

enum px_status px_comm_allgatherv(struct px_comm *comm, const void *send, size_t bytes, void *recv,
                                  size_t *counts) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) {
    double t0 = px_time_now();
    size_t *c, *own;
    enum px_status s = px_comm_sizes(comm, bytes, counts, &c, &own);
    if (s == PX_STATUS_OK) s = px_comm_allgatherv_c(comm, send, bytes, recv, c);
    free(own);
    comm->seconds += px_time_now() - t0;
    return s;
  }
#endif
  (void)comm;
  if (counts) counts[0] = bytes;
  if (bytes && recv != send) memmove(recv, send, bytes);
  return PX_STATUS_OK;
}

enum px_status px_comm_allgatherv_known(struct px_comm *comm, const void *send, void *recv,
                                        const size_t *counts) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) {
    double t0 = px_time_now();
    const enum px_status s = px_comm_allgatherv_c(comm, send, counts[comm->rank], recv, counts);
    comm->seconds += px_time_now() - t0;
    return s;
  }
#endif
  (void)comm;
  if (counts[0] && recv != send) memmove(recv, send, counts[0]);
  return PX_STATUS_OK;
}

#ifdef PX_HAVE_MPI
/* n values of `size` bytes and MPI type `type`, in place. */
static enum px_status px_comm_allreduce_mpi(struct px_comm *comm, void *v, size_t n, size_t size,
                                            MPI_Datatype type, enum px_comm_op op) {
  double t0 = px_time_now();
  MPI_Op o = op == PX_COMM_SUM ? MPI_SUM : op == PX_COMM_MIN ? MPI_MIN : MPI_MAX;
  enum px_status s;
  if (n > (size_t)INT_MAX)
    return px_context_fail(comm->ctx, PX_STATUS_INVALID, "allreduce of %zu values", n);
  px_comm_count(comm, n * size);
  s = px_comm_check(comm, MPI_Allreduce(MPI_IN_PLACE, v, (int)n, type, o, comm->mpi), "allreduce");
  comm->seconds += px_time_now() - t0;
  return s;
}
#endif

enum px_status px_comm_allreduce_double(struct px_comm *comm, double *v, size_t n,
                                        enum px_comm_op op) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) return px_comm_allreduce_mpi(comm, v, n, sizeof *v, MPI_DOUBLE, op);
#endif
  (void)comm, (void)v, (void)n, (void)op;
  return PX_STATUS_OK;
}

enum px_status px_comm_allreduce_long(struct px_comm *comm, long *v, size_t n, enum px_comm_op op) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) return px_comm_allreduce_mpi(comm, v, n, sizeof *v, MPI_LONG, op);
#endif
  (void)comm, (void)v, (void)n, (void)op;
  return PX_STATUS_OK;
}

enum px_status px_comm_start(struct px_comm *comm, const struct px_comm_msg *msg, size_t n) {
  size_t i;
  double t0 = px_time_now();
  if (n > PX_COMM_BATCH_MAX)
    return px_context_fail(comm->ctx, PX_STATUS_INVALID,
                           "px_comm_start: %zu messages (at most %d in one batch)", n,
                           PX_COMM_BATCH_MAX);
  comm->nself = 0;
#ifdef PX_HAVE_MPI
  comm->nreq = 0;
#endif
  for (i = 0; i < n; ++i) {
    const struct px_comm_msg *m = &msg[i];
    if (m->peer < 0 || m->peer >= comm->size || m->tag < 0 || m->bytes > (size_t)INT_MAX)
      return px_context_fail(comm->ctx, PX_STATUS_INVALID,
                             "px_comm_start: message %zu to rank %d (of %d), tag %d, %zu bytes", i,
                             m->peer, comm->size, m->tag, m->bytes);
    if (m->peer == comm->rank) {
      comm->self[comm->nself++] = *m;
      continue;
    }
#ifdef PX_HAVE_MPI
    {
      int err;
      if (!m->recv) px_comm_count(comm, m->bytes);
      err = m->recv ? MPI_Irecv(m->buf, (int)m->bytes, MPI_BYTE, m->peer, m->tag, comm->mpi,
                                &comm->req[comm->nreq])
                    : MPI_Isend(m->buf, (int)m->bytes, MPI_BYTE, m->peer, m->tag, comm->mpi,
                                &comm->req[comm->nreq]);
      PX_TRY(px_comm_check(comm, err, m->recv ? "receive" : "send"));
      comm->nreq++;
    }
#endif
  }
  comm->seconds += px_time_now() - t0;
  return PX_STATUS_OK;
}

enum px_status px_comm_wait(struct px_comm *comm) {
  size_t i, j;
  double t0 = px_time_now();
  enum px_status s = PX_STATUS_OK;
#ifdef PX_HAVE_MPI
  if (comm->nreq) {
    MPI_Status st[PX_COMM_BATCH_MAX];
    s = px_comm_check(comm, MPI_Waitall(comm->nreq, comm->req, st), "wait");
    comm->nreq = 0;
  }
#endif
  /* each send to oneself goes to the receive of the same tag */
  for (i = 0; i < comm->nself && s == PX_STATUS_OK; ++i) {
    const struct px_comm_msg *snd = &comm->self[i];
    if (snd->recv) continue;
    for (j = 0; j < comm->nself; ++j) {
      const struct px_comm_msg *rcv = &comm->self[j];
      if (rcv->recv && rcv->tag == snd->tag) {
        if (rcv->bytes != snd->bytes)
          s = px_context_fail(comm->ctx, PX_STATUS_IO,
                              "px_comm_wait: %zu bytes sent to self with tag %d, %zu expected",
                              snd->bytes, snd->tag, rcv->bytes);
        else if (snd->bytes)
          memmove(rcv->buf, snd->buf, snd->bytes);
        break;
      }
    }
  }
  comm->nself = 0;
  comm->seconds += px_time_now() - t0;
  return s;
}

enum px_status px_comm_exchange(struct px_comm *comm, const struct px_comm_msg *msg, size_t n) {
  PX_TRY(px_comm_start(comm, msg, n));
  return px_comm_wait(comm);
}

enum px_status px_comm_agree(struct px_comm *comm, struct px_context *ctx, enum px_status status,
                             int *interrupted) {
#ifdef PX_HAVE_MPI
  if (px_comm_mpi(comm)) {
    /* the lowest failing rank (size if none) and whether any was interrupted */
    long v[2];
    int who;
    struct {
      int status;
      char message[PX_CONTEXT_MESSAGE_MAX];
    } m;
    v[0] = status != PX_STATUS_OK ? comm->rank : comm->size;
    v[1] = -(long)(interrupted && *interrupted);
    PX_TRY(px_comm_allreduce_long(comm, v, 2, PX_COMM_MIN));
    who = (int)v[0];
    if (interrupted) *interrupted = v[1] != 0;
    if (who == comm->size) return PX_STATUS_OK;
    memset(&m, 0, sizeof m);
    if (comm->rank == who) {
      m.status = (int)status;
      snprintf(m.message, sizeof m.message, "%s", px_context_message(ctx));
    }
    PX_TRY(px_comm_bcast(comm, &m, sizeof m, who));
    /* a failure on rank 0 reads as on one rank; another rank says which */
    if (who == 0)
      px_context_fail(ctx, (enum px_status)m.status, "%s",
                      m.message[0] ? m.message : px_status_message((enum px_status)m.status));
    else
      px_context_fail(ctx, (enum px_status)m.status, "rank %d: %s", who,
                      m.message[0] ? m.message : px_status_message((enum px_status)m.status));
    return (enum px_status)m.status;
  }
#endif
  (void)comm, (void)ctx, (void)interrupted;
  return status;
}
