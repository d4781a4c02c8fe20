#include "pipeline/guard_band.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
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
glm::vec4 filtered(const Scene& scene, const BandTexels& texels, uint32_t source, const UvRect& rect) {
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
      sum += glm::dvec4(texels.at(source, chosen, i, j)) * (weight_u * weight_v);
      total += weight_u * weight_v;
    }
  }
  assert(total > 0.0);
  return glm::vec4(sum / total);
}

// The scene's own chains.
class StoredChains final : public BandTexels {
 public:
  explicit StoredChains(const Scene& scene) : scene_(scene) {}
  const glm::vec4& at(uint32_t face, size_t level, int i, int j) const override {
    return scene_.faces[face].texture.levels[level].at(i, j);
  }

 private:
  const Scene& scene_;
};

// Reads nothing: notes how deep into each level of each face a band reads (band_read_depths).
class ReadDepths final : public BandTexels {
 public:
  explicit ReadDepths(const Scene& scene) : scene_(scene) {}
  const glm::vec4& at(uint32_t face, size_t level, int i, int j) const override {
    const TextureLevel& sizes = scene_.faces[face].texture.levels[level];
    const int from_edge = std::min(std::min(i, sizes.width - 1 - i), std::min(j, sizes.height - 1 - j));
    int& depth = depths_[{face, level}];
    depth = std::max(depth, from_edge + 1);
    return nothing_;
  }
  const std::map<std::pair<uint32_t, size_t>, int>& depths() const { return depths_; }

 private:
  const Scene& scene_;
  mutable std::map<std::pair<uint32_t, size_t>, int> depths_;
  const glm::vec4 nothing_{0.0f};
};

// The two edges at corner k: k-1 (before it) and k.
int edge_before(int corner) { return (corner + 3) % 4; }

}  // namespace

