/* partix check | run | resume */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"
#include "core/comm.h"

#ifdef PX_HAVE_MPI
#include <mpi.h>
#endif

static volatile sig_atomic_t px_cli_interrupt = 0;

static volatile sig_atomic_t px_cli_first_signal_s = 0; /* CLOCK_MONOTONIC [s] */

static void px_cli_on_signal(int sig) {
  struct timespec now;
  (void)sig;
  clock_gettime(CLOCK_MONOTONIC, &now); /* async-signal-safe */
  if (px_cli_interrupt) {
    /* A second Ctrl-C while the checkpoint is written kills the process.
       One that follows the first within a second or two is the same request
       delivered twice (`timeout -s INT` signals the process and its group,
       a key held down), not a second request: it is ignored. */
    static const char msg[] =
        "\npartix: interrupted again: stopping at once, without a checkpoint (the run "
        "folder keeps the last one written)\n";
    if ((long)now.tv_sec - (long)px_cli_first_signal_s < 2) return;
    if (write(2, msg, sizeof msg - 1) < 0) { /* nothing to do: stopping anyway */
    }
    signal(SIGINT, SIG_DFL);
    raise(SIGINT);
    return;
  }
  px_cli_first_signal_s = (sig_atomic_t)now.tv_sec;
  px_cli_interrupt = 1;
}

/* Options shared by run/check/resume; they become --set overrides. */
struct px_cli_run_args {
  const char *file;       /* case or checkpoint */
  const char **overrides; /* owned array of borrowed/owned strings */
  char **owned;           /* strings we built (freed at the end) */
  size_t n, nowned;
  long more;    /* resume --more N: N steps after the checkpoint (0: none) */
  int sections; /* verify --sections: list every section with a hash */
};

/* Push "key=value"; literal: the value is text as given
 * (px_cli_override_text). */
static int px_cli_push(struct px_cli_run_args *a, const char *key, const char *value, int literal) {
  char *s;
  if (literal) {
    s = px_cli_override_text(key, value);
  } else {
    const size_t len = strlen(key) + strlen(value) + 2;
    s = malloc(len);
    if (s) snprintf(s, len, "%s=%s", key, value);
  }
  if (!s) return -1;
  a->owned[a->nowned++] = s;
  a->overrides[a->n++] = s;
  return 0;
}

static void px_cli_run_args_free(struct px_cli_run_args *a) {
  size_t i;
  for (i = 0; i < a->nowned; ++i) free(a->owned[i]);
  free(a->owned);
  free(a->overrides);
}

static const struct {
  const char *option;
  const char *key;
  int literal; /* the value is a name, taken as given (px_cli_push) */
} px_cli_shortcuts[] = {
    {"--backend", "backend.type", 0},
    {"--device", "backend.device", 0},
    {"--threads", "backend.threads", 0},
    {"--precision", "backend.precision", 0},
    {"--workgroup", "backend.workgroup", 0},
    {"--out", "output.dir", 1},
    {"--steps", "time.steps", 0},
    {"--dt", "time.dt", 0},
};

