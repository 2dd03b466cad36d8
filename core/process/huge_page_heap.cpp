#include "core/process/huge_page_heap.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <climits>
#include <cstdint>
#include <cstdlib>

namespace surfinspect {

bool BackHeapWithHugePages(std::size_t reserve_bytes) {
  constexpr uintptr_t kHugePage = uintptr_t{2} << 20;
  if (reserve_bytes < kHugePage || reserve_bytes > static_cast<std::size_t>(INT_MAX)) return false;
  if (mallopt(M_ARENA_MAX, 1) != 1) return false;
  // glibc grows the heap by the request plus M_TOP_PAD, so one small
  // allocation that does not fit the heap's free top makes the whole reserve.
  if (mallopt(M_TOP_PAD, static_cast<int>(reserve_bytes)) != 1) return false;
  void* probe = std::malloc(std::size_t{1} << 20);
  if (probe == nullptr) return false;
  const auto first = reinterpret_cast<uintptr_t>(probe);
  std::free(probe);  // freeing may trim the top a little; the end is read after it
  const auto end = reinterpret_cast<uintptr_t>(sbrk(0));
  const uintptr_t start = (first + kHugePage - 1) & ~(kHugePage - 1);
  // The probe came from a heap that grew (not from an mmap'd fallback when
  // brk is refused) only if the heap now ends above it by most of the reserve.
  if (end <= start || end - first < reserve_bytes / 2) return false;
  return madvise(reinterpret_cast<void*>(start), end - start, MADV_HUGEPAGE) == 0;
}

}  // namespace surfinspect
