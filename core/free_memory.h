#pragma once
// Gives the heap's free pages back to the system once a stage has dropped large arrays.
//
// glibc keeps a freed block inside its arena, resident, when the block was smaller than its mmap
// threshold, which rises to the size of every mapped block freed (up to 32 MiB): after the first
// few stages of a long scan, arrays of several MiB come from the arenas, and what one stage frees
// stays in the process's peak memory while later stages allocate arrays of other sizes beside it.

#include <cstdlib>  // defines __GLIBC__ on glibc
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace arcwheel {

inline void ReturnFreedMemory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace arcwheel
