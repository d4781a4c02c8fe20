#include <seamcl/memory/bench_memory.h>

#include <algorithm>
#include <map>
#include <string>

#include <glm/glm.hpp>

#include <seamcl/memory/compare_memory.h>

namespace seamcl {

BenchMemory bench_memory(const SceneSizes& scene, const RenderOptions& frame, const std::vector<MethodEntry>& entries,
                         const ReferenceSettings& settings, const BenchRun& run) {
  BenchMemory out;
  if (run.with_errors) {
    const CompareMemory references = compare_memory(scene, frame, {}, settings);
    out.device = references.device_shares;
    out.host = references.host_shares;
  } else {
    RenderOptions face_map = frame;  // as render_face_map renders it
    face_map.msaa = 1;
    face_map.shading = ShadingMode::Pixel;
    const RenderMemory m = render_memory(scene, face_map);
    out.device = m.device_shares("size");
    out.host = m.host_shares();
  }
  struct Held {
    RenderMemory memory;
    int msaa = 1;
  };
  std::map<std::string, Held> largest_per_method;
  for (const MethodEntry& entry : entries) {
    const RenderMemory m = render_memory(scene, entry.options);
    const auto [held, inserted] = largest_per_method.try_emplace(entry.method_name, Held{m, entry.options.msaa});
    if (!inserted && m.device_bytes() > held->second.memory.device_bytes()) held->second = {m, entry.options.msaa};
  }
  for (const auto& [method, held] : largest_per_method) {
    out.device.add(held.memory.device_shares(frame_buffers_field(held.msaa)));
    out.host.add(held.memory.host_shares());
  }
  const size_t pixels = saturating_mul(static_cast<size_t>(std::max(frame.width, 1)), static_cast<size_t>(std::max(frame.height, 1)));
  out.host.add("size", saturating_mul(saturating_mul(pixels, 2 * sizeof(glm::vec4)), entries.size()));
  const size_t pooled_bytes = sizeof(float) + 1;  // a distance and a mask byte per pixel and frame
  const size_t error_frames = static_cast<size_t>(std::max(run.error_frames, 0));
  const size_t range_frames = static_cast<size_t>(std::max(run.range_frames, 0));
  const size_t error_pools = saturating_mul(saturating_mul(pixels, pooled_bytes), saturating_mul(entries.size(), error_frames));
  const size_t difference_pools =
      saturating_mul(saturating_mul(pixels, pooled_bytes), saturating_mul(run.difference_pairs, range_frames));
  // Pool::stats copies the largest pool's seam and off-seam masks.
  const size_t summary = saturating_mul(saturating_mul(pixels, 2), std::max(error_frames, run.difference_pairs > 0 ? range_frames : 0));
  out.host.add("frames", saturating_add(error_pools, saturating_add(difference_pools, summary)));
  return out;
}

}  // namespace seamcl
