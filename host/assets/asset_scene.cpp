#include <seamcl/assets/asset_scene.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>

#include <seamcl/assets/ptex_adjacency.h>
#include <seamcl/core/input_error.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {
namespace {

std::string stem_of(const std::string& path) { return std::filesystem::path(path).stem().string(); }

Scene scene_of_mesh(ObjMesh mesh, const std::string& mesh_name) {
  Scene scene;
  scene.name = stem_of(mesh_name);
  scene.positions = std::move(mesh.positions);
  scene.faces.resize(mesh.faces.size());
  for (size_t f = 0; f < mesh.faces.size(); ++f) scene.faces[f].vertices = mesh.faces[f];
  return scene;
}

}  // namespace

Scene scene_from_ptex(ObjMesh mesh, PtexFile ptex, const std::string& mesh_name, const std::string& ptex_name,
                      const std::string& field) {
  if (ptex.textures.size() != mesh.faces.size() || ptex.faces.size() != mesh.faces.size())
    throw InputError(field, "'" + ptex_name + "' has " + std::to_string(ptex.faces.size()) + " faces but the mesh '" +
                                mesh_name + "' has " + std::to_string(mesh.faces.size()) +
                                " (face i of the mesh takes face i of the file)");
  Scene scene = scene_of_mesh(std::move(mesh), mesh_name);
  check_ptex_adjacency(scene, ptex.faces, mesh_name, ptex_name, field);
  for (size_t f = 0; f < scene.faces.size(); ++f) scene.faces[f].texture = std::move(ptex.textures[f]);
  scene.texture_source = std::move(ptex.texture_source);  // the deferred faces' (empty when none is)
  scene.texture_source_bytes = static_cast<size_t>(ptex.texture_source_bytes);
  scene.ptex_file = ptex_name;
  frame_camera(scene);
  validate_scene(scene);
  return scene;
}

int mesh_texture_side(size_t faces, int texture_size) {
  int side = texture_size;
  while (side > 1 && faces * static_cast<size_t>(side) * static_cast<size_t>(side) > kMaxMeshTexels) side /= 2;
  return side;
}

Scene scene_from_mesh(ObjMesh mesh, int texture_size, const std::string& mesh_name, bool defer_textures) {
  if (texture_size < 1 || (texture_size & (texture_size - 1)) != 0)
    throw std::invalid_argument("scene_from_mesh: texture_size must be a power of two");
  if (mesh.faces.size() > kMaxMeshTexels)
    throw InputError("scene", "'" + mesh_name + "' has " + std::to_string(mesh.faces.size()) + " faces; a mesh without a "
                              ".ptx may have at most " + std::to_string(kMaxMeshTexels) + " (one texel each)");
  texture_size = mesh_texture_side(mesh.faces.size(), texture_size);
  Scene scene = scene_of_mesh(std::move(mesh), mesh_name);
  if (defer_textures) {
    // The source keeps its own copy of the corners, so it stays right in any copy of the scene.
    std::vector<std::array<glm::vec3, 4>> corners;
    corners.reserve(scene.faces.size());
    for (Face& face : scene.faces) {
      corners.push_back(scene.corners(face));
      face.texture = deferred_mip_chain(texture_size, texture_size);
    }
    scene.texture_source = [corners = std::make_shared<const std::vector<std::array<glm::vec3, 4>>>(std::move(corners)),
                            texture_size](size_t f) {
      return build_mip_chain(bake_face_texture(corners->at(f), texture_size, texture_size, surface_patterns));
    };
  } else {
    for (Face& face : scene.faces)
      face.texture = build_mip_chain(bake_face_texture(scene.corners(face), texture_size, texture_size, surface_patterns));
  }
  frame_camera(scene);
  validate_scene(scene);
  return scene;
}

ObjMesh ptex_mesh(const PtexFile& ptex, const std::string& ptex_name, const std::string& field) {
  if (!ptex.mesh)
    throw InputError(field, "'" + ptex_name + "' holds no mesh in its metadata (PtexFaceVertCounts, PtexFaceVertIndices, "
                            "PtexVertPositions): give the mesh as an .obj scene and the file as its texture");
  ObjMesh mesh;
  mesh.positions = ptex.mesh->positions;
  mesh.faces = ptex.mesh->faces;
  return mesh;
}

void frame_camera(Scene& scene) {
  glm::vec3 low(INFINITY), high(-INFINITY);
  for (const glm::vec3& p : scene.positions) {
    low = glm::min(low, p);
    high = glm::max(high, p);
  }
  if (scene.positions.empty()) low = high = glm::vec3(0.0f);
  const glm::vec3 center = 0.5f * (low + high);
  const float radius = std::max(0.5f * glm::length(high - low), 1e-3f);
  // The bounding sphere inside the narrower field: 3:4 (portrait, the default 480x540 is 8:9)
  // leaves a horizontal half-angle of atan(0.75 tan 22.5) = 17.3 degrees; 16 leaves a margin.
  constexpr float kFovY = 45.0f;
  constexpr float kHalfAngle = 16.0f;
  constexpr float kElevation = 25.0f;
  constexpr float kStart = 35.0f;  // an oblique first frame, so three sides of a box show
  const float distance = radius / std::sin(glm::radians(kHalfAngle));
  Orbit orbit;
  orbit.center = center;
  orbit.radius = distance * std::cos(glm::radians(kElevation));
  orbit.height = distance * std::sin(glm::radians(kElevation));
  orbit.start_degrees = kStart;
  scene.orbit = orbit;
  scene.camera.fov_y_degrees = kFovY;
  scene.camera = orbit_camera(scene, 0, 1);
}

}  // namespace seamcl
