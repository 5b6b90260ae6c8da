/* The partix command. The only code allowed to decide exit codes. */
#include <stdio.h>
#include <string.h>

#include "partix/partix.h"

int main(int argc, char **argv) {
  if (argc >= 2 && strcmp(argv[1], "info") == 0) {
    printf("partix %s\n", PX_VERSION_STRING);
    return 0;
  }
  fprintf(stderr, "usage: partix info\n");
  return 2;
}
