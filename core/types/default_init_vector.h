// A std::vector whose vector(n) and resize(n) leave new elements
// default-initialized: for a trivial type, unwritten, where std::vector
// zeroes them. A large fresh buffer costs a page fault per 4 KiB on first
// touch; zeroing pays that at allocation, in one serial call that cannot
// poll for cancellation. Left unwritten, the faults happen in the pass that
// fills the buffer, which polls, and in parallel if that pass is.
#pragma once

#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace surfinspect {

template <typename T>
class DefaultInitAllocator : public std::allocator<T> {
 public:
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}

  // Value-less construction default-initializes; anything else constructs
  // as std::allocator does.
  template <typename U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using DefaultInitVector = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace surfinspect
