#include "tests/support/small_file_system.h"

#include <sys/mount.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace surfinspect::testing {

std::unique_ptr<SmallFileSystem> SmallFileSystem::Mount(uint64_t bytes, std::string* why) {
  std::unique_ptr<SmallFileSystem> fs(new SmallFileSystem());
  const std::string options = "size=" + std::to_string(bytes);
  if (::mount("tmpfs", fs->dir_.path().c_str(), "tmpfs", 0, options.c_str()) != 0) {
    *why = "cannot mount a tmpfs at " + fs->dir_.path() + ": " + std::strerror(errno) +
           " (needs root)";
    return nullptr;
  }
  fs->mounted_ = true;
  return fs;
}

SmallFileSystem::~SmallFileSystem() {
  if (mounted_) ::umount2(dir_.path().c_str(), MNT_DETACH);
}

uint64_t FillWithZeros(const std::string& path, uint64_t bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  const std::vector<char> block(1 << 16, 0);
  uint64_t written = 0;
  while (written < bytes && out) {
    const uint64_t n = std::min<uint64_t>(block.size(), bytes - written);
    out.write(block.data(), static_cast<std::streamsize>(n));
    out.flush();
    if (out) written += n;
  }
  return written;
}

}  // namespace surfinspect::testing
