#include "core/filter/union_find.h"

#include <numeric>

namespace surfinspect {

void UnionFind::Reset(std::size_t n) {
  parent_.resize(n);
  std::iota(parent_.begin(), parent_.end(), 0);
}

}  // namespace surfinspect