/* Returns 0 on success, an exit code otherwise. */
static int px_cli_parse_run(struct px_cli *cli, struct px_cli_run_args *a, int *progress) {
  int i;
  size_t k, cap = (size_t)cli->argc + 2;
  memset(a, 0, sizeof *a);
  a->overrides = calloc(cap, sizeof *a->overrides);
  a->owned = calloc(cap, sizeof *a->owned);
  if (!a->overrides || !a->owned) return PX_CLI_EXIT_FAILURE;
  for (i = 0; i < cli->argc; ++i) {
    const char *arg = cli->argv[i];
    int matched = 0;
    if (strcmp(arg, "--set") == 0 || strcmp(arg, "-s") == 0) {
      if (i + 1 >= cli->argc) {
        fprintf(stderr, "partix %s: --set needs key.path=value\n", cli->command);
        return PX_CLI_EXIT_USAGE;
      }
      a->overrides[a->n++] = cli->argv[++i];
      continue;
    }
    if (strncmp(arg, "--set=", 6) == 0) {
      a->overrides[a->n++] = arg + 6;
      continue;
    }
    if (strcmp(arg, "--no-progress") == 0) {
      *progress = 0;
      continue;
    }
    /* the global options are accepted after the command too */
    if (strcmp(arg, "-q") == 0 || strcmp(arg, "--quiet") == 0) {
      cli->log_level = PX_LOG_LEVEL_WARN;
      continue;
    }
    if (strcmp(arg, "-v") == 0 || strcmp(arg, "--verbose") == 0) {
      if (cli->log_level < PX_LOG_LEVEL_TRACE) cli->log_level++;
      continue;
    }
    if (strcmp(arg, "--more") == 0 || strncmp(arg, "--more=", 7) == 0) {
      const char *value = arg[6] == '=' ? arg + 7 : NULL;
      char *end = NULL;
      if (strcmp(cli->command, "resume") != 0) {
        fprintf(stderr, "partix %s: --more is an option of `partix resume`\n", cli->command);
        return PX_CLI_EXIT_USAGE;
      }
      if (!value) {
        if (i + 1 >= cli->argc) {
          fprintf(stderr, "partix %s: --more needs a number of steps\n", cli->command);
          return PX_CLI_EXIT_USAGE;
        }
        value = cli->argv[++i];
      }
      a->more = strtol(value, &end, 10);
      if (!end || end == value || *end != '\0' || a->more < 1 || a->more > 1000000000000L) {
        fprintf(stderr, "partix %s: --more %s: give a number of steps >= 1\n", cli->command, value);
        return PX_CLI_EXIT_USAGE;
      }
      continue;
    }
    if (strcmp(arg, "--sections") == 0) {
      if (strcmp(cli->command, "verify") != 0) {
        fprintf(stderr, "partix %s: --sections is an option of `partix verify`\n", cli->command);
        return PX_CLI_EXIT_USAGE;
      }
      a->sections = 1;
      continue;
    }
    for (k = 0; k < sizeof px_cli_shortcuts / sizeof px_cli_shortcuts[0]; ++k) {
      size_t len = strlen(px_cli_shortcuts[k].option);
      if (strncmp(arg, px_cli_shortcuts[k].option, len) == 0 &&
          (arg[len] == '\0' || arg[len] == '=')) {
        const char *value = arg[len] == '=' ? arg + len + 1 : NULL;
        if (!value) {
          if (i + 1 >= cli->argc) {
            fprintf(stderr, "partix %s: %s needs a value\n", cli->command, arg);
            return PX_CLI_EXIT_USAGE;
          }
          value = cli->argv[++i];
        }
        if (px_cli_push(a, px_cli_shortcuts[k].key, value, px_cli_shortcuts[k].literal) != 0)
          return PX_CLI_EXIT_FAILURE;
        matched = 1;
        break;
      }
    }
    if (matched) continue;
    if (arg[0] == '-' && arg[1] != '\0') {
      fprintf(stderr, "partix %s: unknown option '%s' (see partix %s --help)\n", cli->command, arg,
              cli->command);
      return PX_CLI_EXIT_USAGE;
    }
    if (a->file) {
      fprintf(stderr, "partix %s: more than one file given ('%s' and '%s')\n", cli->command,
              a->file, arg);
      return PX_CLI_EXIT_USAGE;
    }
    a->file = arg;
  }
  if (a->more) {
    for (k = 0; k < a->n; ++k)
      if (strncmp(a->overrides[k], "time.steps=", 11) == 0 ||
          strncmp(a->overrides[k], "time.end=", 9) == 0) {
        fprintf(stderr, "partix %s: --more and %s both set the end of the run: give one\n",
                cli->command, a->overrides[k]);
        return PX_CLI_EXIT_USAGE;
      }
  }
  if (!a->file) {
    fprintf(stderr, "partix %s: no %s given (see partix %s --help)\n", cli->command,
            strcmp(cli->command, "resume") == 0   ? "checkpoint"
            : strcmp(cli->command, "render") == 0 ? "run folder or checkpoint"
            : strcmp(cli->command, "verify") == 0 ? "checkpoint"
                                                  : "case file",
            cli->command);
    return PX_CLI_EXIT_USAGE;
  }
  return 0;
}

