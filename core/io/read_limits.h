// Limits that every reader applies before it allocates from a declared
// count. A reader never trusts a header: besides these caps, every count is
// checked against what the file's size can hold.
#pragma once

#include <cstdint>

namespace surfinspect {

struct CloudReadLimits {
  uint64_t max_points = 200'000'000;  // refuse larger declared counts
};

struct MeshReadLimits {
  uint64_t max_file_bytes = uint64_t{2} << 30;
  uint64_t max_triangles = 50'000'000;
};

}  // namespace surfinspect
