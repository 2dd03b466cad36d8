// A byte-bounded LRU cache of built mesh indices keyed by the mesh's
// content hash (core/io/mesh_hash.h). Keeps the service stateless in effect:
// a miss only costs the client one inline re-send, and any replica can
// rebuild any entry. Thread-safe; entries are shared, so an index in use by
// a running call survives its eviction.
#pragma once

#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

#include "core/distance/mesh_index.h"

namespace surfinspect::server {

class MeshCache {
 public:
  explicit MeshCache(std::size_t max_bytes) : max_bytes_(max_bytes) {}

  std::shared_ptr<const MeshIndex> Find(const std::string& sha256);
  // Inserts (or refreshes) and evicts least-recently-used entries until the
  // total fits. An entry larger than the whole budget is not kept.
  void Insert(const std::string& sha256, std::shared_ptr<const MeshIndex> index);

  std::size_t bytes() const;
  std::size_t entries() const;

 private:
  struct Entry {
    std::string key;
    std::shared_ptr<const MeshIndex> index;
    std::size_t bytes;
  };
  const std::size_t max_bytes_;
  mutable std::mutex mu_;
  std::list<Entry> lru_;  // front = most recent
  std::unordered_map<std::string, std::list<Entry>::iterator> by_key_;
  std::size_t bytes_ = 0;
};

}  // namespace surfinspect::server
