// One fuzz target: SURFINSPECT_FUZZ_TARGET(name) { ...use data, size... }.
// Built for libFuzzer (SURFINSPECT_LIBFUZZER defined, `./run fuzz`) the body
// becomes LLVMFuzzerTestOneInput, one executable per target. In the normal
// build every target is linked into one `fuzz_replay` program that feeds it
// each file of fuzz/corpus/<name>/, so no crash the fuzzer found comes back.
// A target returns nothing: it must only survive its input.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace surfinspect::fuzz {

using TargetFn = void (*)(std::string_view bytes);

// Adds a target to the replay table; returns true so it can seed a static.
bool RegisterTarget(const char* name, TargetFn fn);

// Writes the bytes to a file of this process named NAME.EXT in a RAM folder
// and returns its path, for readers that take a path and pick the format by
// extension. The same path is reused by every input of a target.
std::string WriteScratchFile(std::string_view bytes, const std::string& extension);

}  // namespace surfinspect::fuzz

#ifdef SURFINSPECT_LIBFUZZER
#define SURFINSPECT_FUZZ_TARGET(name)                                                 \
  static void FuzzOne_##name(std::string_view bytes);                                 \
  extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) { \
    FuzzOne_##name(std::string_view(reinterpret_cast<const char*>(data), size));      \
    return 0;                                                                         \
  }                                                                                   \
  static void FuzzOne_##name(std::string_view bytes)
#else
#define SURFINSPECT_FUZZ_TARGET(name)                              \
  static void FuzzOne_##name(std::string_view bytes);              \
  [[maybe_unused]] static const bool kRegistered_##name =          \
      ::surfinspect::fuzz::RegisterTarget(#name, &FuzzOne_##name); \
  static void FuzzOne_##name(std::string_view bytes)
#endif
