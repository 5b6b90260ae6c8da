/* The partix command. The only code that decides exit codes:
 *   0 success;
 *   1 a failure while running (a blow-up, a write error such as a full disk,
 *     out of memory);
 *   2 what the user gave is wrong or unusable, found before anything runs:
 *     usage, the case file (missing, unreadable or invalid), its input files,
 *     a checkpoint that cannot be resumed;
 *   130 interrupted (Ctrl-C, SIGTERM; a checkpoint was written). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "partix/partix.h"

static const struct px_cli_command px_cli_commands[] = {
    {"run", "run a simulation from a case file", px_cli_run},
    {"check", "validate a case file without running it", px_cli_check},
    {"resume", "continue a run from its checkpoint", px_cli_resume},
    {"render", "draw the pictures of a run again from its checkpoint", px_cli_render},
    {"sweep", "run a case for many values of some of its keys, then tabulate", px_cli_sweep},
    {"part3d", "a 3D part through its cross-sections: runs them, maps the results", px_cli_part3d},
    {"summary", "print what runs report (RUN_DIR/summary.json) as a table", px_cli_summary},
    {"verify", "check a checkpoint (structure, case, contents) without running", px_cli_verify},
    {"keys", "list the keys a case file may hold", px_cli_keys},
    {"info", "show version, build options, backends and OpenCL devices", px_cli_info},
};

static void px_cli_usage(FILE *out) {
  size_t i;
  fprintf(out,
          "partix %s: particle mechanics on CPUs and OpenCL devices\n\n"
          "usage: partix [-v|-q] COMMAND [ARGS]\n\ncommands:\n",
          px_version());
  for (i = 0; i < sizeof px_cli_commands / sizeof px_cli_commands[0]; ++i)
    fprintf(out, "  %-8s %s\n", px_cli_commands[i].name, px_cli_commands[i].summary);
  fprintf(out,
          "\noptions:\n"
          "  -v, --verbose   more log output (repeat for trace)\n"
          "  -q, --quiet     only errors and warnings\n"
          "  --version       print the version\n"
          "  -h, --help      this help; `partix COMMAND --help` for a command\n");
}

int main(int argc, char **argv) {
  struct px_cli cli;
  int i = 1;
  size_t k;
  memset(&cli, 0, sizeof cli);
  cli.log_level = PX_LOG_LEVEL_INFO;
  for (; i < argc && argv[i][0] == '-'; ++i) {
    if (strcmp(argv[i], "-v") == 0 || strcmp(argv[i], "--verbose") == 0) {
      if (cli.log_level < PX_LOG_LEVEL_TRACE) cli.log_level++;
    } else if (strcmp(argv[i], "-q") == 0 || strcmp(argv[i], "--quiet") == 0) {
      cli.log_level = PX_LOG_LEVEL_WARN;
    } else if (strcmp(argv[i], "--version") == 0) {
      printf("partix %s\n", px_version());
      return PX_CLI_EXIT_OK;
    } else if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
      px_cli_usage(stdout);
      return PX_CLI_EXIT_OK;
    } else {
      fprintf(stderr, "partix: unknown option '%s'\n\n", argv[i]);
      px_cli_usage(stderr);
      return PX_CLI_EXIT_USAGE;
    }
  }
  if (i >= argc) {
    px_cli_usage(stderr);
    return PX_CLI_EXIT_USAGE;
  }
  for (k = 0; k < sizeof px_cli_commands / sizeof px_cli_commands[0]; ++k) {
    if (strcmp(argv[i], px_cli_commands[k].name) == 0) {
      cli.argc = argc - i - 1;
      cli.argv = argv + i + 1;
      cli.command = px_cli_commands[k].name;
      return px_cli_commands[k].run(&cli);
    }
  }
  fprintf(stderr, "partix: unknown command '%s'\n\n", argv[i]);
  px_cli_usage(stderr);
  return PX_CLI_EXIT_USAGE;
}
