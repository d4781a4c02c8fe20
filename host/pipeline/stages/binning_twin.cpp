#include "pipeline/stages/binning_twin.h"

#include "pipeline/stages/triangle_setup_twin.h"

namespace seamcl {

bool tile_may_be_covered(const TriangleSetup& s, int tile_x, int tile_y) {
  constexpr int64_t tile_span = int64_t{SEAMCL_TILE_SIZE} * SEAMCL_SUBPIXEL_ONE;
  const int64_t x_lo = tile_x * tile_span, y_lo = tile_y * tile_span;
  const int64_t x_hi = x_lo + tile_span - 16, y_hi = y_lo + tile_span - 16;  // last sample position
  for (int i = 0; i < 3; ++i) {
    const int64_t a = s.edge_a[i], b = s.edge_b[i];
    if (a * (a > 0 ? x_hi : x_lo) + b * (b > 0 ? y_hi : y_lo) + s.edge_c[i] < 0) return false;
  }
  return true;
}

std::vector<std::vector<uint32_t>> bin_triangles_reference(const std::vector<TriangleSetup>& setups,
                                                           const FrameParams& frame) {
  std::vector<std::vector<uint32_t>> tiles(static_cast<size_t>(frame.tiles_x) * frame.tiles_y);
  for (size_t slot = 0; slot < setups.size(); ++slot) {
    const TriangleSetup& s = setups[slot];
    if (setup_is_empty(s)) continue;
    for (int ty = s.bbox_min_y / SEAMCL_TILE_SIZE; ty <= s.bbox_max_y / SEAMCL_TILE_SIZE; ++ty) {
      for (int tx = s.bbox_min_x / SEAMCL_TILE_SIZE; tx <= s.bbox_max_x / SEAMCL_TILE_SIZE; ++tx) {
        if (tile_may_be_covered(s, tx, ty)) tiles[static_cast<size_t>(ty) * frame.tiles_x + tx].push_back(static_cast<uint32_t>(slot));
      }
    }
  }
  return tiles;
}

}  // namespace seamcl
