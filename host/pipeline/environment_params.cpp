#include "pipeline/environment_params.h"

#include <cmath>

#include <seamcl/pipeline/packed_cube.h>

namespace seamcl {

EnvironmentParams environment_params(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  EnvironmentParams e{};
  if (!scene.environment) return e;
  e.sampler = cube_sampler(options.cube_method, options.filter, options.aniso, scene.environment->cube_size);
  e.skybox = scene.environment->skybox ? 1 : 0;
  // The pinhole camera of view_projection (glm::lookAt and glm::perspective): the ray through
  // NDC (nx, ny) is forward + right nx tan(fov/2) aspect + up ny tan(fov/2), and pixel (x, y)
  // is at nx = 2x/W - 1, ny = 1 - 2y/H (y down).
  const glm::vec3 forward = glm::normalize(camera.target - camera.eye);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tan_half = std::tan(glm::radians(camera.fov_y_degrees) * 0.5f);
  const float aspect = static_cast<float>(options.width) / static_cast<float>(options.height);
  const glm::vec3 corner = forward - right * (tan_half * aspect) + up * tan_half;
  const glm::vec3 dx = right * (2.0f * tan_half * aspect / static_cast<float>(options.width));
  const glm::vec3 dy = up * (-2.0f * tan_half / static_cast<float>(options.height));
  for (int c = 0; c < 3; ++c) {
    e.eye[c] = camera.eye[c];
    e.ray_corner[c] = corner[c];
    e.ray_dx[c] = dx[c];
    e.ray_dy[c] = dy[c];
  }
  return e;
}

}  // namespace seamcl
