# Warning set for partix code. Library code must be clean under gcc and clang;
# PX_WERROR (on in CI) turns warnings into errors.
function(px_target_warnings target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wstrict-prototypes
    -Wmissing-prototypes -Wvla -Wno-unknown-pragmas
    $<$<BOOL:${PX_WERROR}>:-Werror>)
endfunction()
