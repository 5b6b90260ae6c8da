#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

int px_cli_wants_help(const struct px_cli *cli) {
  int i;
  for (i = 0; i < cli->argc; ++i)
    if (strcmp(cli->argv[i], "-h") == 0 || strcmp(cli->argv[i], "--help") == 0) return 1;
  return 0;
}

struct px_context *px_cli_context(const struct px_cli *cli) {
  struct px_context *ctx = NULL;
  if (px_context_create(&ctx) != PX_STATUS_OK) {
    fprintf(stderr, "partix: out of memory\n");
    return NULL;
  }
  px_context_set_log_level(ctx, cli->log_level);
  return ctx;
}

int px_cli_exit_code(enum px_status status) {
  switch (status) {
    case PX_STATUS_OK: return PX_CLI_EXIT_OK;
    case PX_STATUS_CONFIG:
    case PX_STATUS_INVALID: return PX_CLI_EXIT_USAGE;
    case PX_STATUS_INTERRUPTED: return PX_CLI_EXIT_INTERRUPTED;
    default: return PX_CLI_EXIT_FAILURE;
  }
}

/* Ranks of an MPI launch (mpirun/mpiexec/srun set one of these), 1 outside
 * one: `run` and `resume` start MPI only when K > 1, so a plain `partix run`
 * never pays for (or depends on) an MPI start-up. */
long px_cli_launch_ranks(void) {
  static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE",
                                     "MPI_LOCALNRANKS", "SLURM_STEP_NUM_TASKS"};
  size_t i;
  for (i = 0; i < sizeof vars / sizeof vars[0]; ++i) {
    const char *v = getenv(vars[i]);
    if (v && atol(v) > 1) return atol(v);
  }
  return 1;
}

char *px_cli_override_text(const char *key, const char *value) {
  const size_t len = strlen(key) + 4 * strlen(value) + 4;
  char *s = malloc(len);
  const unsigned char *v;
  size_t at;
  if (!s) return NULL;
  at = (size_t)snprintf(s, len, "%s=\"", key);
  for (v = (const unsigned char *)value; *v; ++v) {
    if (*v == '"' || *v == '\\') s[at++] = '\\';
    if (*v < 0x20 || *v == 0x7f)
      at += (size_t)snprintf(s + at, len - at, "\\x%02x", *v);
    else
      s[at++] = (char)*v;
  }
  s[at++] = '"';
  s[at] = '\0';
  return s;
}
