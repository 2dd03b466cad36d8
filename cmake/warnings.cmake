# One warnings function for our own targets only; third-party headers come in
# as SYSTEM includes through their imported targets and stay quiet.
# The sanitizer builds show warnings but do not stop on them: clang's differ
# from GCC's, and GCC with -fsanitize=address reports false
# -Wmaybe-uninitialized inside std::function. The plain GCC build is the gate.
function(surfinspect_warnings target)
  target_compile_options(
    ${target} PRIVATE -Wall -Wextra -Wpedantic -Wno-deprecated-declarations
                      $<$<NOT:$<OR:$<BOOL:${SURFINSPECT_FUZZ}>,$<BOOL:${SURFINSPECT_SANITIZE}>>>:-Werror>)
endfunction()
