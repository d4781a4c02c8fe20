#include "pipeline/adjacency.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace seamcl {
namespace {

// Corner k of the unit uv square, in the order the quad's vertices carry them.
glm::vec2 corner_uv(int k) {
  constexpr float u[4] = {0, 1, 1, 0};
  constexpr float v[4] = {0, 0, 1, 1};
  return {u[k & 3], v[k & 3]};
}

// Inward unit normal of edge k in uv: the direction from the edge into the square.
glm::vec2 inward_normal(int k) {
  const glm::vec2 edge = corner_uv(k + 1) - corner_uv(k);
  return {-edge.y, edge.x};  // counter-clockwise corners: the left of each edge is inside
}

// A face's edge by its undirected vertex pair (the smaller index in the high half).
struct EdgeRef {
  uint64_t vertices;
  int face;
  int edge;
};

// Every face's edges by their undirected vertex pair, sorted: the faces that share an edge lie
// side by side. A collapsed edge (both ends one vertex: a triangle written as a quad) is left
// out: it has no length for a footprint to cross, and faces that meet only at that vertex (the
// quads around a sphere's pole) would otherwise read as sharing it. A flat array of 16-byte
// entries rather than a std::map of vectors: this runs while the packed texels are already held,
// so whatever it allocates adds to traverse's peak memory (docs/performance.md, "memory" rows).
std::vector<EdgeRef> sorted_edges(const Scene& scene) {
  std::vector<EdgeRef> edges;
  edges.reserve(scene.faces.size() * 4);
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const uint32_t a = scene.faces[f].vertices[k], b = scene.faces[f].vertices[(k + 1) % 4];
      if (a == b) continue;
      edges.push_back({(uint64_t{std::min(a, b)} << 32) | std::max(a, b), static_cast<int>(f), k});
    }
  }
  std::sort(edges.begin(), edges.end(), [](const EdgeRef& x, const EdgeRef& y) {
    return std::tie(x.vertices, x.face, x.edge) < std::tie(y.vertices, y.face, y.edge);
  });
  return edges;
}

// The map across edge k of face f onto edge j of face g, where g runs the edge backwards when
// `reversed` (consistently oriented neighbours do).
UvMap edge_map(int k, int j, bool reversed) {
  // Where f's corner k and corner k+1 sit in g's uv.
  const glm::vec2 ga = reversed ? corner_uv(j + 1) : corner_uv(j);
  const glm::vec2 gb = reversed ? corner_uv(j) : corner_uv(j + 1);
  // A point p = a + s e + t n_f (s along the edge, t into f) lands at a' + s e' - t n_g: the
  // same distance past the edge, out of g. Linear part L = [e', -n_g] [e, n_f]^T (both bases
  // orthonormal), offset o = a' - L a.
  const glm::vec2 e = corner_uv(k + 1) - corner_uv(k);
  const glm::vec2 nf = inward_normal(k);
  const glm::mat2 to_local = glm::transpose(glm::mat2(e, nf));  // rows e, n_f
  UvMap map;
  map.linear = glm::mat2(gb - ga, -inward_normal(j)) * to_local;
  map.offset = ga - map.linear * corner_uv(k);
  return map;
}

// The corner of `face` that holds vertex v, or -1 unless exactly one does.
int corner_of(const Face& face, uint32_t v) {
  int found = -1;
  for (int k = 0; k < 4; ++k) {
    if (face.vertices[k] != v) continue;
    if (found >= 0) return -1;
    found = k;
  }
  return found;
}

}  // namespace

UvMap compose(const UvMap& second, const UvMap& first) {
  return {second.linear * first.linear, second.linear * first.offset + second.offset};
}

std::array<float, 6> map_coefficients(uint8_t code) {
  const bool swap = (code & SEAMCL_MAP_SWAP) != 0;
  const float su = (code & SEAMCL_MAP_NEGATE_U) != 0 ? -1.0f : 1.0f;
  const float sv = (code & SEAMCL_MAP_NEGATE_V) != 0 ? -1.0f : 1.0f;
  const float ou = static_cast<float>(((code >> SEAMCL_MAP_OFFSET_U_SHIFT) & 3) - 1);
  const float ov = static_cast<float>(((code >> SEAMCL_MAP_OFFSET_V_SHIFT) & 3) - 1);
  return {swap ? 0.0f : su, swap ? su : 0.0f, ou, swap ? sv : 0.0f, swap ? 0.0f : sv, ov};
}

UvMap uv_map(uint8_t code) {
  const std::array<float, 6> t = map_coefficients(code);
  UvMap map;
  // glm is column-major: linear[c][r].
  map.linear[0][0] = t[0];
  map.linear[1][0] = t[1];
  map.offset.x = t[2];
  map.linear[0][1] = t[3];
  map.linear[1][1] = t[4];
  map.offset.y = t[5];
  return map;
}