void for_each_band_texel(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face, int level,
                         int band, const BandTexels& texels,
                         const std::function<void(int si, int sj, const glm::vec4& texel)>& emit) {
  const TextureLevel& own = scene.faces[face].texture.levels.at(static_cast<size_t>(level));
  std::array<VertexRing, 4> rings;
  for (int k = 0; k < 4; ++k) rings[k] = corner_ring(scene, adjacency, face, k);

  // Past edge e: the neighbour across it, or, at a boundary, this face (its edge texels repeat).
  auto across_edge = [&](int e, const UvRect& rect) {
    const int other = adjacency[face].neighbor[e];
    if (other < 0) return filtered(scene, texels, face, rect);
    return filtered(scene, texels, static_cast<uint32_t>(other), mapped(uv_map(adjacency[face].edge_map[e]), rect));
  };
  // Past corner k (both of its edges continued).
  auto past_corner = [&](int k, const UvRect& rect) {
    const VertexRing& ring = rings[k];
    if (ring.valence() == 4) {
      return filtered(scene, texels, ring.faces[1].face, mapped(uv_map(adjacency[face].corner_map[k]), rect));
    }
    glm::vec4 sum(0.0f);
    float count = 0.0f;
    if (ring.valence() >= 5) {
      // The faces that share only the vertex, each in both orientations: no one of them is the
      // continuation, so all share the corner alike.
      for (int i = 1; i + 2 < ring.valence(); ++i) {
        for (bool swap : {false, true}) {
          const RingFace& corner_face = ring.faces[static_cast<size_t>(i)];
          sum += filtered(scene, texels, corner_face.face, mapped(corner_map(k, corner_face.corner, swap), rect));
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

  const int width = own.width + 2 * band, height = own.height + 2 * band;
  for (int sj = 0; sj < height; ++sj) {
    const int j = sj - band;
    const bool in_v = j >= 0 && j < own.height;
    for (int si = 0; si < width; ++si) {
      const int i = si - band;
      const bool in_u = i >= 0 && i < own.width;
      if (in_u && in_v) {
        si = band + own.width - 1;  // the face's own texels: not the band's
        continue;
      }
      const UvRect rect{static_cast<double>(i) / own.width, static_cast<double>(i + 1) / own.width,
                        static_cast<double>(j) / own.height, static_cast<double>(j + 1) / own.height};
      // Edges 0..3: v = 0, u = 1, v = 1, u = 0; corner k between edges k-1 and k.
      const int edge_u = i < 0 ? 3 : 1, edge_v = j < 0 ? 0 : 2;
      if (in_u) {
        emit(si, sj, across_edge(edge_v, rect));
      } else if (in_v) {
        emit(si, sj, across_edge(edge_u, rect));
      } else {
        const int corner = i < 0 ? (j < 0 ? 0 : 3) : (j < 0 ? 1 : 2);
        emit(si, sj, past_corner(corner, rect));
      }
    }
  }
}

TextureLevel guard_banded_level(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face,
                                int level, int band) {
  const TextureLevel& own = scene.faces[face].texture.levels.at(static_cast<size_t>(level));
  TextureLevel out{own.width + 2 * band, own.height + 2 * band, {}};
  out.texels.resize(static_cast<size_t>(out.width) * static_cast<size_t>(out.height));
  for (int j = 0; j < own.height; ++j)
    for (int i = 0; i < own.width; ++i) out.texels[static_cast<size_t>(j + band) * out.width + (i + band)] = own.at(i, j);
  for_each_band_texel(scene, adjacency, face, level, band, StoredChains(scene),
                      [&](int si, int sj, const glm::vec4& texel) { out.texels[static_cast<size_t>(sj) * out.width + si] = texel; });
  return out;
}

std::vector<std::vector<int>> band_read_depths(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, int band) {
  std::vector<std::vector<int>> depths(scene.faces.size());
  for (size_t f = 0; f < scene.faces.size(); ++f) depths[f].assign(scene.faces[f].texture.levels.size(), 0);
  std::mutex merging;
  for_each_face_in_parallel(scene.faces.size(), [&](size_t f) {
    const ReadDepths reads(scene);
    for (size_t l = 0; l < scene.faces[f].texture.levels.size(); ++l)
      for_each_band_texel(scene, adjacency, static_cast<uint32_t>(f), static_cast<int>(l), band, reads,
                          [](int, int, const glm::vec4&) {});
    const std::lock_guard<std::mutex> lock(merging);
    for (const auto& [at, depth] : reads.depths()) depths[at.first][at.second] = std::max(depths[at.first][at.second], depth);
  });
  return depths;
}

EdgeStrips::EdgeStrips(const MipChain& chain, const std::vector<int>& depths) {
  if (depths.size() != chain.levels.size()) throw std::logic_error("EdgeStrips: a depth per level is needed");
  size_t count = 0;
  for (size_t l = 0; l < chain.levels.size(); ++l) {
    Strips s{chain.levels[l].width, chain.levels[l].height, std::max(0, depths[l]), count};
    const size_t w = static_cast<size_t>(s.width), h = static_cast<size_t>(s.height), d = static_cast<size_t>(s.depth);
    count += s.whole() ? w * h : 2 * d * w + (h - 2 * d) * 2 * d;
    levels_.push_back(s);
  }
  texels_.reserve(count);
  for (size_t l = 0; l < chain.levels.size(); ++l) {
    const Strips& s = levels_[l];
    const TextureLevel& level = chain.levels[l];
    // Rows along v = 0 and v = 1 whole, the rows between only at their two ends; at() reads them
    // back in this order.
    for (int j = 0; j < s.height; ++j) {
      const bool whole_row = s.whole() || j < s.depth || j >= s.height - s.depth;
      for (int i = 0; i < s.width; ++i)
        if (whole_row || i < s.depth || i >= s.width - s.depth) texels_.push_back(level.at(i, j));
    }
  }
  if (texels_.size() != count) throw std::logic_error("EdgeStrips: strips miscounted");
}

const glm::vec4& EdgeStrips::at(size_t level, int i, int j) const {
  const Strips& s = levels_.at(level);
  if (i < 0 || i >= s.width || j < 0 || j >= s.height) throw std::logic_error("EdgeStrips: texel outside its level");
  const size_t w = static_cast<size_t>(s.width), d = static_cast<size_t>(s.depth);
  const size_t si = static_cast<size_t>(i), sj = static_cast<size_t>(j);
  if (s.whole()) return texels_[s.first + sj * w + si];
  if (j < s.depth) return texels_[s.first + sj * w + si];
  const size_t middle_rows = static_cast<size_t>(s.height) - 2 * d;
  if (j >= s.height - s.depth) return texels_[s.first + d * w + middle_rows * 2 * d + (sj - d - middle_rows) * w + si];
  if (i >= s.depth && i < s.width - s.depth) {
    throw std::logic_error("EdgeStrips: texel (" + std::to_string(i) + ", " + std::to_string(j) + ") of level " +
                           std::to_string(level) + " lies inside the strips");
  }
  const size_t in_row = i < s.depth ? si : d + (si - (w - d));
  return texels_[s.first + d * w + (sj - d) * 2 * d + in_row];
}

}  // namespace seamcl
