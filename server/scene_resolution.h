// The scene a request names: a built-in one (generated on first use and kept), an asset of the
// --assets directory (names inside it only), or an inline scene object, bounded before it is
// built. Refusals are HttpError (request_hygiene.h) or InputError naming the request's field.
#pragma once
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/asset_directory.h>
#include <seamcl/options/render_options.h>

#include "http_server.h"

namespace seamcl {
struct Scene;
}  // namespace seamcl

namespace seamcl::server {

// The key of a built-in scene's Renderer in a render slot: "<name>" or "<name>+tint".
std::string builtin_scene_key(const std::string& name, bool tint);

// An inline scene object taken out of a request (the rest goes to the option parser); null when
// `scene` is a built-in name or absent.
nlohmann::json take_inline_scene(nlohmann::json& rest);

class SceneResolver {
 public:
  // Opens the asset directory when the options name one.
  explicit SceneResolver(const ServerOptions& options);
  ~SceneResolver();

  // A built-in scene by options.scene (and tint), an asset, or `inline_scene` when it is not null
  // (limits checked, parsed, validated). options.scene becomes the scene's name. `key` is the
  // slot Renderer's key (builtin_scene_key), empty for an inline scene or an asset.
  std::shared_ptr<const Scene> resolve(const nlohmann::json& inline_scene, RenderOptions& options,
                                       std::string& key) const;
  // A built-in scene ("paper", tinted or not), generated on first use; null for an unknown name.
  std::shared_ptr<const Scene> builtin_scene(const std::string& name, bool tint) const;

  // GET /v1/scenes and GET /v1/assets.
  nlohmann::json scenes_json() const;
  nlohmann::json assets_json() const;

 private:
  // An asset of the asset directory by options.scene and options.texture (400 without one).
  std::shared_ptr<const Scene> asset_scene(const RenderOptions& options) const;
  std::shared_ptr<const Scene> parse_inline_scene(const nlohmann::json& inline_scene, bool tint) const;

  size_t max_inline_faces_;
  long long max_inline_texels_;
  size_t max_request_host_bytes_;
  std::unique_ptr<AssetDirectory> assets_;  // null without --assets

  mutable std::mutex scenes_mutex_;
  mutable std::map<std::string, std::shared_ptr<const Scene>> scenes_;  // by builtin_scene_key
};

}  // namespace seamcl::server
