// Scenes from JSON files; the format is documented in docs/scene-format.md. Every error is an
// InputError whose field is the JSON path of the value at fault (e.g. "faces[2].texture.width").
#pragma once
#include <nlohmann/json_fwd.hpp>
#include <string>

#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

// Either a generator reference ({"generator": ..., "options": ...}) or an explicit scene.
// The result has passed validate_scene.
Scene parse_scene_json(const nlohmann::json& doc);

// Reads and parses a scene file. An unreadable file or bad JSON syntax is InputError("scene", ...)
// naming the path and the parse error; errors in the content keep their JSON path as the field.
// An explicit scene without "name" is named after the file.
Scene load_scene_file(const std::string& path);

// A built-in scene name, else a scene file (a path that ends in .json or exists). `options`
// apply on top of the scene's own: for a generator file, tint if either asks and the caller's
// constant colour over the file's; for an explicit scene, as apply_generator_options.
Scene load_scene(const std::string& name_or_path, const GeneratorOptions& options);

}  // namespace seamcl
