#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>

#include "fuzz/fuzz_target.h"
#include "fuzz/replay.h"

namespace surfinspect::fuzz {

std::map<std::string, TargetFn>& Targets() {
  static std::map<std::string, TargetFn> targets;
  return targets;
}

bool RegisterTarget(const char* name, TargetFn fn) {
  Targets()[name] = fn;
  return true;
}

std::string WriteScratchFile(std::string_view bytes, const std::string& extension) {
  // /dev/shm keeps the per-input write off the disk; fall back to the temp folder.
  static const std::string folder = std::filesystem::is_directory("/dev/shm")
                                        ? "/dev/shm"
                                        : std::filesystem::temp_directory_path().string();
  const std::string path =
      folder + "/surfinspect-fuzz-" + std::to_string(::getpid()) + "." + extension;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error("cannot write " + path);
  const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error("short write to " + path);
  return path;
}

}  // namespace surfinspect::fuzz
