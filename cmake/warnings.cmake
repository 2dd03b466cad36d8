# One warnings function for our own targets only; third-party headers come in
# as SYSTEM includes through their imported targets and stay quiet.
function(surfinspect_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Werror
                                           -Wno-deprecated-declarations)
endfunction()
