#include "partix/version.h"

#ifdef _OPENMP
#include <omp.h>
#endif
#ifdef PX_HAVE_MPI
#include <mpi.h>
#endif

#include "core/build_config.h"
#include "core/simd.h"

const char *px_version(void) { return PX_VERSION_STRING; }

void px_build_report(FILE *out) {
  fprintf(out, "version: %s\n", PX_VERSION_STRING);
  fprintf(out, "compiler: %s\n", PX_BUILD_COMPILER);
  fprintf(out, "build type: %s\n", PX_BUILD_TYPE);
  fprintf(out, "C flags: %s\n", PX_BUILD_FLAGS);
  fprintf(out, "SIMD: %s\n", px_simd_isa());
#ifdef _OPENMP
  fprintf(out, "OpenMP: %d (%d processors)\n", _OPENMP, omp_get_num_procs());
#else
  fprintf(out, "OpenMP: no\n");
#endif
#ifdef PX_HAVE_OPENCL
  fprintf(out, "OpenCL: yes (OpenCL 1.2 API)\n");
#else
  fprintf(out, "OpenCL: no\n");
#endif
#ifdef PX_HAVE_MPI
  {
    char lib[MPI_MAX_LIBRARY_VERSION_STRING];
    int len = 0, i;
    MPI_Get_library_version(lib, &len);
    for (i = 0; i < len; ++i)
      if (lib[i] == '\n' || lib[i] == ',') {
        lib[i] = '\0';
        break;
      }
    fprintf(out, "MPI: yes (MPI %d.%d, %s)\n", MPI_VERSION, MPI_SUBVERSION, lib);
  }
#else
  fprintf(out, "MPI: no\n");
#endif
}
