// Where a scene comes from, for the command line and the service alike: one entry point over
// built-in names, scene files (docs/scene-format.md: generators, explicit faces, faces with image
// textures, mesh scenes), OBJ meshes with or without a .ptx, and .ptx files that carry their mesh.
// host/scene's load_scene knows the first two; this adds the files only host/assets can read.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

// The kinds of file a scene can be made of, told by the name's extension (case-insensitive):
// .json scene files, .obj meshes, .ptx Ptex textures.
enum class AssetKind { SceneFile, Mesh, Ptex };
std::optional<AssetKind> parse_asset_kind(std::string_view name);  // "scene", "mesh", "ptex"
std::string to_string(AssetKind kind);
std::vector<std::string> asset_kind_names();
std::optional<AssetKind> asset_kind_of_path(const std::string& path);

// Turns a file name as written into a path on disk. `relative_to` is the directory of the file
// that names it (a scene file's), empty for names from the command line or a request; `field`
// names the option or JSON path, for errors. Throws InputError(field) for a name it refuses.
using AssetPathResolver =
    std::function<std::string(const std::string& name, const std::string& relative_to, const std::string& field)>;

// The command line's resolver: any path; a relative one against relative_to when it is not empty.
std::string resolve_any_path(const std::string& name, const std::string& relative_to, const std::string& field);

struct SceneSourceOptions {
  GeneratorOptions generator;  // tint and a constant colour, on top of the scene's own textures;
                               // defer_textures also defers a .ptx's faces and a bare mesh's pattern
  PtexLimits ptex_limits;      // what a .ptx may make the reader allocate
  int mesh_texture_size = 64;  // texels per side of each face of a mesh without a .ptx
  AssetPathResolver resolve;   // empty: resolve_any_path
  // A 1-channel .ptx (resolved like the scene's files, field "displacement_map") whose faces
  // become the scene's displacement maps (attach_ptex_displacement); empty: none.
  std::string displacement_map;
};

// `scene`: a built-in name, a .json scene file, an .obj mesh or a .ptx holding its mesh.
// `texture`: a .ptx for an .obj scene; empty for none (the mesh then gets the surface pattern).
// Errors are InputError naming "scene", "texture", or within a scene file the JSON path.
Scene load_scene_source(const std::string& scene, const std::string& texture = {},
                        const SceneSourceOptions& options = {});

}  // namespace seamcl
