#include "pipeline/reflective_face.h"

#include <cassert>

namespace seamcl {

ReflectiveFace reflective_face(const Scene& scene, const Face& face) {
  assert(face.roughness >= 0.0f && scene.normals.size() == scene.positions.size());
  ReflectiveFace out{};
  for (int k = 0; k < 4; ++k) {
    const glm::vec3 p = scene.positions.at(face.vertices[k]);
    const glm::vec3 n = scene.normals.at(face.vertices[k]);
    for (int c = 0; c < 3; ++c) {
      out.position[k][c] = p[c];
      out.normal[k][c] = n[c];
    }
  }
  out.roughness = face.roughness;
  return out;
}

}  // namespace seamcl
