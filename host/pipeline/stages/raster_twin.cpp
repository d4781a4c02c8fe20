#include "pipeline/stages/raster_twin.h"

#include <limits>

#include "pipeline/stages/sample_pattern.h"
#include "pipeline/stages/triangle_setup_twin.h"

namespace seamcl {

std::vector<uint32_t> raster_reference(const std::vector<TriangleSetup>& setups, const FrameParams& frame) {
  const int samples = frame.sample_count;
  const std::vector<SampleOffset>& pattern = sample_pattern(samples);
  const size_t count = static_cast<size_t>(frame.width) * frame.height * samples;
  std::vector<uint32_t> winner(count, SEAMCL_NO_TRIANGLE);
  std::vector<float> depth(count, -std::numeric_limits<float>::infinity());
  constexpr float to_pixels = 1.0f / SEAMCL_SUBPIXEL_ONE;
  for (size_t slot = 0; slot < setups.size(); ++slot) {
    const TriangleSetup& t = setups[slot];
    if (setup_is_empty(t)) continue;
    for (int y = t.bbox_min_y; y <= t.bbox_max_y; ++y) {
      for (int x = t.bbox_min_x; x <= t.bbox_max_x; ++x) {
        for (int s = 0; s < samples; ++s) {
          const int64_t px = sample_fixed_x(x, pattern[s]);
          const int64_t py = sample_fixed_y(y, pattern[s]);
          if (!setup_covers(t, px, py)) continue;
          const float z = plane_inv_w(t, static_cast<float>(px) * to_pixels, static_cast<float>(py) * to_pixels);
          const size_t i = (static_cast<size_t>(y) * frame.width + x) * samples + s;
          if (z > depth[i] || (z == depth[i] && slot < winner[i])) {
            depth[i] = z;
            winner[i] = static_cast<uint32_t>(slot);
          }
        }
      }
    }
  }
  return winner;
}

}  // namespace seamcl
