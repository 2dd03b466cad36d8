// Process-wide allocator setting for programs that move ~10 MB clouds over
// and over (surfinspectd, the clients, the benches).
#pragma once

#include <cstddef>

namespace surfinspect {

// glibc maps every allocation above its threshold (128 KiB, rising to the
// largest size freed so far) fresh from the kernel and unmaps it on free, so
// each 9.4 MB cloud buffer is first-touched page by page, and those page
// faults are most of the time the Inspect stream spends receiving a view
// (the peers bench's service rows time one view streamed until received).
// This serves buffers up to 32 MiB from the heap and trims the heap only
// when more than 256 MiB is free, so the next call reuses the same pages.
// Resident memory then stays
// near its high-water mark, which the point and message limits bound.
// Call it once, first thing in main. Returns false if glibc refused.
bool ReuseFreedLargeBuffers();

// Largest buffer served from the heap after ReuseFreedLargeBuffers().
constexpr std::size_t kHeapBufferLimitBytes = std::size_t{32} << 20;

}  // namespace surfinspect
