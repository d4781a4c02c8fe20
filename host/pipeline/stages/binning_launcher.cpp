#include "pipeline/stages/binning_launcher.h"

#include <algorithm>

#include "pipeline/frame_params.h"
#include "pipeline/stages/stage_buffers.h"
#include "pipeline/stages/triangle_setup_launcher.h"

namespace seamcl {

void BinningLauncher::use_program(const std::string& program_options) {
  auto it = kernels_.find(program_options);
  if (it == kernels_.end()) {
    const cl::Program& program = runtime_.program(program_options);
    Kernels kernels{cl::Kernel(program, "bin_count"), cl::Kernel(program, "bin_scan"), cl::Kernel(program, "bin_fill")};
    it = kernels_.emplace(program_options, std::move(kernels)).first;
  }
  kernel_ = it->second;
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
  if (chunks.chunks > 0) {
    kernel_.count.setArg(0, frame_params);
    kernel_.count.setArg(1, setups);
    kernel_.count.setArg(2, slot_counts);
    kernel_.count.setArg(3, chunk_counts_);
    kernel_.count.setArg(4, chunk_triangles);
    queue.enqueueNDRangeKernel(kernel_.count, cl::NullRange, cl::NDRange(chunks.chunks), cl::NDRange(1), nullptr,
                               &events.emplace_back());
  }
  kernel_.scan.setArg(0, frame_params);
  kernel_.scan.setArg(1, chunk_counts_);
  kernel_.scan.setArg(2, static_cast<cl_int>(chunks.chunks));
  kernel_.scan.setArg(3, tile_counts_);
  kernel_.scan.setArg(4, tile_offsets_);
  kernel_.scan.setArg(5, stats);
  queue.enqueueNDRangeKernel(kernel_.scan, cl::NullRange, cl::NDRange(1), cl::NDRange(1), nullptr, &events.emplace_back());
  if (chunks.chunks > 0) {
    kernel_.fill.setArg(0, frame_params);
    kernel_.fill.setArg(1, setups);
    kernel_.fill.setArg(2, slot_counts);
    kernel_.fill.setArg(3, chunk_counts_);
    kernel_.fill.setArg(4, chunk_triangles);
    kernel_.fill.setArg(5, tile_lists_);
    kernel_.fill.setArg(6, tile_entry_rows_);
    queue.enqueueNDRangeKernel(kernel_.fill, cl::NullRange, cl::NDRange(chunks.chunks), cl::NDRange(1), nullptr,
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
