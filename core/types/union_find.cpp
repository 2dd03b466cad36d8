#include "core/types/union_find.h"

#include <numeric>

namespace surfinspect {

void UnionFind::Reset(std::size_t n) {
  parent_.resize(n);
  std::iota(parent_.begin(), parent_.end(), 0);
}

void UnionFind::Append(const UnionFind& other) {
  const auto offset = static_cast<int32_t>(parent_.size());
  parent_.reserve(parent_.size() + other.parent_.size());
  for (int32_t p : other.parent_) parent_.push_back(p + offset);
}

}  // namespace surfinspect
