#pragma once
// The heap's policy for a stage's working arrays.
//
// A stage's arrays (megabytes each) are freed and allocated again by the next stage. By default
// glibc gives such blocks back to the kernel and maps them anew, and every page of a block mapped
// anew faults on its first touch, which costs tens of microseconds a page on some virtual
// machines (a 1e8-sample `process` took some 45 000 faults). The program keeps blocks up to
// malloc's largest mapping threshold (32 MiB) in the heap for reuse instead; larger ones (a long
// scan's columns) are still mapped and unmapped whole. Where a stage has dropped large arrays and
// the next allocates arrays of other sizes, `ReturnFreedMemory` gives the heap's free pages back,
// so that they do not stay in the process's peak memory beside the new ones.

#include <cstdlib>  // defines __GLIBC__ on glibc
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace arcwheel {

// Called once, first thing in main(): a library's users keep their own heap policy.
inline void KeepFreedBlocksForReuse() {
#if defined(__GLIBC__)
  constexpr int kLargestHeapBlock = 32 << 20;  // glibc's own maximum for this threshold
  mallopt(M_MMAP_THRESHOLD, kLargestHeapBlock);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

inline void ReturnFreedMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace arcwheel
