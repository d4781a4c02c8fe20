#include <seamcl/assets/scene_source.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <utility>

#include <seamcl/assets/asset_scene.h>
#include "assets/environment_file.h"
#include <seamcl/assets/face_image.h>
#include <seamcl/assets/obj_mesh.h>
#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/regular_file.h>
#include <seamcl/core/json_document.h>
#include <seamcl/scene/scene_json.h>

namespace seamcl {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// In the order of AssetKind.
constexpr std::array<std::pair<std::string_view, std::string_view>, 3> kKinds{
    {{"scene", ".json"}, {"mesh", ".obj"}, {"ptex", ".ptx"}}};

std::string lowercase_extension(const std::string& path) {
  std::string extension = fs::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// The message of an InputError without its "field: " prefix.
std::string message_of(const InputError& error) { return std::string(error.what()).substr(error.field().size() + 2); }

struct Loader {
  const SceneSourceOptions& options;
  AssetPathResolver resolve;

  // The reader names every error "texture"; a .ptx given as the scene is the scene's.
  PtexFile read_ptex(const std::string& path, const std::string& field) const {
    try {
      // Deferred as the generators are when asked: the texels stay compressed until packed.
      return read_ptex_file(path, options.ptex_limits, options.generator.defer_textures);
    } catch (const InputError& error) {
      if (error.field() == field) throw;
      throw InputError(field, message_of(error));
    }
  }

  Scene mesh_scene(const std::string& mesh_path, const std::string& texture_path, const std::string& mesh_field,
                   const std::string& texture_field) const {
    ObjMesh mesh = read_obj_file(mesh_path, mesh_field);
    if (texture_path.empty())
      return scene_from_mesh(std::move(mesh), options.mesh_texture_size, mesh_path, options.generator.defer_textures);
    if (asset_kind_of_path(texture_path) != AssetKind::Ptex)
      throw InputError(texture_field, "must be a .ptx file, got '" + texture_path + "'");
    return scene_from_ptex(std::move(mesh), read_ptex(texture_path, texture_field), mesh_path, texture_path,
                           texture_field);
  }

  Scene ptex_scene(const std::string& ptex_path, const std::string& field) const {
    PtexFile ptex = read_ptex(ptex_path, field);
    ObjMesh mesh = ptex_mesh(ptex, ptex_path, field);
    return scene_from_ptex(std::move(mesh), std::move(ptex), ptex_path, ptex_path, field);
  }

  // {"mesh": ..., "texture": ..., camera, orbit, light, background, name}; names relative to the file.
  Scene mesh_scene_file(const json& doc, const std::string& path) const {
    constexpr std::array<std::string_view, 7> known{"name", "mesh", "texture", "camera", "orbit", "light", "background"};
    for (const auto& [key, unused] : doc.items())
      if (std::find(known.begin(), known.end(), key) == known.end())
        throw InputError(key, "unknown field (known: name, mesh, texture, camera, orbit, light, background)");
    auto name_field = [&doc](const char* key) -> std::string {
      const auto found = doc.find(key);
      if (found == doc.end()) return {};
      if (!found->is_string() || found->get<std::string>().empty())
        throw InputError(key, "must be a file name (a non-empty string)");
      return found->get<std::string>();
    };
    const std::string directory = fs::path(path).parent_path().string();
    const std::string mesh_name = name_field("mesh"), texture_name = name_field("texture");
    Scene scene;
    if (mesh_name.empty()) {
      if (texture_name.empty()) throw InputError("mesh", "is required (or a .ptx that holds its mesh as texture)");
      scene = ptex_scene(resolve(texture_name, directory, "texture"), "texture");
    } else {
      const std::string mesh_path = resolve(mesh_name, directory, "mesh");
      if (asset_kind_of_path(mesh_path) != AssetKind::Mesh) throw InputError("mesh", "must be an .obj file, got '" + mesh_name + "'");
      scene = mesh_scene(mesh_path, texture_name.empty() ? "" : resolve(texture_name, directory, "texture"), "mesh", "texture");
    }
    scene.name = fs::path(path).stem().string();
    if (const auto name = doc.find("name"); name != doc.end()) {
      if (!name->is_string()) throw InputError("name", "must be a string");
      scene.name = name->get<std::string>();
    }
    const SceneViewFields view = parse_scene_view_fields(doc);
    if (view.camera) scene.camera = *view.camera;
    if (view.orbit) scene.orbit = *view.orbit;
    if (view.light) scene.light = *view.light;
    if (view.background) scene.background = *view.background;
    validate_scene(scene);
    return scene;
  }

  Scene scene_file(const std::string& path) const {
    json doc;  // stays discarded (not an object) when the file is missing or not JSON: load_scene says why
    // Only a file the scene reader would read whole is looked into here (a larger one, or one
    // that fails mid-read, is refused by that reader, naming why).
    std::string text;
    RegularFile document_file(path);
    if (document_file.size() <= kMaxSceneFileBytes && document_file.read_all(text, kMaxSceneFileBytes) &&
        text.size() <= kMaxSceneFileBytes) {
      // Parsed as strictly as the scene reader parses (no repeated key, no NUL byte), since a mesh
      // form is read from this document alone.
      try {
        doc = parse_json_document(text);
      } catch (const std::exception&) {
        doc = json(json::value_t::discarded);
      }
    }
    const bool mesh_form = doc.is_object() && (doc.contains("mesh") || (doc.contains("texture") && doc.at("texture").is_string()));
    if (!mesh_form) {
      // Generators and explicit scenes: host/scene's reader (which reports syntax errors itself),
      // with image faces read here, relative to the file.
      const std::string directory = fs::path(path).parent_path().string();
      // Only the header is read here; the pixels when the face is baked (at once, or for a
      // deferred scene when it is packed: the file must not have changed by then).
      const FaceImageLoader load_image = [this, directory](const std::string& name, const std::string& field) {
        FaceImageFile file = open_face_image(resolve(name, directory, field), field);
        const int width = file.width, height = file.height;
        const size_t decode_bytes = file.decode_bytes;
        return FaceImage{width, height, [file = std::move(file)] { return read_face_image(file); }, decode_bytes};
      };
      Scene scene = load_scene(path, options.generator, load_image);
      if (scene.environment) load_environment_files(*scene.environment, directory, resolve);
      return scene;
    }
    try {
      Scene scene = mesh_scene_file(doc, path);
      apply_generator_options(scene, options.generator);
      return scene;
    } catch (const InputError& error) {
      throw error_in_scene_file(error, path);
    }
  }
};

}  // namespace

std::optional<AssetKind> parse_asset_kind(std::string_view name) {
  for (size_t i = 0; i < kKinds.size(); ++i)
    if (kKinds[i].first == name) return static_cast<AssetKind>(i);
  return std::nullopt;
}

std::string to_string(AssetKind kind) { return std::string(kKinds[static_cast<size_t>(kind)].first); }

std::vector<std::string> asset_kind_names() {
  std::vector<std::string> names;
  for (const auto& kind : kKinds) names.emplace_back(kind.first);
  return names;
}

std::optional<AssetKind> asset_kind_of_path(const std::string& path) {
  const std::string extension = lowercase_extension(path);
  for (size_t i = 0; i < kKinds.size(); ++i)
    if (kKinds[i].second == extension) return static_cast<AssetKind>(i);
  return std::nullopt;
}

std::string resolve_any_path(const std::string& name, const std::string& relative_to, const std::string& field) {
  if (name.empty()) throw InputError(field, "must not be empty");
  const fs::path path(name);
  if (relative_to.empty() || path.is_absolute()) return name;
  return (fs::path(relative_to) / path).string();
}

namespace {

Scene load_scene_itself(const Loader& loader, const std::string& scene, const std::string& texture,
                        const SceneSourceOptions& options) {
  if (is_builtin_scene(scene)) {
    if (!texture.empty()) throw InputError("texture", "goes with an .obj scene, not the built-in scene '" + scene + "'");
    Scene out = generate_scene(scene, options.generator);
    if (out.environment) load_environment_files(*out.environment, "", loader.resolve);
    return out;
  }
  const std::string path = loader.resolve(scene, "", "scene");
  const std::optional<AssetKind> kind = asset_kind_of_path(path);
  if (!texture.empty() && kind != AssetKind::Mesh)
    throw InputError("texture", "goes with an .obj scene; '" + scene + "' " +
                                    (kind == AssetKind::Ptex ? "is a .ptx with textures of its own" : "is not a mesh"));
  Scene out;
  if (kind == AssetKind::Mesh) {
    out = loader.mesh_scene(path, texture.empty() ? "" : loader.resolve(texture, "", "texture"), "scene", "texture");
  } else if (kind == AssetKind::Ptex) {
    out = loader.ptex_scene(path, "scene");
  } else {
    return loader.scene_file(path);  // applies the generator options itself
  }
  apply_generator_options(out, options.generator);
  return out;
}

}  // namespace

Scene load_scene_source(const std::string& scene, const std::string& texture, const SceneSourceOptions& options) {
  const Loader loader{options, options.resolve ? options.resolve : AssetPathResolver(resolve_any_path)};
  Scene out = load_scene_itself(loader, scene, texture, options);
  if (!options.displacement_map.empty()) {
    attach_ptex_displacement(out, loader.resolve(options.displacement_map, "", "displacement_map"), options.ptex_limits);
  }
  return out;
}

}  // namespace seamcl
