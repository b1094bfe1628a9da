#pragma once
// keep_freed_memory(): the program keeps the memory it frees for its own reuse instead of
// handing it back to the kernel.
//
// glibc's defaults give a freed block back when 128 KiB are free at the top of the heap, and map
// each block of 128 KiB or more on its own (unmapped again when freed; the threshold adapts only
// after such a free). An analysis that allocates and frees the same buffers at every Newton step
// or period (histories, step maps, Krylov bases) then faults their pages in again each time, at
// about 1 us per 4 KiB page on the test machine. With blocks up to 32 MiB (glibc's own upper
// bound for the adaptive threshold) taken from the heap and the heap never trimmed on free, a
// page is faulted in once per process. Bigger blocks (bases at N ~ 10^6) are still mapped on
// their own and unmapped when freed, so the peak is unchanged; memory_probe.hpp's malloc_trim
// still trims on demand.
//
// Only the program calls it (main.cpp): it owns its short-lived process. The Python module
// leaves the interpreter's allocator settings alone.
namespace delayspec::cli {

void keep_freed_memory();

}  // namespace delayspec::cli
