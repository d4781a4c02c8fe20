#include "pipeline/displacement_packing.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

constexpr std::array<std::array<float, 2>, 4> kCornerUv{{{0.0f, 0.0f}, {1.0f, 0.0f}, {1.0f, 1.0f}, {0.0f, 1.0f}}};

struct EdgeSide {
  uint32_t face;
  int edge;
};

// Edges by their two vertices (smaller index first), each with the face sides that use it.
std::map<std::pair<uint32_t, uint32_t>, std::vector<EdgeSide>> edge_sides(const Scene& scene) {
  std::map<std::pair<uint32_t, uint32_t>, std::vector<EdgeSide>> out;
  for (uint32_t f = 0; f < scene.faces.size(); ++f) {
    const auto& v = scene.faces[f].vertices;
    for (int e = 0; e < 4; ++e) {
      const uint32_t a = v[e], b = v[(e + 1) % 4];
      out[{std::min(a, b), std::max(a, b)}].push_back({f, e});
    }
  }
  return out;
}

// The lowest-numbered face at each vertex (among those `eligible` says), or -1.
template <typename Eligible>
std::vector<int> lowest_face_at_vertex(const Scene& scene, Eligible eligible) {
  std::vector<int> out(scene.positions.size(), -1);
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    if (!eligible(f)) continue;
    for (uint32_t v : scene.faces[f].vertices) {
      if (out[v] < 0) out[v] = static_cast<int>(f);
    }
  }
  return out;
}

// The first corner of `face` that holds `vertex`; 0 when none does (adjacency.cpp's corner_of
// asks a stricter question: exactly one corner, else -1).
int corner_holding(const Face& face, uint32_t vertex) {
  for (int c = 0; c < 4; ++c) {
    if (face.vertices[c] == vertex) return c;
  }
  return 0;
}

// Samples along edge e of a map, from corner e to corner e+1: their count and the k-th one.
int edge_length(const DisplacementMap& m, int e) { return (e % 2 == 0) ? m.columns : m.rows; }
uint16_t& edge_sample(DisplacementMap& m, int e, int k) {
  switch (e) {
    case 0: return m.at(k, 0);
    case 1: return m.at(m.columns - 1, k);
    case 2: return m.at(m.columns - 1 - k, m.rows - 1);
    default: return m.at(0, m.rows - 1 - k);
  }
}
uint16_t& corner_sample(DisplacementMap& m, int c) { return edge_sample(m, c, 0); }

bool matchable(const DisplacementMap& m) { return m.columns >= 2 && m.rows >= 2; }

uint16_t round_to_multiple(uint16_t value, int multiple) {
  const long rounded = std::lround(static_cast<double>(value) / multiple) * multiple;
  return static_cast<uint16_t>(std::min<long>(rounded, 65535L / multiple * multiple));
}

}  // namespace

size_t match_edge_samples(const Scene& scene, std::vector<DisplacementMap>& maps, size_t* unmatched_edges) {
  size_t changed = 0;
  auto set = [&](uint16_t& sample, uint16_t value) {
    changed += sample != value;
    sample = value;
  };
  // 1. One value per vertex at every face's corner: a multiple of 64, so that any edge ratio up
  //    to 64 interpolates it exactly.
  const std::vector<int> owner = lowest_face_at_vertex(scene, [&](size_t f) { return matchable(maps[f]); });
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    if (!matchable(maps[f])) continue;
    for (int c = 0; c < 4; ++c) {
      const uint32_t v = scene.faces[f].vertices[c];
      const auto o = static_cast<size_t>(owner[v]);
      const uint16_t value = round_to_multiple(corner_sample(maps[o], corner_holding(scene.faces[o], v)), 64);
      set(corner_sample(maps[f], c), value);
    }
  }
  // 2. Across each shared edge, the finer side's samples on the coarser side's lines.
  size_t unmatched = 0;
  for (const auto& [key, sides] : edge_sides(scene)) {
    if (sides.size() != 2) continue;
    EdgeSide a = sides[0], b = sides[1];
    DisplacementMap* ma = &maps[a.face];
    DisplacementMap* mb = &maps[b.face];
    if (ma->empty() && mb->empty()) continue;
    if (!matchable(*ma) || !matchable(*mb)) {
      ++unmatched;
      continue;
    }
    // Coarse side first (fewer samples; on a tie the lower-numbered face).
    const int na = edge_length(*ma, a.edge) - 1, nb = edge_length(*mb, b.edge) - 1;
    if (nb < na || (nb == na && b.face < a.face)) {
      std::swap(a, b);
      std::swap(ma, mb);
    }
    const int coarse = edge_length(*ma, a.edge) - 1, fine = edge_length(*mb, b.edge) - 1;
    const int ratio = fine / coarse;
    if (fine % coarse != 0 || ratio > 64 || (64 % ratio) != 0) {
      ++unmatched;
      continue;
    }
    // Both sides from a's corner a.edge: b runs the other way unless its edge starts there too.
    const bool same_way = scene.faces[b.face].vertices[b.edge] == scene.faces[a.face].vertices[a.edge];
    auto b_at = [&](int k) -> uint16_t& { return edge_sample(*mb, b.edge, same_way ? k : fine - k); };
    for (int k = 1; k < coarse; ++k) set(edge_sample(*ma, a.edge, k), round_to_multiple(edge_sample(*ma, a.edge, k), ratio));
    for (int k = 0; k < coarse; ++k) {
      const long lo = edge_sample(*ma, a.edge, k), hi = edge_sample(*ma, a.edge, k + 1);
      for (int m = (k == 0 ? 1 : 0); m < ratio; ++m) set(b_at(k * ratio + m), static_cast<uint16_t>(lo + (hi - lo) * m / ratio));
    }
  }
  if (unmatched_edges) *unmatched_edges = unmatched;
  return changed;
}

