#include "request_budget.h"

#include <cstdio>

#include <seamcl/scene/scene.h>

#include "request_hygiene.h"

namespace seamcl::server {
namespace {

using nlohmann::json;

std::string mebibytes(size_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1 << 20));
  return text;
}

// The request field to change when the library names what drives a figure: a built-in scene
// cannot be changed by the client, but its texel format can (`texels`); an inline scene or an
// asset is the client's own (`scene`), held to the budgets as one.
std::string budget_field(const std::string& library_field, bool builtin_scene) {
  return library_field == "scene" && builtin_scene ? "texels" : library_field;
}

}  // namespace

void RequestBudget::refuse_over(size_t device_bytes, const std::string& device_field, size_t host_bytes,
                                const std::string& host_field, const std::string& what) const {
  if (device_bytes > max_device_bytes_) {
    throw HttpError{413, device_field,
                    what + " needs about " + mebibytes(device_bytes) + " of device memory, over this server's limit of " +
                        mebibytes(max_device_bytes_) + " per request"};
  }
  if (host_bytes > max_host_bytes_) {
    throw HttpError{413, host_field,
                    what + " needs about " + mebibytes(host_bytes) + " of host memory, over this server's limit of " +
                        mebibytes(max_host_bytes_) + " per request"};
  }
}

void RequestBudget::refuse_over(const MemoryShares& device_bytes, const MemoryShares& host_bytes, bool builtin_scene,
                                const std::string& what) const {
  refuse_over(device_bytes.total(), budget_field(device_bytes.field(), builtin_scene), host_bytes.total(),
              budget_field(host_bytes.field(), builtin_scene), what);
}

void RequestBudget::refuse_scene_over(const Scene& scene, const RenderOptions& options, const json& inline_scene,
                                      const std::string& key) const {
  const bool builtin_scene = !key.empty();
  const SceneSizes sizes = scene_sizes(scene);
  const RenderMemory memory = scene_render_memory(sizes, options);
  const MemoryShares device = memory.device_shares(frame_buffers_field(1));  // scene_render_memory: one sample
  MemoryShares host = memory.host_shares();
  // The request holds its own copy of an inline scene or asset on top of the Renderer's (what its
  // texture_source keeps, a deferred .ptx's bytes, is shared by the copies: host_scene counts it).
  host.add("scene", builtin_scene ? 0 : scene_host_bytes(sizes));
  std::string device_field = budget_field(device.field(), builtin_scene), host_field = budget_field(host.field(), builtin_scene);
  // An inline generator's sizing options: the field is the first given, the message names them all.
  std::string sized_by;
  if (const auto given = inline_scene.is_object() ? inline_scene.find("options") : inline_scene.end();
      !inline_scene.is_null() && given != inline_scene.end() && given->is_object()) {
    for (const char* option : {"faces", "texture_scale_log2"})
      if (given->contains(option)) {
        const std::string field = std::string("scene.options.") + option;
        if (sized_by.empty()) {
          if (device_field == "scene") device_field = field;
          if (host_field == "scene") host_field = field;
        }
        sized_by += (sized_by.empty() ? ", sized by " : " and ") + field;
      }
  }
  refuse_over(device.total(), device_field, host.total(), host_field,
              "the scene (" + std::to_string(sizes.faces.size()) + " faces, " +
                  std::to_string(memory.textures.texels) + " packed texels" + sized_by + ")");
}

}  // namespace seamcl::server
