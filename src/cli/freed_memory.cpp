#include "cli/freed_memory.hpp"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace delayspec::cli {

void keep_freed_memory() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, -1);  // never trim on free (malloc_trim still does)
#endif
}

}  // namespace delayspec::cli