size_t PackedDisplacement::vertex_count() const {
  const auto t = static_cast<size_t>(params.tessellation);
  return patches.size() * (t + 1) * (t + 1);
}

size_t PackedDisplacement::triangle_count() const {
  const auto t = static_cast<size_t>(params.tessellation);
  return patches.size() * 2 * t * t;
}

size_t PackedDisplacement::surface_triangle_count() const {
  if (!adaptive()) return triangle_count();
  const int t = params.tessellation;
  const auto step = [t](int k, int f) { return (2 * k * f + t) / (2 * t); };
  size_t count = 0;
  for (const DisplacementPatch& p : patches) {
    // Every slot's domain point as the kernel makes it, in units of 2^-40: two steps m / f and
    // m' / f' (f, f' <= 64) that differ, differ by at least 2^-12, so floor keeps them apart.
    const auto point = [&](int i, int j) -> std::array<int64_t, 2> {
      const int64_t one = int64_t{1} << 40;
      const bool corner = (i == 0 || i == t) && (j == 0 || j == t);
      if (corner) return {i == 0 ? 0 : one, j == 0 ? 0 : one};
      int e = -1, k = 0;
      if (j == 0) { e = 0; k = i; }
      else if (i == t) { e = 1; k = j; }
      else if (j == t) { e = 2; k = t - i; }
      else if (i == 0) { e = 3; k = t - j; }
      if (e >= 0) {
        const int f = p.edge_factor[e];
        const bool lower_first = p.vertex[e] < p.vertex[(e + 1) % 4];
        const int m = step(lower_first ? k : t - k, f);
        const int64_t at = lower_first ? one * m / f : one - one * m / f;  // from corner e
        switch (e) {
          case 0: return {at, 0};
          case 1: return {one, at};
          case 2: return {one - at, one};
          default: return {0, one - at};
        }
      }
      const int f = p.inner_factor;
      return {one * std::clamp(step(i, f), 1, f - 1) / f, one * std::clamp(step(j, f), 1, f - 1) / f};
    };
    for (int j = 0; j < t; ++j) {
      for (int i = 0; i < t; ++i) {
        const bool flip = t >= 2 && ((i == t - 1 && j == 0) || (i == 0 && j == t - 1));
        const auto a = point(i, j), b = point(i + 1, j), c = point(i + 1, j + 1), d = point(i, j + 1);
        const std::array<std::array<int64_t, 2>, 3> tris[2] = {flip ? std::array{a, b, d} : std::array{a, b, c},
                                                               flip ? std::array{b, c, d} : std::array{a, c, d}};
        for (const auto& tri : tris) count += tri[0] != tri[1] && tri[1] != tri[2] && tri[0] != tri[2];
      }
    }
  }
  return count;
}

size_t PackedDisplacement::method_bytes() const {
  switch (params.method) {
    case SEAMCL_DISPLACEMENT_ZIPPER:
      return patches.size() * (sizeof(DisplacementPatch::neighbor) + sizeof(DisplacementPatch::neighbor_edge) +
                               sizeof(DisplacementPatch::neighbor_same_way) + sizeof(DisplacementPatch::corner_value));
    case SEAMCL_DISPLACEMENT_OWNERSHIP: return patches.size() * sizeof(DisplacementPatch::texcoord);
    case SEAMCL_DISPLACEMENT_PTEX_FILTER:
      return patches.size() * (sizeof(DisplacementPatch::neighbor) + sizeof(DisplacementPatch::neighbor_edge) +
                               sizeof(DisplacementPatch::neighbor_same_way));
    default: return 0;
  }
}

