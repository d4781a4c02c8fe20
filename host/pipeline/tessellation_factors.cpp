#include "pipeline/tessellation_factors.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <seamcl/core/input_error.h>
#include "pipeline/frame_params.h"

namespace seamcl {

std::vector<std::array<int, 4>> screen_space_edge_factors(const Scene& scene, const glm::mat4& view_proj, int width,
                                                          int height, float pixels_per_segment, int max_factor) {
  if (!(pixels_per_segment > 0.0f) || !std::isfinite(pixels_per_segment)) {
    throw InputError("tessellation_pixels", "must be a positive number");
  }
  std::vector<std::array<int, 4>> out(scene.faces.size());
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      // The ends in index order: the same arithmetic from either face.
      uint32_t a = scene.faces[f].vertices[k], b = scene.faces[f].vertices[(k + 1) % 4];
      if (b < a) std::swap(a, b);
      const glm::vec4 ca = view_proj * glm::vec4(scene.positions[a], 1.0f);
      const glm::vec4 cb = view_proj * glm::vec4(scene.positions[b], 1.0f);
      int factor = max_factor;
      if (ca.w > kNearPlane && cb.w > kNearPlane) {
        const float dx = (ca.x / ca.w - cb.x / cb.w) * 0.5f * static_cast<float>(width);
        const float dy = (ca.y / ca.w - cb.y / cb.w) * 0.5f * static_cast<float>(height);
        const float segments = std::ceil(std::sqrt(dx * dx + dy * dy) / pixels_per_segment);
        factor = std::isfinite(segments) ? static_cast<int>(std::clamp(segments, 1.0f, static_cast<float>(max_factor)))
                                         : max_factor;
      }
      out[f][static_cast<size_t>(k)] = factor;
    }
  }
  return out;
}

DisplacementSettings displacement_settings(const Scene& scene, const RenderOptions& options, const Camera& camera) {
  if (!options.displacement) throw InputError("displacement_method", "is needed to tessellate a displaced surface");
  DisplacementSettings settings{*options.displacement, options.tessellation, options.displacement_level, {}};
  if (options.tessellation_pixels) {
    check_tessellation(scene.faces.size(), options.tessellation);
    settings.edge_factors =
        screen_space_edge_factors(scene, view_projection(camera, options.width, options.height), options.width,
                                  options.height, *options.tessellation_pixels, options.tessellation);
  }
  return settings;
}

}  // namespace seamcl