static void px_cli_run_help(const char *command) {
  if (strcmp(command, "verify") == 0)
    printf(
        "usage: partix verify CHECKPOINT|RUN_DIR [--sections]\n\n"
        "Checks a checkpoint without running or writing anything: its structure and\n"
        "CRCs, the case it stores (against its header's hash), and every section the\n"
        "solver loads (sizes, indices and values in range). Exit 0 when it can be\n"
        "resumed, 2 with the reason otherwise.\n\n"
        "  --sections   then list every section: name, type, count and a 64-bit hash\n"
        "               of its contents (FNV-1a), to compare the states of two runs\n");
  else if (strcmp(command, "check") == 0)
    printf(
        "usage: partix check CASE.yaml [--set key.path=value]...\n\n"
        "Validates a case file and builds its problem (geometry, parameters) without\n"
        "running or writing anything. Errors read file:line:col: key.path: message.\n");
  else if (strcmp(command, "render") == 0)
    printf(
        "usage: partix render RUN_DIR|CHECKPOINT [--set key.path=value]...\n\n"
        "Draws the pictures of a run's last checkpointed state and its end-of-run plots\n"
        "again (e.g. with other picture settings given by --set), without running.\n");
  else if (strcmp(command, "resume") == 0)
    printf(
        "usage: partix resume CHECKPOINT [options]\n\n"
        "Continues a run from its checkpoint (RUN_DIR/checkpoint.pxc), appending to its\n"
        "outputs: the run folder ends as an uninterrupted run's would. On the cpu backend\n"
        "with the same thread count the continuation is bit-identical. Options as for\n"
        "`partix run`, and\n"
        "  --more N                 run N steps past the checkpoint\n"
        "--steps N (or --set time.end=T) moves the end; it must lie after the checkpoint.\n"
        "Only how far the run goes (time.*), its outputs (output.*), where it runs\n"
        "(backend.* except precision) and picture settings may change on resume; other\n"
        "keys define the stored state and are refused by name.\n");
  else
    printf(
        "usage: partix run CASE.yaml [options]\n\n"
        "Runs a simulation. Ctrl-C writes a checkpoint and stops cleanly.\n");
  if (strcmp(command, "check") != 0 && strcmp(command, "render") != 0 &&
      strcmp(command, "verify") != 0)
    printf(
        "\noptions (shortcuts for --set):\n"
        "  --backend cpu|opencl     backend.type\n"
        "  --device N               backend.device (OpenCL device, see `partix info`)\n"
        "  --threads N              backend.threads (0 = all cores)\n"
        "  --precision P            backend.precision: single | double | mixed\n"
        "  --workgroup N            backend.workgroup (0 = automatic)\n"
        "  --out DIR                output.dir\n"
        "  --steps N                time.steps\n"
        "  --dt DT                  time.dt\n"
        "  --set key.path=value     override any key of the case (repeatable)\n"
        "  --no-progress            no progress line\n"
        "  -q, --quiet / -v         only errors and warnings / more detail\n");
}

/* verify --sections: each section of the (verified) checkpoint with a hash
 * of its contents, one line each: NAME TYPE COUNT FNV1A64. */
static enum px_status px_cli_list_sections(struct px_context *ctx, const char *path) {
  struct px_checkpoint *ck = NULL;
  unsigned char *buf = NULL;
  size_t cap = 0, i, n;
  enum px_status s = px_checkpoint_open(ctx, path, &ck);
  n = s == PX_STATUS_OK ? px_checkpoint_section_count(ck) : 0;
  for (i = 0; i < n && s == PX_STATUS_OK; ++i) {
    const char *name = NULL;
    enum px_dtype type;
    uint64_t count = 0, h = 14695981039346656037ull, b;
    size_t bytes;
    s = px_checkpoint_section(ck, i, &name, &type, &count);
    if (s != PX_STATUS_OK) break;
    bytes = (size_t)count * px_dtype_size(type);
    if (bytes > cap) {
      unsigned char *g = realloc(buf, bytes);
      if (!g) {
        s = px_context_fail(ctx, PX_STATUS_NOMEM, "out of memory");
        break;
      }
      buf = g;
      cap = bytes;
    }
    s = px_checkpoint_read(ck, name, type, count, buf);
    for (b = 0; s == PX_STATUS_OK && b < bytes; ++b) h = (h ^ buf[b]) * 1099511628211ull;
    if (s == PX_STATUS_OK)
      printf("%s %s %llu %016llx\n", name, px_dtype_name(type), (unsigned long long)count,
             (unsigned long long)h);
  }
  free(buf);
  px_checkpoint_close(ck);
  return s;
}

