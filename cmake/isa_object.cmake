# One translation unit compiled for one instruction set and linked into
# surfinspect_core, where its caller picks it at run time (after a cpuid
# check). -ffp-contract=off: no multiply-add is fused in one set and not
# in another. GCC 12's AVX-512 intrinsics pass an "undefined" register
# (_mm512_undefined_*) that its own -W(maybe-)uninitialized flag, so those
# two are off in these files under GCC. Extra arguments are the set's flags.
function(surfinspect_isa_object target source)
  add_library(${target} OBJECT ${source})
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR})
  surfinspect_warnings(${target})
  target_compile_options(
    ${target} PRIVATE ${ARGN} -ffp-contract=off
                      $<$<CXX_COMPILER_ID:GNU>:-Wno-uninitialized -Wno-maybe-uninitialized>)
  target_sources(surfinspect_core PRIVATE $<TARGET_OBJECTS:${target}>)
endfunction()
