// Named triangle groups of a CAD file, for inspection regions that select a
// group by name. An OBJ file's `g NAME` and `o NAME` statements open a group;
// every `f` after them belongs to it, so a reader fills `names` in order of
// first appearance and `triangle_group[t]` with the index of the group open
// when triangle t was read (kNoGroup before any, or after a bare `g`). A face
// with several names (`g a b`) goes to the first. Empty = no groups.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace surfinspect {

struct MeshGroups {
  static constexpr uint32_t kNoGroup = UINT32_MAX;
  std::vector<std::string> names;
  std::vector<uint32_t> triangle_group;  // size 0 or the mesh's triangle count
};

}  // namespace surfinspect
