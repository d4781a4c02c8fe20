#include "pipeline/stages/binning_launcher.h"

#include <algorithm>

#include "pipeline/frame_params.h"
#include "pipeline/stages/stage_buffers.h"
#include "pipeline/stages/triangle_setup_launcher.h"

namespace seamcl {

BinningLauncher::Kernels& BinningLauncher::kernels() {
  if (kernel_.count() == nullptr) {
    const cl::Program& program = runtime_.program(KernelProgram::Geometry);
    kernel_ = Kernels{cl::Kernel(program, "bin_count"), cl::Kernel(program, "bin_scan"), cl::Kernel(program, "bin_fill")};
  }
  return kernel_;
}

void BinningLauncher::reserve(const FrameParams& p) {
  const cl::Context& context = runtime_.context();
  const size_t tiles = static_cast<size_t>(p.tiles_x) * p.tiles_y;
  if (tiles > tiles_capacity_ || tiles_capacity_ == 0) {
    tiles_capacity_ = tiles;
    tile_counts_ = cl::Buffer(context, CL_MEM_READ_WRITE, tiles * sizeof(cl_uint));
    tile_offsets_ = cl::Buffer(context, CL_MEM_READ_WRITE, tiles * sizeof(cl_uint));
  }
  grow_buffer(chunk_counts_, chunk_counts_capacity_,
              std::max<size_t>(bin_chunks(static_cast<size_t>(p.input_triangles), tiles).chunks, 1) * tiles,
              sizeof(cl_uint), context);
  if (tile_lists_() == nullptr || tile_lists_capacity_ < p.bin_capacity) {
    tile_lists_capacity_ = p.bin_capacity;
    tile_lists_ = cl::Buffer(context, CL_MEM_READ_WRITE, static_cast<size_t>(p.bin_capacity) * sizeof(cl_uint));
    tile_entry_rows_ = cl::Buffer(context, CL_MEM_READ_WRITE, static_cast<size_t>(p.bin_capacity) * sizeof(cl_ushort));
  }
}

void BinningLauncher::enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups, const cl::Buffer& slot_counts,
                              const cl::Buffer& stats, const FrameParams& p, std::vector<cl::Event>& events) {
  cl::CommandQueue& queue = runtime_.queue();
  const size_t tiles = static_cast<size_t>(p.tiles_x) * p.tiles_y;
  const BinChunks chunks = bin_chunks(static_cast<size_t>(p.input_triangles), tiles);
  const cl_int chunk_triangles = static_cast<cl_int>(chunks.chunk_triangles);
  Kernels& kernel = kernels();
  if (chunks.chunks > 0) {
    kernel.count.setArg(0, frame_params);
    kernel.count.setArg(1, setups);
    kernel.count.setArg(2, slot_counts);
    kernel.count.setArg(3, chunk_counts_);
    kernel.count.setArg(4, chunk_triangles);
    queue.enqueueNDRangeKernel(kernel.count, cl::NullRange, cl::NDRange(chunks.chunks), cl::NDRange(1), nullptr,
                               &events.emplace_back());
  }
  kernel.scan.setArg(0, frame_params);
  kernel.scan.setArg(1, chunk_counts_);
  kernel.scan.setArg(2, static_cast<cl_int>(chunks.chunks));
  kernel.scan.setArg(3, tile_counts_);
  kernel.scan.setArg(4, tile_offsets_);
  kernel.scan.setArg(5, stats);
  queue.enqueueNDRangeKernel(kernel.scan, cl::NullRange, cl::NDRange(1), cl::NDRange(1), nullptr, &events.emplace_back());
  if (chunks.chunks > 0) {
    kernel.fill.setArg(0, frame_params);
    kernel.fill.setArg(1, setups);
    kernel.fill.setArg(2, slot_counts);
    kernel.fill.setArg(3, chunk_counts_);
    kernel.fill.setArg(4, chunk_triangles);
    kernel.fill.setArg(5, tile_lists_);
    kernel.fill.setArg(6, tile_entry_rows_);
    queue.enqueueNDRangeKernel(kernel.fill, cl::NullRange, cl::NDRange(chunks.chunks), cl::NDRange(1), nullptr,
                               &events.emplace_back());
  }
}

std::vector<uint32_t> BinningLauncher::read_tile_counts(size_t tiles) {
  return read_buffer<uint32_t>(runtime_.queue(), tile_counts_, tiles);
}

std::vector<uint32_t> BinningLauncher::read_tile_offsets(size_t tiles) {
  return read_buffer<uint32_t>(runtime_.queue(), tile_offsets_, tiles);
}

std::vector<uint32_t> BinningLauncher::read_tile_lists(size_t entries, uint32_t triangles) {
  std::vector<uint32_t> lists = read_buffer<uint32_t>(runtime_.queue(), tile_lists_, entries);
  for (uint32_t& slot : lists) slot = input_order_slot(slot, triangles);
  return lists;
}

std::vector<uint16_t> BinningLauncher::read_tile_entry_rows(size_t entries) {
  return read_buffer<uint16_t>(runtime_.queue(), tile_entry_rows_, entries);
}

void BinningLauncher::release_tile_lists() { tile_lists_ = tile_entry_rows_ = cl::Buffer(); }

void BinningLauncher::release() {
  tile_counts_ = tile_offsets_ = chunk_counts_ = tile_lists_ = tile_entry_rows_ = cl::Buffer();
  tiles_capacity_ = chunk_counts_capacity_ = 0;
  tile_lists_capacity_ = 0;
}

size_t BinningLauncher::device_bytes() const {
  return buffer_bytes(tile_counts_) + buffer_bytes(tile_offsets_) + buffer_bytes(chunk_counts_) + buffer_bytes(tile_lists_) +
         buffer_bytes(tile_entry_rows_);
}

}  // namespace seamcl
