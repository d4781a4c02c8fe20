// The triangle setup stage's launcher (kernels/triangle_setup.cl): transforms and clips every
// input triangle into its fan of records (up to SEAMCL_CLIP_SLOTS) and counts them, into buffers
// it keeps for binning, raster and shading to read.
#pragma once
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

// The device keeps setup records slot-major (slot k of input triangle t at k * triangles + t;
// kernels/seamcl_types.h); the read-backs number them in input order, t * SEAMCL_CLIP_SLOTS + k,
// as the twins do.
inline uint32_t input_order_slot(uint32_t slot, uint32_t triangles) {
  if (slot == SEAMCL_NO_TRIANGLE || triangles == 0) return slot;
  return (slot % triangles) * SEAMCL_CLIP_SLOTS + slot / triangles;
}

class TriangleSetupLauncher {
 public:
  explicit TriangleSetupLauncher(ClRuntime& runtime) : runtime_(runtime) {}

  // Sizes the records and counts for `input_triangles`; the tessellation stage writes them too.
  void reserve(size_t input_triangles);
  // Queues setup of `input_triangles` triangles (none: nothing is queued); its event is appended.
  void enqueue(const cl::Buffer& frame_params, const cl::Buffer& positions, const cl::Buffer& faces,
               const cl::Buffer& stats, int input_triangles, std::vector<cl::Event>& events);

  const cl::Buffer& setups() const { return setups_; }
  const cl::Buffer& slot_counts() const { return slot_counts_; }

  // The records of the last frame of `triangles` input triangles, in input order; input triangle t
  // belongs to face t / triangles_per_face.
  std::vector<TriangleSetup> read_setups(size_t triangles, size_t triangles_per_face);

  void release();
  size_t device_bytes() const;

 private:
  ClRuntime& runtime_;
  cl::Kernel& kernel();  // built on first use: the geometry program has no variants
  cl::Kernel kernel_;
  cl::Buffer setups_, slot_counts_;
  size_t setups_capacity_ = 0, slot_counts_capacity_ = 0;
};

}  // namespace seamcl
