#include <stdio.h>

#include "cli/cli.h"

int px_cli_info(struct px_cli *cli) {
  struct px_context *ctx;
  if (px_cli_wants_help(cli)) {
    printf(
        "usage: partix info\n\nPrints the version, the build options, the compiled backends,\n"
        "every OpenCL platform and device, and the solvers of this build.\n");
    return PX_CLI_EXIT_OK;
  }
  ctx = px_cli_context(cli);
  if (!ctx) return PX_CLI_EXIT_FAILURE;
  printf("partix %s\n\n", px_version());
  printf("Build\n");
  px_build_report(stdout);
  {
    const char *const *names = px_sim_solver_names();
    size_t i;
    printf("\nSolvers\n");
    if (!names[0]) printf("  (none in this build)\n");
    for (i = 0; names[i]; ++i) printf("  %-10s %s\n", names[i], px_sim_solver_summary(names[i]));
  }
  printf("\n");
  px_backend_report(ctx, stdout);
  px_context_free(ctx);
  return PX_CLI_EXIT_OK;
}
