#include "pipeline/frame_params.h"

#include "pipeline/environment_params.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

namespace seamcl {

BinChunks bin_chunks(size_t input_triangles, size_t tiles) {
  if (input_triangles == 0) return {};
  size_t chunks = std::min((input_triangles + kBinChunkTriangles - 1) / kBinChunkTriangles, kMaxBinChunks);
  chunks = std::max<size_t>(std::min(chunks, kMaxBinCounters / std::max<size_t>(tiles, 1)), 1);
  return {chunks, (input_triangles + chunks - 1) / chunks};
}

glm::mat4 view_projection(const Camera& camera, int width, int height) {
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  // The far plane does not clip (depth is 1/w); it only has to be finite.
  const glm::mat4 projection = glm::perspective(glm::radians(camera.fov_y_degrees), aspect, kNearPlane, 1000.0f);
  return projection * glm::lookAt(camera.eye, camera.target, camera.up);
}

FrameParams make_frame_params(const Scene& scene, const Camera& camera, const RenderOptions& options,
                              uint32_t bin_capacity) {
  FrameParams p{};
  const glm::mat4 vp = view_projection(camera, options.width, options.height);
  const float* m = glm::value_ptr(vp);
  for (int i = 0; i < 16; ++i) p.view_proj[i] = m[i];
  p.environment = environment_params(scene, camera, options);
  p.width = options.width;
  p.height = options.height;
  p.tiles_x = (options.width + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE;
  p.tiles_y = (options.height + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE;
  p.sample_count = options.msaa;
  p.shading_mode = options.shading == ShadingMode::Pixel      ? SEAMCL_SHADE_PIXEL
                   : options.shading == ShadingMode::Centroid ? SEAMCL_SHADE_CENTROID
                                                              : SEAMCL_SHADE_SAMPLE;
  p.input_triangles = static_cast<cl_int>(scene.triangle_count());
  p.bin_capacity = bin_capacity;
  p.near_w = kNearPlane;
  p.guard_x = kGuardBand;
  p.guard_y = kGuardBand;
  const glm::vec3 l = glm::normalize(scene.light.to_light);
  for (int i = 0; i < 3; ++i) {
    p.light_dir[i] = l[i];
    p.light_color[i] = scene.light.color[i];
    p.background[i] = scene.background[i];
  }
  p.ambient = scene.light.ambient;
  p.sampler = sampler_params(options);
  return p;
}

}  // namespace seamcl
