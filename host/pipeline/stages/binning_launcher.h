// The binning stage's launcher (kernels/binning.cl): bin_count counts each chunk of triangles'
// slots per tile, bin_scan turns the counts into each tile's list offset, bin_fill writes the
// lists (a slot and the rows it covers per entry). The buffers are kept for raster to read.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

class BinningLauncher {
 public:
  explicit BinningLauncher(ClRuntime& runtime) : runtime_(runtime) {}

  // Sizes the per-tile counters for the frame's tiles and input triangles, and the tile lists for
  // p.bin_capacity entries.
  void reserve(const FrameParams& p);
  // Queues count, scan and fill of the frame's setup records; their events are appended.
  void enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups, const cl::Buffer& slot_counts,
               const cl::Buffer& stats, const FrameParams& p, std::vector<cl::Event>& events);

  const cl::Buffer& tile_counts() const { return tile_counts_; }
  const cl::Buffer& tile_offsets() const { return tile_offsets_; }
  const cl::Buffer& tile_lists() const { return tile_lists_; }
  const cl::Buffer& tile_entry_rows() const { return tile_entry_rows_; }
  // The entries the tile lists have room for.
  uint32_t tile_list_capacity() const { return tile_lists_capacity_; }

  // The last frame's, of `tiles` tiles; the lists' first `entries` entries (slots in input order
  // for `triangles` input triangles).
  std::vector<uint32_t> read_tile_counts(size_t tiles);
  std::vector<uint32_t> read_tile_offsets(size_t tiles);
  std::vector<uint32_t> read_tile_lists(size_t entries, uint32_t triangles);
  std::vector<uint16_t> read_tile_entry_rows(size_t entries);

  // Drops the tile lists only: the next reserve allocates them at the entries it asks for.
  void release_tile_lists();
  void release();
  size_t device_bytes() const;

 private:
  struct Kernels {
    cl::Kernel count, scan, fill;
  };
  ClRuntime& runtime_;
  Kernels& kernels();  // built on first use: the geometry program has no variants
  Kernels kernel_;
  cl::Buffer tile_counts_, tile_offsets_, chunk_counts_, tile_lists_, tile_entry_rows_;
  size_t tiles_capacity_ = 0, chunk_counts_capacity_ = 0;
  uint32_t tile_lists_capacity_ = 0;
};

}  // namespace seamcl
