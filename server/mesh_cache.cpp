#include "server/mesh_cache.h"

namespace surfinspect::server {

std::shared_ptr<const MeshIndex> MeshCache::Find(const std::string& sha256) {
  std::lock_guard<std::mutex> lock(mu_);
  auto it = by_key_.find(sha256);
  if (it == by_key_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, it->second);
  return it->second->index;
}

void MeshCache::Insert(const std::string& sha256, std::shared_ptr<const MeshIndex> index) {
  const std::size_t size = index->memory_bytes();
  std::lock_guard<std::mutex> lock(mu_);
  if (auto it = by_key_.find(sha256); it != by_key_.end()) {
    bytes_ -= it->second->bytes;
    lru_.erase(it->second);
    by_key_.erase(it);
  }
  if (size > max_bytes_) return;
  lru_.push_front({sha256, std::move(index), size});
  by_key_[sha256] = lru_.begin();
  bytes_ += size;
  while (bytes_ > max_bytes_ && !lru_.empty()) {
    bytes_ -= lru_.back().bytes;
    by_key_.erase(lru_.back().key);
    lru_.pop_back();
  }
}

std::size_t MeshCache::bytes() const {
  std::lock_guard<std::mutex> lock(mu_);
  return bytes_;
}

std::size_t MeshCache::entries() const {
  std::lock_guard<std::mutex> lock(mu_);
  return lru_.size();
}

}  // namespace surfinspect::server
