// Process-wide allocator setting for one-shot programs (the surfinspect CLI)
// that fill 100+ MB of fresh buffers once and exit.
#pragma once

#include <cstddef>

namespace surfinspect {

// A fresh 4 KiB page costs a page fault on first touch, a large share of
// `surfinspect errormap`'s wall time on 10^6 points (the peers bench's
// command rows time that command, process start to exit). With
// transparent huge pages in "madvise" mode (the kernel default), one fault
// maps 2 MiB instead. This grows glibc's heap once by `reserve_bytes` of
// address space (not memory: pages are still mapped on first touch), marks
// that range MADV_HUGEPAGE, and keeps every thread's allocations in that one
// heap (M_ARENA_MAX = 1; TBB workers would otherwise get arenas of their own,
// mapped without the advice). Buffers above glibc's mmap threshold
// (ReuseFreedLargeBuffers: 32 MiB) are mapped on their own, without it.
// Resident memory grows in 2 MiB steps. Not for the server: one arena
// serializes its concurrent calls' allocations.
// Call it once, first thing in main, after ReuseFreedLargeBuffers. Returns
// false, leaving the heap as glibc made it apart from the settings above,
// when the heap cannot grow (strict overcommit) or the kernel refuses the
// advice (THP compiled out); results never depend on it.
bool BackHeapWithHugePages(std::size_t reserve_bytes);

// The reserve the CLI asks for: room for a 10^7-point error map's buffers.
constexpr std::size_t kCliHeapReserveBytes = std::size_t{1} << 30;

}  // namespace surfinspect
