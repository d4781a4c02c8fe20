// Scenes made of users' assets: a quad mesh (an OBJ, or the mesh a .ptx carries) with its Ptex
// textures, or with the surface pattern when there are none. Units are the mesh's own; the camera
// and its orbit are framed from the mesh's bounds.
#pragma once
#include <string>

#include <seamcl/assets/obj_mesh.h>
#include <seamcl/assets/ptex_file.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Face i of the mesh takes face i of the file (a deferred file's texture_source becomes the scene's). Throws InputError(field) when the face counts
// differ or the file's adjacency disagrees with the mesh's shared edges (check_ptex_adjacency).
Scene scene_from_ptex(ObjMesh mesh, PtexFile ptex, const std::string& mesh_name, const std::string& ptex_name,
                      const std::string& field = "texture");

// Every face the surface pattern (surface_pattern), baked at texture_size x texture_size texels
// (a power of two): for a mesh without textures of its own. With defer_textures, baked by
// Scene::texture_source when packed instead (the faces hold their sizes only).
// At most kMaxMeshTexels level-0 texels in all (the bound of scene files' textures): a mesh with
// more faces than texture_size^2 texels each would fit gets smaller textures (a power of two a side,
// mesh_texture_side), one of more faces than kMaxMeshTexels is refused (InputError "scene").
Scene scene_from_mesh(ObjMesh mesh, int texture_size, const std::string& mesh_name, bool defer_textures = false);

inline constexpr size_t kMaxMeshTexels = size_t{1} << 26;
// The side of each face's texture for a mesh of `faces` faces: texture_size, halved until the
// faces' texels fit kMaxMeshTexels (at least 1).
int mesh_texture_side(size_t faces, int texture_size);

// The mesh a .ptx carries in its metadata, as an ObjMesh; InputError(field) when it has none.
ObjMesh ptex_mesh(const PtexFile& ptex, const std::string& ptex_name, const std::string& field = "scene");

// Sets the camera and an orbit around the bounds of the scene's positions: the whole mesh in view
// at 45 degrees vertical field of view for any aspect from 3:4 up, seen from 25 degrees above its
// centre. Frame 0 of the orbit is the camera.
void frame_camera(Scene& scene);

}  // namespace seamcl
