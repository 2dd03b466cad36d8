#include "core/process/buffer_reuse.h"

#include <malloc.h>

namespace surfinspect {

bool ReuseFreedLargeBuffers() {
  // 32 MiB is glibc's ceiling for M_MMAP_THRESHOLD on 64-bit (HEAP_MAX_SIZE / 2).
  const bool mmap_ok = mallopt(M_MMAP_THRESHOLD, static_cast<int>(kHeapBufferLimitBytes)) == 1;
  const bool trim_ok = mallopt(M_TRIM_THRESHOLD, 256 << 20) == 1;
  return mmap_ok && trim_ok;
}

}  // namespace surfinspect
