// Batches of cube-map lookups on the device (kernel cube_lookup_batch): the cube sampler on its
// own, for its tests and the seam measurements.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/packed_cube.h>

namespace seamcl {

struct CubeLookup {
  glm::vec3 direction{0, 0, 1};  // any length
  glm::vec3 ddx{0.0f}, ddy{0.0f};  // d(direction)/d(pixel)
  float roughness = 0.0f;
  float explicit_lod = -1.0f;    // >= 0: one trilinear lookup at this lod
};

class CubeLookups {
 public:
  // Uploads the cube's texels once; `border`: in cube-border's layout (for that method only).
  CubeLookups(ClRuntime& runtime, const CubeMap& cube, bool border = false);

  // What sample_cube returns for each lookup; `kernel_ms` gets the kernel's time. sampler.size
  // must be the cube's.
  std::vector<glm::vec4> sample(const std::vector<CubeLookup>& lookups, const CubeSampler& sampler,
                                double* kernel_ms = nullptr);

 private:
  ClRuntime& runtime_;
  int size_;
  cl::Kernel kernel_;
  cl::Buffer texels_;
};

}  // namespace seamcl