void check_tessellation(size_t patches, int tessellation) {
  if (tessellation < 1 || tessellation > SEAMCL_MAX_TESSELLATION) {
    throw InputError("tessellation", "must be in 1.." + std::to_string(SEAMCL_MAX_TESSELLATION) + ", got " +
                                         std::to_string(tessellation));
  }
  const auto t = static_cast<size_t>(tessellation);
  if (patches * 2 * t * t > kMaxTessellatedTriangles) {
    throw InputError("tessellation", std::to_string(patches) + " patches at T = " + std::to_string(t) + " make " +
                                         std::to_string(patches * 2 * t * t) + " triangles, over the limit of " +
                                         std::to_string(kMaxTessellatedTriangles));
  }
}

PackedDisplacement pack_displacement(const Scene& scene, const DisplacementSettings& settings) {
  check_tessellation(scene.faces.size(), settings.tessellation);
  if (settings.level < 0 || settings.level > 16) {
    throw InputError("displacement_level", "must be in 0..16, got " + std::to_string(settings.level));
  }
  if (!scene.displacement) {
    throw InputError("displacement", "scene '" + scene.name +
                                         "' has no displacement maps (the built-in 'displaced' scene has; an .obj "
                                         "takes them with --displacement-map FILE.ptx)");
  }
  const Displacement& source = *scene.displacement;
  validate_displacement(source, scene.faces.size());

  // Adaptive: the factors checked, the slot grid sized by the largest.
  int slots = settings.tessellation;
  if (!settings.edge_factors.empty()) {
    if (settings.edge_factors.size() != scene.faces.size()) {
      throw InputError("tessellation_factors", "needs one set of 4 edge factors per face (" +
                                                   std::to_string(scene.faces.size()) + "), got " +
                                                   std::to_string(settings.edge_factors.size()));
    }
    std::map<std::pair<uint32_t, uint32_t>, int> by_edge;
    slots = 1;
    for (size_t f = 0; f < scene.faces.size(); ++f) {
      for (int k = 0; k < 4; ++k) {
        const int factor = settings.edge_factors[f][static_cast<size_t>(k)];
        if (factor < 1 || factor > settings.tessellation) {
          throw InputError("tessellation_factors", "face " + std::to_string(f) + " edge " + std::to_string(k) + ": " +
                                                       std::to_string(factor) + " is outside 1.." +
                                                       std::to_string(settings.tessellation));
        }
        const uint32_t a = scene.faces[f].vertices[k], b = scene.faces[f].vertices[(k + 1) % 4];
        const auto [it, inserted] = by_edge.emplace(std::make_pair(std::min(a, b), std::max(a, b)), factor);
        if (!inserted && it->second != factor) {
          throw InputError("tessellation_factors", "face " + std::to_string(f) + " edge " + std::to_string(k) +
                                                       " has factor " + std::to_string(factor) +
                                                       ", its other face " + std::to_string(it->second) +
                                                       ": an edge's factor must be the same on both sides");
        }
        slots = std::max(slots, factor);
      }
    }
    check_tessellation(scene.faces.size(), slots);
  }

  PackedDisplacement out;
  out.params.tessellation = slots;
  out.params.method = displacement_method_code(settings.method);
  out.params.patches = static_cast<cl_int>(scene.faces.size());
  out.params.scale = source.scale;

  std::vector<DisplacementMap> maps;
  maps.reserve(source.maps.size());
  for (const DisplacementMap& m : source.maps) maps.push_back(displacement_level(m, settings.level));
  if (settings.method == DisplacementMethod::Fixed) out.matched_samples = match_edge_samples(scene, maps, &out.unmatched_edges);

  for (const glm::vec3& p : scene.positions) out.positions.push_back({{p.x, p.y, p.z, 1.0f}});
  // Vertex normals: the mean of the faces' normals around each vertex, in face order.
  std::vector<glm::vec3> normal_sum(scene.positions.size(), glm::vec3(0.0f));
  for (const Face& face : scene.faces) {
    const glm::vec3 n = scene.face_normal(face);
    for (uint32_t v : face.vertices) normal_sum[v] += n;
  }
  for (const glm::vec3& s : normal_sum) {
    const float length = glm::length(s);
    const glm::vec3 n = length > 0.0f && std::isfinite(length) ? s / length : glm::vec3(0.0f, 0.0f, 1.0f);
    out.normals.push_back({{n.x, n.y, n.z, 0.0f}});
  }

  const auto sides = edge_sides(scene);
  const std::vector<int> lowest = lowest_face_at_vertex(scene, [](size_t) { return true; });
  const std::vector<int> lowest_mapped = lowest_face_at_vertex(scene, [&](size_t f) { return !maps[f].empty(); });
  out.patches.resize(scene.faces.size());
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const Face& face = scene.faces[f];
    DisplacementPatch& p = out.patches[f];
    p.map_offset = static_cast<cl_uint>(out.samples.size());
    p.columns = maps[f].columns;
    p.rows = maps[f].rows;
    out.samples.insert(out.samples.end(), maps[f].samples.begin(), maps[f].samples.end());
    p.inner_factor = 0;
    for (int k = 0; k < 4; ++k) p.edge_factor[k] = slots;
    if (!settings.edge_factors.empty()) {
      int inner = 1;
      for (int k = 0; k < 4; ++k) {
        p.edge_factor[k] = settings.edge_factors[f][static_cast<size_t>(k)];
        inner = std::max(inner, p.edge_factor[k]);
      }
      // With interior slots (N >= 2) the inner grid needs a point strictly inside.
      p.inner_factor = slots >= 2 ? std::max(inner, 2) : 1;
    }
    for (int k = 0; k < 4; ++k) {
      p.vertex[k] = face.vertices[k];
      p.neighbor[k] = -1;
      p.neighbor_edge[k] = 0;
      p.neighbor_same_way[k] = 0;
      const uint32_t a = face.vertices[k], b = face.vertices[(k + 1) % 4];
      const auto& edge = sides.at({std::min(a, b), std::max(a, b)});
      if (edge.size() == 2) {
        const EdgeSide other = edge[0].face == f && edge[0].edge == k ? edge[1] : edge[0];
        p.neighbor[k] = static_cast<cl_int>(other.face);
        p.neighbor_edge[k] = other.edge;
        p.neighbor_same_way[k] = scene.faces[other.face].vertices[other.edge] == a ? 1 : 0;
      }
    }
    for (int k = 0; k < 4; ++k) {
      const uint32_t v = face.vertices[k];
      // Zipper: the corner's one value, the corner sample of the lowest-numbered mapped face there.
      const int z = lowest_mapped[v];
      p.corner_value[k] = z < 0 ? 0.0f
                                : static_cast<float>(corner_sample(maps[static_cast<size_t>(z)],
                                                                   corner_holding(scene.faces[static_cast<size_t>(z)], v))) /
                                      65535.0f;
      // Ownership: this corner's uv in its own face, in the owners of its two edges, in the
      // corner's owner (the lowest-numbered face of each).
      auto texcoord = [&](int owner) {
        const auto o = static_cast<size_t>(owner);
        const int c = corner_holding(scene.faces[o], v);
        return DisplacementTexcoord{owner, kCornerUv[c][0], kCornerUv[c][1]};
      };
      const int edge_before = (k + 3) % 4;
      const int own = static_cast<int>(f);
      p.texcoord[k][0] = texcoord(own);
      p.texcoord[k][1] = texcoord(p.neighbor[k] < 0 ? own : std::min(own, p.neighbor[k]));
      p.texcoord[k][2] = texcoord(p.neighbor[edge_before] < 0 ? own : std::min(own, p.neighbor[edge_before]));
      p.texcoord[k][3] = texcoord(lowest[v]);
    }
  }
  // Patch corners by mesh vertex: faces in order, and within a face its corners in slot order
  // (j, then i): corner 0 (0, 0), 1 (T, 0), 3 (0, T), 2 (T, T).
  out.corner_offsets.assign(scene.positions.size() + 1, 0);
  for (const Face& face : scene.faces)
    for (uint32_t v : face.vertices) ++out.corner_offsets[v + 1];
  for (size_t v = 0; v < scene.positions.size(); ++v) out.corner_offsets[v + 1] += out.corner_offsets[v];
  out.corner_copies.resize(out.corner_offsets.back());
  std::vector<cl_uint> filled(out.corner_offsets.begin(), out.corner_offsets.end() - 1);
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int c : {0, 1, 3, 2}) {
      const uint32_t v = scene.faces[f].vertices[static_cast<size_t>(c)];
      out.corner_copies[filled[v]++] = static_cast<cl_uint>(f * 4 + static_cast<size_t>(c));
    }
  }
  return out;
}

}  // namespace seamcl
