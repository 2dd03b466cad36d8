// Named triangle groups of a CAD file, for inspection regions that select a
// group by name. An OBJ file's `g NAME...` and `o NAME` statements open
// groups; every `f` after them belongs to each, so a reader fills `names` in
// order of first appearance and `triangle_group[t]` with the index of the
// first group open when triangle t was read (kNoGroup before any, or after a
// bare `g`). A face under several names (`g face:3 color:#ff0000 body:b`,
// as surfinspect cad writes a STEP face) belongs to all of them: the others
// are in `more`. Empty = no groups.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace surfinspect {

struct MeshGroups {
  static constexpr uint32_t kNoGroup = UINT32_MAX;
  std::vector<std::string> names;
  std::vector<uint32_t> triangle_group;  // size 0 or the mesh's triangle count
  // (triangle, group) for each group of a triangle after its first, sorted.
  std::vector<std::pair<uint32_t, uint32_t>> more;

  bool Contains(uint32_t triangle, uint32_t group) const {
    if (triangle >= triangle_group.size()) return false;
    return triangle_group[triangle] == group ||
           std::binary_search(more.begin(), more.end(), std::make_pair(triangle, group));
  }
};

}  // namespace surfinspect
