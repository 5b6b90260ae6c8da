# Embed OpenCL C programs into the library at build time (CMake only, no Python).
# Each FILE.cl becomes a C byte array `px_cl_source_FILE` (NUL-terminated) with
# every `#include "..."` inlined, so that kernels share the physics headers of
# src/kernels/ with the C code and the binary needs no files at run time.
set(PX_EMBED_SCRIPT ${CMAKE_CURRENT_LIST_DIR}/PxEmbedFile.cmake)

function(px_embed_opencl out_var)
  set(generated)
  file(GLOB_RECURSE header_deps CONFIGURE_DEPENDS
       ${PROJECT_SOURCE_DIR}/src/kernels/*.h ${PROJECT_SOURCE_DIR}/src/compute/opencl/*.h
       ${PROJECT_SOURCE_DIR}/src/solvers/*.h)
  foreach(cl IN LISTS ARGN)
    get_filename_component(name ${cl} NAME_WE)
    set(out ${PROJECT_BINARY_DIR}/embedded/px_cl_${name}.c)
    add_custom_command(OUTPUT ${out}
      COMMAND ${CMAKE_COMMAND} -DINPUT=${cl} -DOUTPUT=${out} -DNAME=${name}
              -DINCLUDE_DIRS=${PROJECT_SOURCE_DIR}/src -P ${PX_EMBED_SCRIPT}
      DEPENDS ${cl} ${header_deps} ${PX_EMBED_SCRIPT}
      COMMENT "Embedding OpenCL program ${name}.cl"
      VERBATIM)
    list(APPEND generated ${out})
  endforeach()
  set(${out_var} ${generated} PARENT_SCOPE)
endfunction()
