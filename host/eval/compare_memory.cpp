#include <seamcl/eval/compare_memory.h>

#include <algorithm>

#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {
namespace {

size_t add(size_t a, size_t b) { return saturating_add(a, b); }
size_t mul(size_t a, size_t b) { return saturating_mul(a, b); }

// What a phase of one Renderer holds at most: the largest packing, each frame buffer at its max.
struct PhaseDevice {
  size_t scene = 0, constants = 0, setups = 0, tiles = 0, tile_lists = 0, tile_lists_bound = 0, samples = 0, image = 0;
  void include(const RenderMemory& m) {
    scene = std::max(scene, m.scene_device_bytes());
    constants = std::max(constants, m.constants);
    setups = std::max(setups, m.setups);
    tiles = std::max(tiles, m.tiles);
    tile_lists = std::max(tile_lists, m.tile_lists);
    tile_lists_bound = std::max(tile_lists_bound, m.tile_lists_bound);
    samples = std::max(samples, m.samples);
    image = std::max(image, m.image);
  }
  size_t bytes(bool bound) const {
    return add(add(add(scene, constants), add(setups, tiles)),
               add(add(bound ? tile_lists_bound : tile_lists, samples), image));
  }
};

}  // namespace

CompareMemory compare_memory(const SceneSizes& scene, const RenderOptions& frame, const std::vector<MethodEntry>& entries,
                             const ReferenceSettings& settings) {
  CompareMemory out;
  RenderOptions face_map_options = frame;  // as render_face_map renders it
  face_map_options.msaa = 1;
  face_map_options.shading = ShadingMode::Pixel;
  out.face_map = render_memory(scene, face_map_options);
  out.reference = render_memory(scene, reference_render_options(frame, settings));

  PhaseDevice phase1;
  RenderOptions loaded = frame;  // load_scene packs the frame's format without a band, as any method but guardband
  loaded.method = Method::Discard;
  phase1.include(render_memory(scene, loaded));
  phase1.include(out.face_map);
  phase1.include(out.reference);
  PhaseDevice phase2;
  size_t largest_packed = std::max(out.face_map.host_packed, out.reference.host_packed);
  for (const MethodEntry& entry : entries) {
    out.entries.push_back(render_memory(scene, entry.options));
    phase2.include(out.entries.back());
    RenderOptions warm_up = entry.options;  // Renderer::warm_up: one tile
    warm_up.width = SEAMCL_TILE_SIZE;
    warm_up.height = SEAMCL_TILE_SIZE;
    phase2.include(render_memory(scene, warm_up));
    largest_packed = std::max(largest_packed, out.entries.back().host_packed);
  }
  out.device_bytes = std::max(phase1.bytes(false), phase2.bytes(false));
  out.device_bytes_bound = std::max(phase1.bytes(true), phase2.bytes(true));

  const size_t pixels = mul(static_cast<size_t>(std::max(frame.width, 1)), static_cast<size_t>(std::max(frame.height, 1)));
  const size_t frame_image = mul(pixels, sizeof(glm::vec4));
  const size_t mask = pixels;  // one byte a pixel
  // render_face_map: its image, the winners and setups read back, the face per slot, the map.
  const size_t face_map = add(add(out.face_map.host_image, mul(pixels, sizeof(uint32_t))),
                              add(out.face_map.setups, add(mul(mul(scene.triangle_count(), SEAMCL_CLIP_SLOTS), sizeof(uint32_t)),
                                                                   mul(pixels, sizeof(int32_t)))));
  const size_t phase1_host = std::max(add(face_map, mask), add(add(out.reference.host_image, mul(frame_image, 2)), mask));
  size_t phase2_host = add(add(frame_image, mask), out.entries.empty() ? 0 : frame_image);  // reference, mask, a read-back
  for (size_t i = 0; i < entries.size(); ++i) phase2_host = add(phase2_host, add(frame_image, mul(pixels, sizeof(float))));
  out.host_bytes = add(add(out.reference.host_scene, largest_packed), std::max(phase1_host, phase2_host));
  return out;
}

}  // namespace seamcl
