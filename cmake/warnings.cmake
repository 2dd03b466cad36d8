# One warnings function for our own targets only; third-party headers come in
# as SYSTEM includes through their imported targets and stay quiet.
# The fuzz build uses clang, whose warnings differ from GCC's: there they
# are shown but do not stop the build (GCC's -Werror build is the gate).
function(surfinspect_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-deprecated-declarations
                                           $<$<NOT:$<BOOL:${SURFINSPECT_FUZZ}>>:-Werror>)
endfunction()