/* Under mpirun -np K (K > 1), `run` and `resume` run one case over the K
 * ranks: MPI started, the world communicator set on ctx. Rank 0 alone
 * prints (the ranks agree on every failure, so its message is the run's).
 * 0, or an exit code. */
static int px_cli_ranks_begin(struct px_context *ctx, struct px_comm **comm, int *progress) {
#ifdef PX_HAVE_MPI
  int provided = 0;
  if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    fprintf(stderr, "partix: MPI could not start (MPI_Init_thread failed)\n");
    return PX_CLI_EXIT_FAILURE;
  }
  if (px_comm_world(ctx, comm) != PX_STATUS_OK) {
    fprintf(stderr, "partix: %s\n", px_context_message(ctx));
    MPI_Finalize();
    return PX_CLI_EXIT_FAILURE;
  }
  px_context_set_comm(ctx, *comm);
  if (px_comm_rank(*comm) != 0) {
    px_context_set_log_level(ctx, PX_LOG_LEVEL_ERROR);
    *progress = 0;
  }
  return 0;
#else
  (void)ctx, (void)comm, (void)progress;
  fprintf(stderr,
          "partix: started as one of %ld MPI ranks, but this build has no MPI "
          "(configure with -DPX_WITH_MPI=ON); run it without mpirun; nothing was written.\n",
          px_cli_launch_ranks());
  return PX_CLI_EXIT_USAGE;
#endif
}

/* How long ranks that failed wait for each other before they take it that
 * some rank is stuck elsewhere [s]: ranks failing together (a case error
 * every rank finds) meet within milliseconds, but oversubscribed ranks may
 * be descheduled for a while. */
#define PX_CLI_SETTLE_S 10.0

static void px_cli_ranks_end(struct px_comm *comm) {
#ifdef PX_HAVE_MPI
  if (comm) {
    px_comm_free(comm);
    MPI_Finalize();
  }
#else
  (void)comm;
#endif
}

