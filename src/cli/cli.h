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
int px_cli_part3d(struct px_cli *cli);

/* Reading a run's summary.json (cli/summary.c; `partix summary` and
 * `partix sweep` share them). */
struct fy_document;
struct fy_node;
/* Member `key` of a mapping node; NULL when map is not a mapping or lacks it. */
struct fy_node *px_cli_json_get(struct fy_node *map, const char *key);
/* The value node of quantity `name` ({"quantities": {name: {"value": V}}}),
 * NULL when absent. */
struct fy_node *px_cli_summary_value(struct fy_document *d, const char *name);
/* A value as text: a scalar, or a list as "[a, b]"; null or absent: `none`;
 * brief: reals with six significant digits (tables). */
void px_cli_summary_text(struct fy_node *n, char *buf, size_t size, int brief, const char *none);
/* 1 if argv holds -h/--help. */
int px_cli_wants_help(const struct px_cli *cli);
/* Create a context logging at the CLI's level; prints and returns NULL on failure. */
struct px_context *px_cli_context(const struct px_cli *cli);
/* Ranks of an MPI launch (mpirun/mpiexec/srun), 1 outside one. */
long px_cli_launch_ranks(void);
/* Map a status to an exit code. */
int px_cli_exit_code(enum px_status status);
/* The override "key=\"value\"" (malloc'ed; NULL: out of memory): value as
 * text as given (a folder name such as "my run #2" or "'q'"), a YAML
 * double-quoted string, which the override's YAML parse would otherwise
 * cut at " #" or unquote; control characters as \xNN. */
char *px_cli_override_text(const char *key, const char *value);

#endif
