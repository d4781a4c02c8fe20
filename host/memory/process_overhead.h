// What a process holds beyond the arrays and buffers of a figure: allocator and driver
// bookkeeping, page rounding, the packing threads' arenas. The process_shares of a render and of a
// compare include it; the device and host figures, exact to the byte where they can be, do not.
#pragma once
#include <seamcl/memory/render_memory.h>

namespace seamcl {

// Adds 1/64 of the figure to its largest share.
void add_process_overhead(MemoryShares& figure);

}  // namespace seamcl
