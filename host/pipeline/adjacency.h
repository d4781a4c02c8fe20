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

// Applies transform k of `n` to a uv point (or, with translate = false, to a derivative).
glm::vec2 transform_uv(const FaceNeighbors& n, int edge, glm::vec2 uv, bool translate = true);

}  // namespace seamcl
