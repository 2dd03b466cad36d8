// A small tmpfs mounted for one test, so that a full disk is real: writes
// fail with ENOSPC exactly as on a cell PC's full results disk. Mounting
// needs root (CI and the developers' machines run as root); where it is not
// allowed, Mount says why and the test skips loudly.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "tests/support/temp_dir.h"

namespace surfinspect::testing {

class SmallFileSystem {
 public:
  // A tmpfs of `bytes` (rounded to pages); null with `why` when not allowed.
  static std::unique_ptr<SmallFileSystem> Mount(uint64_t bytes, std::string* why);
  ~SmallFileSystem();  // unmounts (lazily, should a file still be open)
  const std::string& path() const { return dir_.path(); }
  std::string File(const std::string& name) const { return dir_.File(name); }

 private:
  SmallFileSystem() = default;
  TempDir dir_;
  bool mounted_ = false;
};

// Writes `bytes` of zeros at `path`, as much as fits; returns what fitted.
uint64_t FillWithZeros(const std::string& path, uint64_t bytes);

}  // namespace surfinspect::testing