uint8_t encode_uv_map(const UvMap& map) {
  const float t0 = map.linear[0][0], t1 = map.linear[1][0], t3 = map.linear[0][1], t4 = map.linear[1][1];
  const auto unit = [](float x) { return x == 1.0f || x == -1.0f; };
  unsigned code = 0;
  if (t0 == 0.0f && t4 == 0.0f && unit(t1) && unit(t3)) {
    code = SEAMCL_MAP_SWAP | (t1 < 0.0f ? SEAMCL_MAP_NEGATE_U : 0u) | (t3 < 0.0f ? SEAMCL_MAP_NEGATE_V : 0u);
  } else if (t1 == 0.0f && t3 == 0.0f && unit(t0) && unit(t4)) {
    code = (t0 < 0.0f ? SEAMCL_MAP_NEGATE_U : 0u) | (t4 < 0.0f ? SEAMCL_MAP_NEGATE_V : 0u);
  } else {
    throw std::logic_error("encode_uv_map: the linear part is not a signed permutation");
  }
  for (const auto& [offset, shift] : {std::pair{map.offset.x, SEAMCL_MAP_OFFSET_U_SHIFT}, {map.offset.y, SEAMCL_MAP_OFFSET_V_SHIFT}}) {
    if (!(offset >= -1.0f && offset <= 2.0f) || offset != std::floor(offset)) {
      throw std::logic_error("encode_uv_map: an offset is not a whole number in -1..2");
    }
    code |= static_cast<unsigned>(static_cast<int>(offset) + 1) << shift;
  }
  return static_cast<uint8_t>(code);
}

uint8_t encode_reach_side(float side) {
  int exponent = 0;
  const float mantissa = std::frexp(side, &exponent);  // side = mantissa 2^exponent, mantissa in [0.5, 1)
  if (!(mantissa == 0.5f) || exponent - 1 < -126 || exponent - 1 > 127) return SEAMCL_SIDE_NONE;
  return static_cast<uint8_t>(exponent - 1 + SEAMCL_SIDE_BIAS);
}

float reach_side(uint8_t stored) {
  // Below 2 (never encoded) 0, as the kernels' exponent bits give it.
  return stored < 2 ? 0.0f : std::ldexp(1.0f, static_cast<int>(stored) - SEAMCL_SIDE_BIAS);
}

UvMap corner_map(int k, int j, bool swap) {
  // Outward axes at corner k: edge k-1 and edge k continued past the corner.
  const glm::vec2 p = corner_uv(k) - corner_uv(k + 3);
  const glm::vec2 q = corner_uv(k) - corner_uv(k + 1);
  // Inward axes at corner j of the other face: along its edges j and j-1.
  const glm::vec2 e1 = corner_uv(j + 1) - corner_uv(j);
  const glm::vec2 e2 = corner_uv(j + 3) - corner_uv(j);
  UvMap map;
  map.linear = (swap ? glm::mat2(e2, e1) : glm::mat2(e1, e2)) * glm::transpose(glm::mat2(p, q));
  map.offset = corner_uv(j) - map.linear * corner_uv(k);
  return map;
}

bool corner_swap(const Scene& scene, const RingFace& diagonal) {
  // The distance past the corner along edge k-1's line runs along the edge the walk entered the
  // diagonal face by (shared with the neighbour across edge k).
  const Face& face = scene.faces[diagonal.face];
  return face.vertices[(diagonal.corner + 1) % 4] != diagonal.entered_from;
}

VertexRing corner_ring(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t start, int corner) {
  VertexRing ring;
  const Face& first = scene.faces[start];
  const uint32_t vertex = first.vertices[corner];
  if (corner_of(first, vertex) != corner) return ring;
  uint32_t current = start;
  int exit_edge = corner;
  for (int step = 0; step < kMaxRingValence; ++step) {
    const Face& here = scene.faces[current];
    const int next = adjacency[current].neighbor[exit_edge];
    if (next < 0) return ring;  // a boundary: open
    // The far end of the edge crossed.
    const uint32_t a = here.vertices[exit_edge], b = here.vertices[(exit_edge + 1) % 4];
    assert(a == vertex || b == vertex);
    const uint32_t entered_from = a == vertex ? b : a;
    if (static_cast<uint32_t>(next) == start) {
      ring.closed = entered_from == first.vertices[(corner + 3) % 4];
      if (!ring.closed) ring.faces.clear();
      return ring;
    }
    const Face& face = scene.faces[static_cast<size_t>(next)];
    const int j = corner_of(face, vertex);
    if (j < 0) return ring;
    // Leave by the other edge at the vertex.
    if (face.vertices[(j + 1) % 4] == entered_from) {
      exit_edge = (j + 3) % 4;
    } else if (face.vertices[(j + 3) % 4] == entered_from) {
      exit_edge = j;
    } else {
      return ring;
    }
    ring.faces.push_back({static_cast<uint32_t>(next), j, entered_from});
    current = static_cast<uint32_t>(next);
  }
  return ring;  // more faces than kMaxRingValence: open
}

