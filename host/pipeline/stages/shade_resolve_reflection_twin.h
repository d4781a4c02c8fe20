// Scalar twin of the environment branch of kernels/shade_resolve.cl: a reflective face's
// fragment (the reflected view ray and its derivatives, looked up in the cube map) and the skybox.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/gpu_types.h>
#include "pipeline/stages/shade_resolve_twin.h"

namespace seamcl {

// The reflected direction of a reflective face at uv and its screen derivatives.
struct ReflectedRay {
  glm::vec3 direction, ddx, ddy;
};
ReflectedRay reflected_ray(const FrameParams& frame, const ReflectiveFace& face, const SurfaceUv& s);

// The environment along d (or, for SEAMCL_CUBE_DIRECTION, d normalised times 1 + roughness).
glm::vec3 environment_lookup_reference(const FrameParams& frame, const std::vector<float>& cube_texels, glm::vec3 d,
                                       glm::vec3 ddx, glm::vec3 ddy, float roughness);
glm::vec3 shade_reflection_reference(const FrameParams& frame, const ReflectiveFace& face,
                                     const std::vector<float>& cube_texels, const SurfaceUv& s);
// The skybox at pixel-space point (x, y).
glm::vec3 shade_sky_reference(const FrameParams& frame, const std::vector<float>& cube_texels, float x, float y);

}  // namespace seamcl
