/* Internal declarations of the partix command. */
#ifndef PX_CLI_H
#define PX_CLI_H

#include "partix/partix.h"

enum px_cli_exit {
  PX_CLI_EXIT_OK = 0,
  PX_CLI_EXIT_FAILURE = 1,
  PX_CLI_EXIT_USAGE = 2,
  PX_CLI_EXIT_INTERRUPTED = 130
};

struct px_cli {
  int argc;            /* arguments after the command name */
  char **argv;         /* borrowed from main */
  const char *command; /* borrowed */
  enum px_log_level log_level;
};

struct px_cli_command {
  const char *name;
  const char *summary;
  int (*run)(struct px_cli *cli);
};

int px_cli_info(struct px_cli *cli);
int px_cli_run(struct px_cli *cli);
int px_cli_check(struct px_cli *cli);
int px_cli_resume(struct px_cli *cli);
int px_cli_keys(struct px_cli *cli);
int px_cli_render(struct px_cli *cli);
int px_cli_summary(struct px_cli *cli);
int px_cli_verify(struct px_cli *cli);
int px_cli_sweep(struct px_cli *cli);
/* 1 if argv holds -h/--help. */
int px_cli_wants_help(const struct px_cli *cli);
/* Create a context logging at the CLI's level; prints and returns NULL on failure. */
struct px_context *px_cli_context(const struct px_cli *cli);
/* Ranks of an MPI launch (mpirun/mpiexec/srun), 1 outside one. */
long px_cli_launch_ranks(void);
/* Map a status to an exit code. */
int px_cli_exit_code(enum px_status status);

#endif
