# Sanitizer builds, each in a build folder of its own (see ./run):
#  SURFINSPECT_SANITIZE=ON  ASan + UBSan on every target (./run test --sanitize)
#  SURFINSPECT_FUZZ=ON      the same plus libFuzzer's coverage (./run fuzz)
# UBSan stops at the first finding, so a test or a fuzz run fails on it.
option(SURFINSPECT_SANITIZE "Build everything with AddressSanitizer and UBSan" OFF)
if(SURFINSPECT_SANITIZE OR SURFINSPECT_FUZZ)
  set(_san -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  if(SURFINSPECT_FUZZ)
    list(APPEND _san -fsanitize=fuzzer-no-link)
  endif()
  add_compile_options(${_san} -g)
  add_link_options(-fsanitize=address,undefined)
endif()
