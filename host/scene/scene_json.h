// Scenes from JSON files; the format is documented in docs/scene-format.md. Every error is an
// InputError whose field is the JSON path of the value at fault (e.g. "faces[2].texture.width").
#pragma once
#include <cstddef>
#include <functional>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>

#include <seamcl/core/input_error.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

// A scene file's text is read only up to this (64 MiB holds some 500,000 explicit faces): the
// parsed document takes some 40 times the text.
inline constexpr size_t kMaxSceneFileBytes = size_t{64} << 20;

// A face's image as the loader found it while the scene was read: its size (from the file's
// header; powers of two) and how to read its pixels as level 0 (width x height texels), at once
// or, for a deferred scene, each time the face's texture is made (Scene::texture_source).
struct FaceImage {
  int width = 0;
  int height = 0;
  std::function<TextureLevel()> read;  // throws InputError naming the field (the file changed, went)
  size_t decode_bytes = 0;             // what `read` holds beside level 0 while it decodes
};

// Looks up the image a face names ("texture": {"image": NAME}): refuses a missing or bad file
// from its header, reading no pixels. `field` is the JSON path to name in errors
// (faces[3].texture.image). host/scene reads no image files itself: host/assets supplies this
// (seamcl::load_scene_source), and without one an image face is an InputError, so an inline scene
// (the HTTP service) can name no file.
using FaceImageLoader = std::function<FaceImage(const std::string& name, const std::string& field)>;

// Either a generator reference ({"generator": ..., "options": ...}) or an explicit scene.
// The result has passed validate_scene. `options` apply on top of the document's own as in
// load_scene (defer_textures: a generator's textures, and every face's of an explicit scene,
// images included, are left to Scene::texture_source, so that the scene's sizes, and what it will
// cost, are known before anything is baked or decoded; a face's errors found only then, such as
// an image file that changed since, are InputErrors naming the face's field).
Scene parse_scene_json(const nlohmann::json& doc, const FaceImageLoader& load_image = {},
                       const GeneratorOptions& options = {});

// Reads and parses a scene file. An unreadable file or bad JSON syntax is InputError("scene", ...)
// naming the path and the parse error; errors in the content keep their JSON path as the field
// and name the file (error_in_scene_file), also those found only when a deferred face is made
// (an image file changed since, a non-finite texel). An explicit scene without "name" is named
// after the file.
Scene load_scene_file(const std::string& path, const FaceImageLoader& load_image = {});

// A built-in scene name, else a scene file (a path that ends in .json or exists). `options`
// apply on top of the scene's own: for a generator file, tint if either asks and the caller's
// constant colour over the file's; for an explicit scene, as apply_generator_options.
Scene load_scene(const std::string& name_or_path, const GeneratorOptions& options,
                 const FaceImageLoader& load_image = {});

// `error` as every error of a scene file reads: its message followed by " (in 'path')", its
// field kept.
InputError error_in_scene_file(const InputError& error, const std::string& path);

// True for a built-in scene name (scene_generators()).
bool is_builtin_scene(const std::string& name);

// The members of a scene document that are not geometry, read exactly as an explicit scene reads
// them (same defaults, same errors); absent members stay empty. Other members are not looked at:
// for documents of other forms (host/assets' mesh scenes) that share these members.
struct SceneViewFields {
  std::optional<Camera> camera;
  std::optional<Orbit> orbit;
  std::optional<Light> light;
  std::optional<glm::vec3> background;
};
SceneViewFields parse_scene_view_fields(const nlohmann::json& doc);

}  // namespace seamcl
