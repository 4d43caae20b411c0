#include "reuse_freed_memory.h"

#include <cstddef>  // defines __GLIBC__ where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace sdfc {

void reuseFreedMemory() {
#if defined(__GLIBC__)
  // Blocks below 32 MB come from the heap (not mmap, which unmaps them when
  // freed), and the heap's free top is kept up to 512 MB (not trimmed at
  // twice the last freed block).
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
}

}  // namespace sdfc
