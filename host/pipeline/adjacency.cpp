#include "pipeline/adjacency.h"

#include <map>
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

struct EdgeRef {
  int face;
  int edge;
};

}  // namespace

std::vector<FaceNeighbors> build_adjacency(const Scene& scene) {
  std::vector<FaceNeighbors> out(scene.faces.size());
  // Every directed edge (from, to) with the face and edge index that own it.
  std::map<std::pair<uint32_t, uint32_t>, std::vector<EdgeRef>> edges;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const uint32_t a = scene.faces[f].vertices[k], b = scene.faces[f].vertices[(k + 1) % 4];
      edges[{std::min(a, b), std::max(a, b)}].push_back({static_cast<int>(f), k});
    }
  }
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    FaceNeighbors& n = out[f];
    for (int k = 0; k < 4; ++k) {
      n.neighbor[k] = -1;
      for (int i = 0; i < 6; ++i) n.transform[k][i] = 0.0f;
      const uint32_t a = scene.faces[f].vertices[k], b = scene.faces[f].vertices[(k + 1) % 4];
      const auto& sharing = edges.at({std::min(a, b), std::max(a, b)});
      if (sharing.size() != 2) continue;
      const EdgeRef other = sharing[0].face == static_cast<int>(f) && sharing[0].edge == k ? sharing[1] : sharing[0];
      if (other.face == static_cast<int>(f)) continue;  // a quad folded onto itself
      const Face& g = scene.faces[static_cast<size_t>(other.face)];
      const int j = other.edge;
      // Where vertex a (corner k of f) and vertex b (corner k+1) sit in g's uv.
      const bool reversed = g.vertices[j] == b;  // consistently oriented neighbours run the edge backwards
      const glm::vec2 ga = reversed ? corner_uv(j + 1) : corner_uv(j);
      const glm::vec2 gb = reversed ? corner_uv(j) : corner_uv(j + 1);
      // A point p = a + s e + t n_f (s along the edge, t into f) lands at a' + s e' - t n_g: the
      // same distance past the edge, out of g. Linear part L = [e', -n_g] [e, n_f]^T (both bases
      // orthonormal), offset o = a' - L a.
      const glm::vec2 e = corner_uv(k + 1) - corner_uv(k);
      const glm::vec2 nf = inward_normal(k);
      const glm::vec2 e_g = gb - ga;
      const glm::vec2 ng = inward_normal(j);
      const glm::mat2 to_local = glm::transpose(glm::mat2(e, nf));  // rows e, n_f
      const glm::mat2 linear = glm::mat2(e_g, -ng) * to_local;
      const glm::vec2 offset = ga - linear * corner_uv(k);
      n.neighbor[k] = other.face;
      // glm is column-major: linear[c][r].
      n.transform[k][0] = linear[0][0];
      n.transform[k][1] = linear[1][0];
      n.transform[k][2] = offset.x;
      n.transform[k][3] = linear[0][1];
      n.transform[k][4] = linear[1][1];
      n.transform[k][5] = offset.y;
    }
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
  const float* t = n.transform[edge];
  const float w = translate ? 1.0f : 0.0f;
  return {t[0] * uv.x + t[1] * uv.y + t[2] * w, t[3] * uv.x + t[4] * uv.y + t[5] * w};
}

}  // namespace seamcl
