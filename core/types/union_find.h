// Union-find (disjoint sets) over the indices 0..n-1, the connected-component
// kernel of both link-clustering paths. Path halving, and the smaller root
// always becomes the root of a merged set, so parent(i) <= i for every i: a
// second pass in index order then finds every element's root already final
// (link_clustering_grid.cpp relies on this).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace surfinspect {

class UnionFind {
 public:
  UnionFind() = default;
  // n singletons.
  explicit UnionFind(std::size_t n) { Reset(n); }
  void Reset(std::size_t n);
  void Reserve(std::size_t n) { parent_.reserve(n); }
  // Appends a singleton and returns its index.
  int32_t Add() {
    const auto id = static_cast<int32_t>(parent_.size());
    parent_.push_back(id);
    return id;
  }
  std::size_t size() const { return parent_.size(); }

  // The root of i's set (halves the path on the way).
  int32_t Find(int32_t i) {
    while (parent_[i] != i) {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  // Merges two roots; returns the root of the merged set (the smaller one).
  int32_t LinkRoots(int32_t root_a, int32_t root_b) {
    if (root_a < root_b) {
      parent_[root_b] = root_a;
      return root_a;
    }
    parent_[root_a] = root_b;
    return root_b;
  }
  // Merges the sets of a and b; returns the merged set's root.
  int32_t Union(int32_t a, int32_t b) {
    a = Find(a);
    b = Find(b);
    return a == b ? a : LinkRoots(a, b);
  }
  // Appends `other`'s elements as size() + i, with their links: a forest
  // built apart (a band of rows, say) joins this one, parent(i) <= i kept.
  void Append(const UnionFind& other);
  // The parent array (parent[i] <= i), e.g. to relabel in place.
  std::vector<int32_t> ReleaseParents() && { return std::move(parent_); }

 private:
  std::vector<int32_t> parent_;
};

}  // namespace surfinspect
