#include "scene_resolution.h"

#include <algorithm>
#include <utility>

#include <seamcl/core/input_error.h>
#include <seamcl/jobs/scene_domains.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>

#include "request_hygiene.h"

namespace seamcl::server {
namespace {

using nlohmann::json;

// An inline scene with every face texture's width and height that is a power of two in 1..4096
// (what the parser accepts) replaced by 1: the same structure to validate, at no cost. Sizes the
// parser refuses are kept, so it still refuses them.
json with_tiny_textures(json scene) {
  if (!scene.is_object() || !scene.contains("faces") || !scene.at("faces").is_array()) return scene;
  for (json& face : scene.at("faces")) {
    if (!face.is_object() || !face.contains("texture") || !face.at("texture").is_object()) continue;
    json& texture = face.at("texture");
    for (const char* side : {"width", "height"}) {
      if (!texture.contains(side) || !texture.at(side).is_number_integer()) continue;
      const long long size = texture.at(side).get<long long>();
      if (size >= 1 && size <= 4096 && (size & (size - 1)) == 0) texture[side] = 1;
    }
  }
  return scene;
}

}  // namespace

std::string builtin_scene_key(const std::string& name, bool tint) { return tint ? name + "+tint" : name; }

json take_inline_scene(json& rest) {
  json scene;
  if (rest.contains("scene") && rest.at("scene").is_object()) {
    scene = rest.at("scene");
    rest.erase("scene");
  }
  return scene;
}

SceneResolver::SceneResolver(const ServerOptions& options)
    : max_inline_faces_(options.max_inline_faces),
      max_inline_texels_(options.max_inline_texels),
      max_request_host_bytes_(options.max_request_host_bytes) {
  if (!options.assets_dir.empty()) assets_ = std::make_unique<AssetDirectory>(options.assets_dir, options.asset_cache);
}

SceneResolver::~SceneResolver() = default;

json SceneResolver::assets_json() const {
  json list = json::array();
  if (assets_) {
    for (const AssetEntry& entry : assets_->list())
      list.push_back({{"name", entry.name}, {"kind", to_string(entry.kind)}, {"bytes", entry.bytes}});
  }
  return {{"enabled", assets_ != nullptr}, {"assets", list}};
}

json SceneResolver::scenes_json() const {
  json list = json::array();
  const std::string default_scene = RenderOptions{}.scene;
  for (const GeneratorInfo& g : scene_generators()) {
    const Scene& scene = *builtin_scene(g.name, false);
    list.push_back({{"name", g.name},
                    {"description", g.description},
                    {"faces", scene.faces.size()},
                    {"triangles", scene.triangle_count()},
                    {"texels", scene.texel_count()},
                    {"orbit", scene.orbit.has_value()},
                    {"domains", scene_option_domains(scene)},
                    {"default", g.name == default_scene}});
  }
  return {{"scenes", list}};
}

std::shared_ptr<const Scene> SceneResolver::builtin_scene(const std::string& name, bool tint) const {
  const std::string key = builtin_scene_key(name, tint);
  std::lock_guard lock(scenes_mutex_);
  if (const auto found = scenes_.find(key); found != scenes_.end()) return found->second;
  const auto& generators = scene_generators();
  if (std::none_of(generators.begin(), generators.end(), [&](const GeneratorInfo& g) { return g.name == name; })) return nullptr;
  GeneratorOptions generator_options;
  generator_options.tint = tint;
  // Deferred: a slot's Renderer packs each face from the generator, so no float copy of the
  // scene's textures is held for the server's life (the built-in scenes' float textures together
  // would be most of the service's memory).
  generator_options.defer_textures = true;
  auto scene = std::make_shared<const Scene>(generate_scene(name, generator_options));
  scenes_[key] = scene;
  return scene;
}

std::shared_ptr<const Scene> SceneResolver::asset_scene(const RenderOptions& options) const {
  SceneSourceOptions source;
  source.generator.tint = options.tint;
  source.generator.defer_textures = true;  // a .ptx's faces decoded while packed, not held as floats
  // A file whose texels could not fit the host budget in any packing (4 bytes each, rgba8) is
  // refused by the reader before they are decoded; a deferred file never holds them all as floats.
  // A smaller asset is measured against the budgets like any scene.
  source.ptex_limits.max_texels = std::min<uint64_t>(source.ptex_limits.max_texels, max_request_host_bytes_ / sizeof(uint32_t));
  source.displacement_map = options.displacement_map;
  return assets_->load(options.scene, options.texture, source);
}

std::shared_ptr<const Scene> SceneResolver::resolve(const json& inline_scene, RenderOptions& options,
                                                    std::string& key) const {
  key.clear();
  const bool builtin = inline_scene.is_null() && is_builtin_scene(options.scene);
  if (!options.texture.empty() && (builtin || !inline_scene.is_null()))
    throw HttpError{400, "texture", "goes with an .obj scene of the asset directory"};
  if (!options.displacement_map.empty() && (builtin || !inline_scene.is_null()))
    throw HttpError{400, "displacement_map", "goes with a scene of the asset directory"};
  if (inline_scene.is_null() && !builtin && assets_) {
    std::shared_ptr<const Scene> scene = asset_scene(options);
    options.scene = scene->name;
    return scene;
  }
  if (!options.texture.empty()) throw HttpError{400, "texture", "this server has no asset directory (seamcl serve --assets DIR)"};
  if (!options.displacement_map.empty())
    throw HttpError{400, "displacement_map", "this server has no asset directory (seamcl serve --assets DIR)"};
  if (!inline_scene.is_null()) {
    std::shared_ptr<const Scene> scene = parse_inline_scene(inline_scene, options.tint);
    options.scene = scene->name;
    return scene;
  }
  std::shared_ptr<const Scene> found =
      options.scene.find('+') == std::string::npos ? builtin_scene(options.scene, options.tint) : nullptr;
  if (!found) {
    std::string known;
    for (const GeneratorInfo& g : scene_generators()) known += (known.empty() ? "" : ", ") + g.name;
    throw HttpError{400, "scene", "unknown scene '" + options.scene + "' (built-in: " + known + "; or an inline scene object" +
                                      (assets_ ? "; or an asset (GET /v1/assets))" : ")")};
  }
  key = builtin_scene_key(options.scene, options.tint);
  return found;
}

std::shared_ptr<const Scene> SceneResolver::parse_inline_scene(const json& inline_scene, bool tint) const {
  // Its structure first, on a copy whose valid texture sizes are shrunk to 1x1 and whose
  // generator bakes nothing (so nothing big is built), so that a malformed scene is a 400
  // whatever its size; then the size limits, from the JSON, before any texture is made.
  GeneratorOptions deferred;
  deferred.defer_textures = true;
  try {
    Scene shape = parse_scene_json(with_tiny_textures(inline_scene), {}, deferred);
    validate_scene(shape);
  } catch (const InputError& e) {
    throw InputError("scene." + e.field(), input_error_message(e));
  }
  if (inline_scene.contains("faces") && inline_scene.at("faces").is_array()) {
    const json& faces = inline_scene.at("faces");
    if (faces.size() > max_inline_faces_) {
      throw HttpError{413, "scene.faces", std::to_string(faces.size()) + " faces exceed this server's limit of " +
                                              std::to_string(max_inline_faces_)};
    }
    long long texels = 0;
    for (size_t i = 0; i < faces.size(); ++i) {
      const json* texture = faces[i].is_object() && faces[i].contains("texture") ? &faces[i].at("texture") : nullptr;
      if (!texture || !texture->is_object()) continue;
      auto side = [&](const char* name) -> long long {
        if (!texture->contains(name) || !texture->at(name).is_number_integer()) return 1;
        return std::clamp<long long>(texture->at(name).get<long long>(), 1, 1 << 20);
      };
      texels += side("width") * side("height");
      if (texels > max_inline_texels_) {
        throw HttpError{413, "scene.faces[" + std::to_string(i) + "].texture",
                        "the scene's textures exceed this server's limit of " + std::to_string(max_inline_texels_) +
                            " texels at level 0"};
      }
    }
  }
  try {
    // A generator's textures deferred: the budgets are checked on the scene's sizes before any
    // texel exists, and a render packs each face's texels straight from the generator.
    GeneratorOptions generator_options = deferred;
    generator_options.tint = tint;
    Scene parsed = parse_scene_json(inline_scene, {}, generator_options);
    validate_scene(parsed);
    return std::make_shared<const Scene>(std::move(parsed));
  } catch (const InputError& e) {
    throw InputError("scene." + e.field(), input_error_message(e));
  }
}

}  // namespace seamcl::server
