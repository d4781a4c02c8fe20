#include "pipeline/guard_band.h"

#include <algorithm>
#include <cmath>

#include "pipeline/adjacency.h"

namespace seamcl {
namespace {

// Bilinear with clamp on one level, in linear float.
glm::vec4 bilinear_clamp(const TextureLevel& level, glm::vec2 uv) {
  const float x = uv.x * static_cast<float>(level.width) - 0.5f;
  const float y = uv.y * static_cast<float>(level.height) - 0.5f;
  const float x0 = std::floor(x), y0 = std::floor(y);
  const float fx = x - x0, fy = y - y0;
  auto at = [&](float i, float j) {
    return level.at(std::clamp(static_cast<int>(i), 0, level.width - 1), std::clamp(static_cast<int>(j), 0, level.height - 1));
  };
  return (at(x0, y0) * (1 - fx) + at(x0 + 1, y0) * fx) * (1 - fy) + (at(x0, y0 + 1) * (1 - fx) + at(x0 + 1, y0 + 1) * fx) * fy;
}

// The edge of the unit square that uv has left furthest past, or -1 when inside.
int edge_crossed(glm::vec2 uv) {
  const float past[4] = {-uv.y, uv.x - 1.0f, uv.y - 1.0f, -uv.x};  // edges v=0, u=1, v=1, u=0
  int edge = -1;
  float most = 0.0f;
  for (int k = 0; k < 4; ++k) {
    if (past[k] > most) {
      most = past[k];
      edge = k;
    }
  }
  return edge;
}

}  // namespace

TextureLevel guard_banded_level(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face,
                                int level, int band) {
  const TextureLevel& own = scene.faces[face].texture.levels.at(static_cast<size_t>(level));
  TextureLevel out{own.width + 2 * band, own.height + 2 * band, {}};
  out.texels.reserve(static_cast<size_t>(out.width) * static_cast<size_t>(out.height));
  for (int sj = 0; sj < out.height; ++sj) {
    for (int si = 0; si < out.width; ++si) {
      const int i = si - band, j = sj - band;
      if (i >= 0 && i < own.width && j >= 0 && j < own.height) {
        out.texels.push_back(own.at(i, j));
        continue;
      }
      // Walk across at most two edges (a corner texel crosses two), then sample what we reached.
      uint32_t current = face;
      glm::vec2 uv((static_cast<float>(i) + 0.5f) / static_cast<float>(own.width),
                   (static_cast<float>(j) + 0.5f) / static_cast<float>(own.height));
      for (int step = 0; step < 2; ++step) {
        const int edge = edge_crossed(uv);
        if (edge < 0) break;
        const int next = adjacency[current].neighbor[edge];
        if (next < 0) break;
        uv = transform_uv(adjacency[current], edge, uv);
        current = static_cast<uint32_t>(next);
      }
      const auto& levels = scene.faces[current].texture.levels;
      const TextureLevel& source = levels[std::min(static_cast<size_t>(level), levels.size() - 1)];
      out.texels.push_back(bilinear_clamp(source, uv));
    }
  }
  return out;
}

}  // namespace seamcl
