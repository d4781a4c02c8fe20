#include <seamcl/assets/ptex_adjacency.h>

#include <cassert>

#include <seamcl/core/input_error.h>
#include "pipeline/adjacency.h"

namespace seamcl {
namespace {

constexpr const char* kEdgeNames[4] = {"bottom", "right", "top", "left"};

std::string edge_name(int face, int edge) {
  return "face " + std::to_string(face) + " edge " + std::to_string(edge) + " (" + kEdgeNames[edge & 3] + ")";
}

// The edge of `neighbor` that joins vertices a and b (either direction); -1 if none does.
int edge_joining(const Face& neighbor, uint32_t a, uint32_t b) {
  for (int j = 0; j < 4; ++j) {
    const uint32_t from = neighbor.vertices[static_cast<size_t>(j)], to = neighbor.vertices[static_cast<size_t>((j + 1) % 4)];
    if ((from == a && to == b) || (from == b && to == a)) return j;
  }
  return -1;
}

}  // namespace

void check_ptex_adjacency(const Scene& mesh_scene, const std::vector<PtexFaceInfo>& file_faces,
                          const std::string& mesh_name, const std::string& ptex_name, const std::string& field) {
  assert(mesh_scene.faces.size() == file_faces.size());
  const std::vector<FaceNeighbors> mesh = build_adjacency(mesh_scene);
  for (size_t f = 0; f < file_faces.size(); ++f) {
    const Face& face = mesh_scene.faces[f];
    for (int k = 0; k < 4; ++k) {
      const int mesh_neighbor = mesh[f].neighbor[k];
      int mesh_edge = -1;
      if (mesh_neighbor >= 0) {
        mesh_edge = edge_joining(mesh_scene.faces[static_cast<size_t>(mesh_neighbor)], face.vertices[static_cast<size_t>(k)],
                                 face.vertices[static_cast<size_t>((k + 1) % 4)]);
        assert(mesh_edge >= 0);
      }
      const int file_neighbor = file_faces[f].adjacent_faces[static_cast<size_t>(k)] < 0 ? -1 : file_faces[f].adjacent_faces[static_cast<size_t>(k)];
      const int file_edge = file_neighbor < 0 ? -1 : file_faces[f].adjacent_edges[static_cast<size_t>(k)] & 3;
      if (mesh_neighbor == file_neighbor && mesh_edge == file_edge) continue;
      const std::string here = edge_name(static_cast<int>(f), k);
      const std::string in_file = file_neighbor < 0 ? "no neighbour" : edge_name(file_neighbor, file_edge);
      const std::string in_mesh = mesh_neighbor < 0 ? "no neighbour (no other face shares its two vertices)"
                                                    : edge_name(mesh_neighbor, mesh_edge);
      throw InputError(field, "the adjacency of '" + ptex_name + "' disagrees with the mesh '" + mesh_name + "': " +
                                  here + " meets " + in_file + " in the file but " + in_mesh + " in the mesh");
    }
  }
}

}  // namespace seamcl
