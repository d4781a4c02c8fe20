// Edge adjacency of a scene's quads and the uv transform across each shared edge: what the
// traverse method (McDonald 2013) reads. Built once per scene from the shared vertex indices.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Per face, as the kernels read it (FaceNeighbors in kernels/seamcl_types.h). An edge shared by
// exactly two faces links them; an edge of one face, or of three or more, has no neighbour.
std::vector<FaceNeighbors> build_adjacency(const Scene& scene);

// What the methods that read neighbours (traverse, guardband) need: true unless there are two or
// more faces and no edge links two of them. A single face has nothing to read across; many faces
// that share no vertex index (an OBJ written with split vertices, say) would quietly render as
// discard or clamp.
bool has_adjacency(const std::vector<FaceNeighbors>& adjacency);

// Applies transform k of `n` to a uv point (or, with translate = false, to a derivative).
glm::vec2 transform_uv(const FaceNeighbors& n, int edge, glm::vec2 uv, bool translate = true);

}  // namespace seamcl
