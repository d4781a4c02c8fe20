// A .ptx file's own adjacency (adjfaces, adjedges) against its mesh's. seamcl's traverse and
// guardband read the adjacency of shared vertex indices (host/pipeline/adjacency.h); a file whose
// adjacency says otherwise would be filtered across other edges than its author's tools did, so
// the two must agree, rotated neighbours included.
#pragma once
#include <string>
#include <vector>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Throws InputError(field) on the first face edge where they differ, naming both faces (and
// edges), `mesh_name` and `ptex_name`. Face counts must already match.
void check_ptex_adjacency(const Scene& mesh_scene, const std::vector<PtexFaceInfo>& file_faces,
                          const std::string& mesh_name, const std::string& ptex_name,
                          const std::string& field = "texture");

}  // namespace seamcl
