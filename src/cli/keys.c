/* partix keys [SECTION]: every case-file key with type, default, range, meaning. */
#include <stdio.h>

#include "cli/cli.h"

int px_cli_keys(struct px_cli *cli) {
  enum px_status s;
  if (px_cli_wants_help(cli) || cli->argc > 1) {
    printf(
        "usage: partix keys [SECTION]\n\nLists every key a case file may hold (or those of one "
        "section,\ne.g. `partix keys time` or `partix keys vortex`), with its type,\ndefault, "
        "allowed range and meaning.\n");
    return cli->argc > 1 && !px_cli_wants_help(cli) ? PX_CLI_EXIT_USAGE : PX_CLI_EXIT_OK;
  }
  s = px_case_print_keys(stdout, cli->argc == 1 ? cli->argv[0] : NULL);
  if (s != PX_STATUS_OK) {
    fprintf(stderr, "partix keys: no section '%s'\n", cli->argv[0]);
    return PX_CLI_EXIT_USAGE;
  }
  return PX_CLI_EXIT_OK;
}