std::vector<FaceNeighbors> build_adjacency(const Scene& scene) {
  std::vector<FaceNeighbors> out(scene.faces.size());
  for (FaceNeighbors& n : out) {
    for (int k = 0; k < 4; ++k) {
      n.neighbor[k] = n.corner[k] = -1;
      n.edge_map[k] = n.corner_map[k] = 0;
      n.reach_min_side[k] = n.reach_max_side[k] = SEAMCL_SIDE_NONE;  // fill_edge_reach fills them
    }
  }
  std::vector<EdgeRef> edges = sorted_edges(scene);
  for (size_t first = 0; first < edges.size();) {
    size_t end = first + 1;
    while (end < edges.size() && edges[end].vertices == edges[first].vertices) ++end;
    // An edge of exactly two faces links them; a quad folded onto itself links nothing.
    if (end - first == 2 && edges[first].face != edges[first + 1].face) {
      for (int side = 0; side < 2; ++side) {
        const EdgeRef& here = edges[first + side];
        const EdgeRef& other = edges[first + 1 - side];
        const Face& f = scene.faces[static_cast<size_t>(here.face)];
        const Face& g = scene.faces[static_cast<size_t>(other.face)];
        const uint32_t b = f.vertices[(here.edge + 1) % 4];
        const bool reversed = g.vertices[other.edge] == b;  // consistently oriented neighbours run the edge backwards
        out[static_cast<size_t>(here.face)].neighbor[here.edge] = other.face;
        out[static_cast<size_t>(here.face)].edge_map[here.edge] = encode_uv_map(edge_map(here.edge, other.edge, reversed));
      }
    }
    first = end;
  }
  edges = {};
  // Corners, once every edge is linked: the diagonal face of a valence-4 vertex, reached across
  // edge k and then across the neighbour's other edge at the vertex.
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const VertexRing ring = corner_ring(scene, out, static_cast<uint32_t>(f), k);
      if (ring.valence() != 4) continue;
      const RingFace& beside = ring.faces[0];
      const RingFace& diagonal = ring.faces[1];
      // The edge of `beside` into the diagonal face: the one from the vertex to where the walk
      // entered it (two faces may share two edges, as on a torus two faces around).
      int across = -1;
      const uint32_t vertex = scene.faces[f].vertices[k];
      const Face& b = scene.faces[beside.face];
      for (int e = 0; e < 4; ++e) {
        const bool at_vertex = b.vertices[e] == vertex || b.vertices[(e + 1) % 4] == vertex;
        const bool to_entry = b.vertices[e] == diagonal.entered_from || b.vertices[(e + 1) % 4] == diagonal.entered_from;
        if (at_vertex && to_entry && out[beside.face].neighbor[e] == static_cast<int>(diagonal.face)) across = e;
      }
      assert(across >= 0);
      const UvMap map = compose(uv_map(out[beside.face].edge_map[across]), uv_map(out[f].edge_map[k]));
      out[f].corner[k] = static_cast<int>(diagonal.face);
      out[f].corner_map[k] = encode_uv_map(map);
    }
  }
  return out;
}

NonManifoldEdges non_manifold_edges(const Scene& scene) {
  const std::vector<EdgeRef> edges = sorted_edges(scene);
  NonManifoldEdges out;
  for (size_t first = 0; first < edges.size();) {
    size_t end = first + 1;
    while (end < edges.size() && edges[end].vertices == edges[first].vertices) ++end;
    if (end - first > 2) {
      if (out.count++ == 0) {
        out.first_vertex = static_cast<uint32_t>(edges[first].vertices >> 32);
        out.second_vertex = static_cast<uint32_t>(edges[first].vertices);
        out.example_faces = end - first;
      }
    }
    first = end;
  }
  return out;
}

bool has_adjacency(const std::vector<FaceNeighbors>& adjacency) {
  if (adjacency.size() < 2) return true;
  for (const FaceNeighbors& n : adjacency)
    for (int k = 0; k < 4; ++k)
      if (n.neighbor[k] >= 0) return true;
  return false;
}

glm::vec2 transform_uv(const FaceNeighbors& n, int edge, glm::vec2 uv, bool translate) {
  const UvMap map = uv_map(n.edge_map[edge]);
  return translate ? map.point(uv) : map.direction(uv);
}

}  // namespace seamcl
