// Adjacency of a scene's quads and the uv maps between neighbouring faces: what traverse
// (McDonald 2013, with Ptex's corners) and the guard bands read. Built once per scene from the
// shared vertex indices: the edge neighbours, and the ring of faces around each corner's vertex.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// uv' = linear uv + offset, from one face's unit square to another's: a rotation by a multiple of
// 90 degrees or a reflection, and a translation by whole units.
struct UvMap {
  glm::mat2 linear{1.0f};
  glm::vec2 offset{0.0f};
  glm::vec2 point(glm::vec2 uv) const { return linear * uv + offset; }
  glm::vec2 direction(glm::vec2 d) const { return linear * d; }
};
UvMap compose(const UvMap& second, const UvMap& first);  // first, then second
// As FaceNeighbors stores a map (SEAMCL_MAP_* in kernels/seamcl_types.h): decoded to the same exact
// floats as the kernels decode it, and encoded (std::logic_error for a map that is not a signed
// permutation with whole offsets in -1..2).
UvMap uv_map(uint8_t code);
uint8_t encode_uv_map(const UvMap& map);
// The map's coefficients as the kernels apply them: (t0 u + t1 v + t2, t3 u + t4 v + t5).
std::array<float, 6> map_coefficients(uint8_t code);
// A reach side as FaceNeighbors stores it: a power of two 2^-126..2^127 exactly, anything else
// (0 included) as SEAMCL_SIDE_NONE, which reads back as 0 (never skips).
uint8_t encode_reach_side(float side);
float reach_side(uint8_t stored);

// Per face, as the kernels read it (FaceNeighbors in kernels/seamcl_types.h). An edge shared by
// exactly two faces links them; an edge of one face, or of three or more, has no neighbour, nor
// has a collapsed edge (one vertex at both ends: a triangle written as a quad). A corner whose
// vertex has valence 4 links the diagonal face, through the edge maps composed.
std::vector<FaceNeighbors> build_adjacency(const Scene& scene);

// What the methods that read neighbours (traverse, guardband) need: true unless there are two or
// more faces and no edge links two of them. A single face has nothing to read across; many faces
// that share no vertex index (an OBJ written with split vertices, say) would quietly render as
// discard or clamp.
bool has_adjacency(const std::vector<FaceNeighbors>& adjacency);

// The edges held by three or more faces (non-manifold): build_adjacency links no face across them,
// so a mesh whose only shared edges are these has no adjacency although its faces do share edges.
// For the refusal's message: how many there are, and the first by vertex indices with its faces.
struct NonManifoldEdges {
  size_t count = 0;
  uint32_t first_vertex = 0, second_vertex = 0;  // the example edge, lower index first
  size_t example_faces = 0;                      // faces holding it (validate_scene leaves none holding it twice:
                                                 // such a quad has no area)
};
NonManifoldEdges non_manifold_edges(const Scene& scene);

// Applies edge map k of `n` to a uv point (or, with translate = false, to a derivative).
glm::vec2 transform_uv(const FaceNeighbors& n, int edge, glm::vec2 uv, bool translate = true);

// A face of the ring around a vertex: which of its corners is the vertex, and the vertex at the
// other end of the edge the walk entered it through.
struct RingFace {
  uint32_t face;
  int corner;
  uint32_t entered_from;
};

// Rings are walked up to this many faces; a vertex with more is treated as open (a mesh
// boundary): past its corners nothing is read.
inline constexpr int kMaxRingValence = 32;

// The faces around corner `corner` of `face`: the walk starts across edge `corner` and goes on,
// each time across the edge at the vertex that it did not come in by. closed: it came back to
// `face` across edge corner - 1, and `faces` holds the valence - 1 other faces, the diagonal ones
// (sharing no edge with `face`) from faces[1] to faces[valence - 3]. Open: a mesh boundary or
// non-manifold edge on the way, a face holding the vertex twice, or more than kMaxRingValence.
struct VertexRing {
  std::vector<RingFace> faces;
  bool closed = false;
  int valence() const { return closed ? static_cast<int>(faces.size()) + 1 : 0; }
};
VertexRing corner_ring(const Scene& scene, const std::vector<FaceNeighbors>& adjacency, uint32_t face, int corner);

// The map of the quadrant past corner k of a face (its two edges at that corner continued) onto
// the corner of another face at its corner j: distances past the two edges become distances in
// from that face's two edges at j. Which edge takes which is `swap`; at a valence-4 vertex the
// mesh decides it (corner_swap), at others a symmetric use takes both.
UvMap corner_map(int k, int j, bool swap);
// The swap that carries a ring's diagonal face (ring.faces[1] at valence 4) into place.
bool corner_swap(const Scene& scene, const RingFace& diagonal);

}  // namespace seamcl
