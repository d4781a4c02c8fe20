// The memory one request may need, held to this server's per-request limits before anything is
// allocated: the library estimates the figures (render_memory.h, compare_memory.h) and names what
// drives each; a figure over its limit is a 413 naming the request field to change.
#pragma once
#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/options/render_options.h>
#include <seamcl/memory/render_memory.h>

namespace seamcl {
struct Scene;
}  // namespace seamcl

namespace seamcl::server {

class RequestBudget {
 public:
  RequestBudget(size_t max_device_bytes, size_t max_host_bytes)
      : max_device_bytes_(max_device_bytes), max_host_bytes_(max_host_bytes) {}

  // 413 for a figure over its limit, naming that figure's field; `what` starts the message.
  void refuse_over(size_t device_bytes, const std::string& device_field, size_t host_bytes, const std::string& host_field,
                   const std::string& what) const;
  // For figures split by what drives them (a render's, a compare's): the limit exceeded names the
  // largest share of its own figure, as the client knows it ("texels" for a built-in scene's share).
  void refuse_over(const MemoryShares& device_bytes, const MemoryShares& host_bytes, bool builtin_scene,
                   const std::string& what) const;
  // 413 when the scene alone (scene_render_memory: at 1x1, whatever the size asked) is over the
  // budgets, naming the largest share as the above does; for an inline generator scene the
  // scene's share names its first sizing option given (scene.options.faces, else
  // scene.options.texture_scale_log2). `key` is empty unless the scene is a built-in one.
  void refuse_scene_over(const Scene& scene, const RenderOptions& options, const nlohmann::json& inline_scene,
                         const std::string& key) const;

 private:
  size_t max_device_bytes_;
  size_t max_host_bytes_;
};

}  // namespace seamcl::server
