// The tessellation stage's launcher (kernels/tessellate.cl): uploads a PackedDisplacement and
// queues, in place of triangle setup, the tessellation of every patch and the setup of every
// micro-triangle, so binning, raster and shading run on the displaced surface unchanged.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include "pipeline/displacement_packing.h"

namespace seamcl {

class TessellateLauncher {
 public:
  explicit TessellateLauncher(ClRuntime& runtime) : runtime_(runtime) {}

  // Uploads the patches, samples, positions and normals, and sizes the vertex buffer.
  void load(PackedDisplacement packed);
  const PackedDisplacement& packed() const { return packed_; }
  bool loaded() const { return loaded_; }
  void release();

  // Queues tessellate and tessellated_setup (kernels of the geometry program),
  // writing each micro-triangle's fan of records into `setups` and its size into `slot_counts`
  // (as triangle_setup does); one event each is appended to `tessellate_events` and `setup_events`.
  void enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups,
               const cl::Buffer& slot_counts, const cl::Buffer& stats, int input_triangles, std::vector<cl::Event>& tessellate_events,
               std::vector<cl::Event>& setup_events);

  // Only tessellates (for the gap metric and the kernel tests), then reads the vertices back.
  std::vector<TessVertex> tessellate();
  // The vertices of the last enqueue or tessellate.
  std::vector<TessVertex> read_vertices();

  size_t device_bytes() const;

 private:
  struct Kernels {
    cl::Kernel tessellate, setup;
  };
  Kernels& kernels();  // built on first use
  void enqueue_tessellate(Kernels& k, std::vector<cl::Event>* events);

  ClRuntime& runtime_;
  std::optional<Kernels> kernels_;
  PackedDisplacement packed_;
  bool loaded_ = false;
  cl::Buffer params_, patches_, samples_, positions_, normals_, vertices_;
};

}  // namespace seamcl
