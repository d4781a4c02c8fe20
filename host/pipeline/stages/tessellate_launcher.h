// The tessellation stage's launcher (kernels/tessellate.cl): uploads a PackedDisplacement and
// queues, in place of triangle setup, the tessellation of every patch, the displaced surface's
// normals at its vertices (for shading) and the setup of every micro-triangle, so binning and
// raster run on the displaced surface unchanged.
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

  // Uploads the patches, samples, positions, normals and corner table, and sizes the vertex and
  // vertex-normal buffers.
  void load(PackedDisplacement packed);
  const PackedDisplacement& packed() const { return packed_; }
  bool loaded() const { return loaded_; }
  void release();

  // Queues tessellate, with `normals` displaced_normals, and tessellated_setup (kernels of the
  // geometry program), writing each micro-triangle's fan of records into `setups` and its size
  // into `slot_counts` (as triangle_setup does); the events of tessellate and displaced_normals are
  // appended to `tessellate_events`, setup's to `setup_events`.
  void enqueue(const cl::Buffer& frame_params, const cl::Buffer& setups,
               const cl::Buffer& slot_counts, const cl::Buffer& stats, int input_triangles, bool normals,
               std::vector<cl::Event>& tessellate_events, std::vector<cl::Event>& setup_events);

  // Only tessellates (for the gap metric and the kernel tests), then reads the vertices back.
  std::vector<TessVertex> tessellate();
  // The vertices of the last enqueue or tessellate.
  std::vector<TessVertex> read_vertices();
  // Tessellates and computes the displaced surface's normals (displaced_normals), then reads
  // them back: xyz unit (or 0 where the ring has no area), w = 0, one per vertex.
  std::vector<cl_float4> tessellate_normals();

  // The device's vertices and their normals (what a displaced render's shading reads).
  const cl::Buffer& vertex_buffer() const { return vertices_; }
  const cl::Buffer& normal_buffer() const { return vertex_normals_; }

  size_t device_bytes() const;

 private:
  struct Kernels {
    cl::Kernel tessellate, setup, normals;
  };
  Kernels& kernels();  // built on first use
  void enqueue_tessellate(Kernels& k, std::vector<cl::Event>* events);
  void enqueue_normals(Kernels& k, std::vector<cl::Event>* events);

  ClRuntime& runtime_;
  std::optional<Kernels> kernels_;
  PackedDisplacement packed_;
  bool loaded_ = false;
  cl::Buffer params_, patches_, samples_, positions_, normals_, corner_offsets_, corner_copies_, vertices_,
      vertex_normals_;
};

}  // namespace seamcl
