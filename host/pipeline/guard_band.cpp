#include "pipeline/guard_band.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <utility>

#include "pipeline/adjacency.h"

namespace seamcl {
namespace {

// A band texel's square in some face's uv: [u0, u1] x [v0, v1].
struct UvRect {
  double u0, u1, v0, v1;
};

UvRect mapped(const UvMap& map, const UvRect& r) {
  // The maps permute and negate the axes: the image of a rectangle is the box of two corners.
  const glm::vec2 a = map.point({static_cast<float>(r.u0), static_cast<float>(r.v0)});
  const glm::vec2 b = map.point({static_cast<float>(r.u1), static_cast<float>(r.v1)});
  return {std::min(a.x, b.x), std::max(a.x, b.x), std::min(a.y, b.y), std::max(a.y, b.y)};
}

// Texels of one axis of n and their weights for the band texel's interval [lo, hi]: a box over
// the texels it overlaps when they are no longer than it, else (a coarser neighbour) linear
// interpolation at its centre. Both stay on the face: an interval past its end takes the end texel.
void axis_weights(double lo, double hi, int n, std::vector<std::pair<int, double>>& out) {
  out.clear();
  const double texel = 1.0 / n;
  if (texel <= hi - lo) {
    const double a = std::clamp(lo, 0.0, 1.0), b = std::clamp(hi, 0.0, 1.0);
    if (!(b > a)) {
      out.emplace_back(lo >= 1.0 ? n - 1 : 0, 1.0);
      return;
    }
    for (int i = static_cast<int>(std::floor(a * n)); i < n && i * texel < b; ++i) {
      const double overlap = std::min(b, (i + 1) * texel) - std::max(a, i * texel);
      if (overlap > 0.0) out.emplace_back(i, overlap);
    }
    return;
  }
  const double x = std::clamp(0.5 * (lo + hi) * n - 0.5, 0.0, static_cast<double>(n - 1));
  const int i = static_cast<int>(std::floor(x));
  const double t = x - i;
  out.emplace_back(i, 1.0 - t);
  if (t > 0.0) out.emplace_back(std::min(i + 1, n - 1), t);
}

// What face `source` holds over `rect` (its uv): the level whose texels are as long as the
// rectangle's sides (the coarsest no longer on either axis; mip levels are box filters of the
// finer ones, so this is a box filter of level 0), box-filtered over the rectangle. A neighbour
// coarser even at level 0 is interpolated instead; never a point sample of a finer level.
glm::vec4 filtered(const Scene& scene, uint32_t source, const UvRect& rect) {
  const std::vector<TextureLevel>& levels = scene.faces[source].texture.levels;
  size_t chosen = 0;
  for (size_t l = levels.size(); l-- > 0;) {
    if (1.0 / levels[l].width <= rect.u1 - rect.u0 && 1.0 / levels[l].height <= rect.v1 - rect.v0) {
      chosen = l;
      break;
    }
  }
  const TextureLevel& level = levels[chosen];
  // Reused between calls: a scene's bands call this millions of times.
  thread_local std::vector<std::pair<int, double>> wu, wv;
  axis_weights(rect.u0, rect.u1, level.width, wu);
  axis_weights(rect.v0, rect.v1, level.height, wv);
  // In double and normalised: a constant texture gives its constant back to the last bit.
  glm::dvec4 sum(0.0);
  double total = 0.0;
  for (const auto& [j, weight_v] : wv) {
    for (const auto& [i, weight_u] : wu) {
      sum += glm::dvec4(level.at(i, j)) * (weight_u * weight_v);
      total += weight_u * weight_v;
    }
  }
  assert(total > 0.0);
  return glm::vec4(sum / total);
}

// The two edges at corner k: k-1 (before it) and k.
int edge_before(int corner) { return (corner + 3) % 4; }

}  // namespace

TextureLevel guard_banded_level(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face,
                                int level, int band) {
  const TextureLevel& own = scene.faces[face].texture.levels.at(static_cast<size_t>(level));
  std::array<VertexRing, 4> rings;
  for (int k = 0; k < 4; ++k) rings[k] = corner_ring(scene, adjacency, face, k);

  // Past edge e: the neighbour across it, or, at a boundary, this face (its edge texels repeat).
  auto across_edge = [&](int e, const UvRect& rect) {
    const int other = adjacency[face].neighbor[e];
    if (other < 0) return filtered(scene, face, rect);
    return filtered(scene, static_cast<uint32_t>(other), mapped(uv_map(adjacency[face].transform[e]), rect));
  };
  // Past corner k (both of its edges continued).
  auto past_corner = [&](int k, const UvRect& rect) {
    const VertexRing& ring = rings[k];
    if (ring.valence() == 4) {
      return filtered(scene, ring.faces[1].face, mapped(uv_map(adjacency[face].corner_transform[k]), rect));
    }
    glm::vec4 sum(0.0f);
    float count = 0.0f;
    if (ring.valence() >= 5) {
      // The faces that share only the vertex, each in both orientations: no one of them is the
      // continuation, so all share the corner alike.
      for (int i = 1; i + 2 < ring.valence(); ++i) {
        for (bool swap : {false, true}) {
          const RingFace& corner_face = ring.faces[static_cast<size_t>(i)];
          sum += filtered(scene, corner_face.face, mapped(corner_map(k, corner_face.corner, swap), rect));
          count += 1.0f;
        }
      }
    } else {
      // Valence 3 (nothing lies past the corner), a boundary vertex or an open ring: the mean of
      // the two edges' continuations, each clamped to the face across it (or to this one).
      sum = across_edge(edge_before(k), rect) + across_edge(k, rect);
      count = 2.0f;
    }
    return sum / count;
  };

  TextureLevel out{own.width + 2 * band, own.height + 2 * band, {}};
  out.texels.reserve(static_cast<size_t>(out.width) * static_cast<size_t>(out.height));
  for (int sj = 0; sj < out.height; ++sj) {
    for (int si = 0; si < out.width; ++si) {
      const int i = si - band, j = sj - band;
      const bool in_u = i >= 0 && i < own.width, in_v = j >= 0 && j < own.height;
      if (in_u && in_v) {
        out.texels.push_back(own.at(i, j));
        continue;
      }
      const UvRect rect{static_cast<double>(i) / own.width, static_cast<double>(i + 1) / own.width,
                        static_cast<double>(j) / own.height, static_cast<double>(j + 1) / own.height};
      // Edges 0..3: v = 0, u = 1, v = 1, u = 0; corner k between edges k-1 and k.
      const int edge_u = i < 0 ? 3 : 1, edge_v = j < 0 ? 0 : 2;
      if (in_u) {
        out.texels.push_back(across_edge(edge_v, rect));
      } else if (in_v) {
        out.texels.push_back(across_edge(edge_u, rect));
      } else {
        const int corner = i < 0 ? (j < 0 ? 0 : 3) : (j < 0 ? 1 : 2);
        out.texels.push_back(past_corner(corner, rect));
      }
    }
  }
  return out;
}

}  // namespace seamcl
