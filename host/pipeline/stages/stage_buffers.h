// What the stage launchers share: their output buffers grow to the largest frame asked for and
// are kept, and the tests read them back.
#pragma once
#include <algorithm>
#include <cstddef>
#include <vector>

#include <seamcl/cl/cl_runtime.h>

namespace seamcl {

inline size_t round_up(size_t value, size_t multiple) { return (value + multiple - 1) / multiple * multiple; }

// Reallocates `buffer` for `needed` elements unless the `capacity` it holds suffices; at least one
// element, as OpenCL refuses zero-sized buffers.
inline void grow_buffer(cl::Buffer& buffer, size_t& capacity, size_t needed, size_t element_bytes,
                        const cl::Context& context) {
  if (needed <= capacity && capacity > 0) return;
  capacity = std::max<size_t>(needed, 1);
  buffer = cl::Buffer(context, CL_MEM_READ_WRITE, capacity * element_bytes);
}

// CL_MEM_SIZE of a buffer, 0 for one not allocated.
inline size_t buffer_bytes(const cl::Buffer& buffer) {
  return buffer() != nullptr ? buffer.getInfo<CL_MEM_SIZE>() : 0;
}

template <typename T>
std::vector<T> read_buffer(cl::CommandQueue& queue, const cl::Buffer& buffer, size_t count) {
  std::vector<T> out(count);
  if (count > 0) queue.enqueueReadBuffer(buffer, CL_TRUE, 0, count * sizeof(T), out.data());
  return out;
}

}  // namespace seamcl