static int px_cli_run_common(struct px_cli *cli) {
  struct px_cli_run_args a;
  struct px_context *ctx = NULL;
  struct px_case *c = NULL;
  struct px_sim *sim = NULL;
  struct px_comm *comm = NULL;
  int progress = 1, code, setup;
  char path[4096];
  enum px_status s;
  int check = strcmp(cli->command, "check") == 0;
  int render = strcmp(cli->command, "render") == 0;
  int verify = strcmp(cli->command, "verify") == 0;
  int resume = render || verify || strcmp(cli->command, "resume") == 0;

  if (px_cli_wants_help(cli)) {
    px_cli_run_help(cli->command);
    return PX_CLI_EXIT_OK;
  }
  code = px_cli_parse_run(cli, &a, &progress);
  if (code != 0) {
    px_cli_run_args_free(&a);
    return code;
  }
  if (cli->log_level < PX_LOG_LEVEL_INFO) progress = 0; /* -q: no progress line either */
  ctx = px_cli_context(cli);
  if (!ctx) {
    px_cli_run_args_free(&a);
    return PX_CLI_EXIT_FAILURE;
  }
  if (!check && !render && !verify && px_cli_launch_ranks() > 1) {
    code = px_cli_ranks_begin(ctx, &comm, &progress);
    if (code) {
      px_context_free(ctx);
      px_cli_run_args_free(&a);
      return code;
    }
  }
  if (resume) {
    struct stat st;
    if ((render || verify) && stat(a.file, &st) == 0 && S_ISDIR(st.st_mode)) {
      snprintf(path, sizeof path, "%s/checkpoint.pxc", a.file);
      a.file = path;
    }
    s = PX_STATUS_OK;
    if (a.more > 0) {
      /* --more N: N steps past the checkpoint's step */
      struct px_checkpoint *ck = NULL;
      char steps[32];
      s = px_checkpoint_open(ctx, a.file, &ck);
      if (s == PX_STATUS_OK) {
        snprintf(steps, sizeof steps, "%llu",
                 (unsigned long long)px_checkpoint_step(ck) + (unsigned long long)a.more);
        px_checkpoint_close(ck);
        if (px_cli_push(&a, "time.steps", steps, 0) != 0) s = PX_STATUS_NOMEM;
      }
    }
    if (s == PX_STATUS_OK)
      s = px_sim_open(ctx, a.file, a.overrides, a.n,
                      render   ? PX_SIM_MODE_RENDER
                      : verify ? PX_SIM_MODE_CHECK
                               : PX_SIM_MODE_RUN,
                      &sim);
  } else {
    s = px_case_load(ctx, a.file, a.overrides, a.n, &c);
    if (s == PX_STATUS_OK)
      s = px_sim_create(ctx, c, check ? PX_SIM_MODE_CHECK : PX_SIM_MODE_RUN, &sim);
  }
  /* A failure before anything runs means that what the user gave partix
     (command line, case, input files, checkpoint) is wrong or unusable: exit
     2, as a usage error; a failure while running exits 1. */
  setup = s != PX_STATUS_OK && s != PX_STATUS_NOMEM && s != PX_STATUS_INTERNAL;
  if (s == PX_STATUS_OK && render) {
    s = px_sim_render(sim);
    if (s == PX_STATUS_OK && cli->log_level >= PX_LOG_LEVEL_INFO)
      printf("pictures of step %ld written to %s\n", px_sim_step_index(sim),
             px_sim_output_dir(sim));
  } else if (s == PX_STATUS_OK && verify) {
    printf(
        "%s: ok: %s checkpoint at step %ld (t = %.9g s), the case and every section "
        "checked and loaded\n",
        a.file, px_case_solver(px_sim_case(sim)), px_sim_step_index(sim), px_sim_time(sim));
    if (a.sections) s = px_cli_list_sections(ctx, a.file);
  } else if (s == PX_STATUS_OK && check) {
    printf("%s: ok (%s solver, %ld steps of dt = %.6g)\n", a.file, px_case_solver(px_sim_case(sim)),
           px_sim_step_count(sim), px_sim_dt(sim));
  } else if (s == PX_STATUS_OK) {
    px_context_set_interrupt_flag(ctx, &px_cli_interrupt);
    signal(SIGINT, px_cli_on_signal);
    signal(SIGTERM, px_cli_on_signal);
    px_sim_set_progress(sim, progress ? stderr : NULL, -1);
    s = px_sim_run(sim);
  }
  if (s != PX_STATUS_OK && px_comm_rank(px_context_comm(ctx)) == 0) {
    const char *msg = px_context_message(ctx);
    fprintf(stderr, "%s%s\n",
            s == PX_STATUS_CONFIG ? "" : "partix: ", msg[0] ? msg : px_status_message(s));
  }
  code = setup ? PX_CLI_EXIT_USAGE : px_cli_exit_code(s);
  if (s != PX_STATUS_OK && comm && !px_comm_settle(comm, PX_CLI_SETTLE_S)) {
    /* this rank failed alone where the ranks do not agree on each status
       (inside a solver's create): the others wait in a collective it will
       never join, and MPI_Finalize would hang the job */
    int rank = px_comm_rank(comm);
    const char *msg = px_context_message(ctx);
    char own[32];
    snprintf(own, sizeof own, "rank %d: ", rank);
    if (!msg[0]) msg = px_status_message(s);
    /* rank 0 printed its message above; an agreement may have prefixed it */
    if (rank != 0)
      fprintf(stderr, "partix: %s%s\n", strncmp(msg, own, strlen(own)) ? own : "", msg);
    fprintf(stderr, "partix: rank %d failed while the other ranks went on: ending the job\n", rank);
    fflush(NULL);
    px_comm_abort(comm, code);
  }
  px_sim_free(sim);
  px_context_free(ctx);
  px_cli_ranks_end(comm);
  px_cli_run_args_free(&a);
  return code;
}

int px_cli_run(struct px_cli *cli) { return px_cli_run_common(cli); }
int px_cli_check(struct px_cli *cli) { return px_cli_run_common(cli); }
int px_cli_resume(struct px_cli *cli) { return px_cli_run_common(cli); }
int px_cli_render(struct px_cli *cli) { return px_cli_run_common(cli); }
int px_cli_verify(struct px_cli *cli) { return px_cli_run_common(cli); }
