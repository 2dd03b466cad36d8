// The cancellation flag every long core loop polls: null means "cannot be
// cancelled". The server raises it from gRPC's OnCancel; loops poll it often
// enough that a cancelled call stops within milliseconds.
#pragma once

#include <atomic>

namespace surfinspect {

inline bool IsCancelled(const std::atomic<bool>* cancel) {
  return cancel != nullptr && cancel->load(std::memory_order_relaxed);
}

}  // namespace surfinspect
