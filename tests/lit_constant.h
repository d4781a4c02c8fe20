// Whole renders of scenes whose faces all hold one constant colour: every covered pixel must be
// that colour times the face's lighting, mixed by coverage. Shared by the method and asset tests.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/renderer.h>

namespace seamcl_tests {

struct SeamCheck {
  size_t checked = 0;  // pixels with at least one covered sample
  size_t off = 0;      // of those, pixels that differ from the lit constant by more than 1e-5
  size_t brighter = 0; // of those, pixels brighter than it by more than 1e-5 in some channel
  float worst = 0;     // largest difference, linear RGB
};

// Compares every covered pixel with the lit constant mixed by coverage (sample winners give
// each sample's face; uncovered samples count the background).
inline SeamCheck compare_with_lit_constant(seamcl::Renderer& renderer, const seamcl::RenderResult& result, glm::vec3 stored_color) {
  const seamcl::Scene& scene = renderer.scene();
  const FrameParams frame = renderer.last_frame_params();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const int samples = frame.sample_count;
  SeamCheck check;
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const size_t pixel = static_cast<size_t>(y) * frame.width + x;
      glm::vec3 expected(0.0f);
      bool covered = false;
      for (int s = 0; s < samples; ++s) {
        const uint32_t slot = winners[pixel * samples + s];
        if (slot == SEAMCL_NO_TRIANGLE) {
          expected += scene.background;
          continue;
        }
        covered = true;
        const glm::vec3 n = scene.face_normal(scene.faces[setups[slot].face]);
        const float n_dot_l = glm::dot(n, glm::normalize(scene.light.to_light));
        expected += stored_color * scene.light.color * (scene.light.ambient + (1 - scene.light.ambient) * std::max(n_dot_l, 0.0f));
      }
      if (!covered) continue;
      expected /= static_cast<float>(samples);
      ++check.checked;
      const glm::vec3 got(result.pixels[pixel]);
      const float difference = glm::length(got - expected);
      check.worst = std::max(check.worst, std::isnan(difference) ? INFINITY : difference);
      check.off += !(difference <= 1e-5f);
      check.brighter += glm::any(glm::greaterThan(got, expected + glm::vec3(1e-5f)));
    }
  }
  return check;
}

}  // namespace seamcl_tests
