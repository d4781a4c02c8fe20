#include <seamcl/eval/compare_memory.h>

#include <algorithm>
#include <stdexcept>

#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {
namespace {

size_t add(size_t a, size_t b) { return saturating_add(a, b); }
size_t mul(size_t a, size_t b) { return saturating_mul(a, b); }

// What a phase of one Renderer holds at most: the largest packing, each frame buffer at its max.
struct PhaseDevice {
  size_t scene = 0, constants = 0, setups = 0, tiles = 0, tile_lists = 0, tile_lists_bound = 0, samples = 0, image = 0,
         seam_mask = 0;
  void include(const RenderMemory& m) {
    scene = std::max(scene, m.scene_device_bytes());
    constants = std::max(constants, m.constants);
    setups = std::max(setups, m.setups);
    tiles = std::max(tiles, m.tiles);
    tile_lists = std::max(tile_lists, m.tile_lists);
    tile_lists_bound = std::max(tile_lists_bound, m.tile_lists_bound);
    samples = std::max(samples, m.samples);
    image = std::max(image, m.image);
    seam_mask = std::max(seam_mask, m.seam_mask);
  }
  // The scene's buffers only: a packing held over from an earlier phase.
  void include_scene(const RenderMemory& m) {
    scene = std::max(scene, m.scene_device_bytes());
    constants = std::max(constants, m.constants);
  }
  size_t bytes(bool bound) const {
    return add(add(add(scene, constants), add(setups, tiles)),
               add(add(bound ? tile_lists_bound : tile_lists, samples), add(image, seam_mask)));
  }
};

}  // namespace

CompareMemory compare_memory(const SceneSizes& scene, const RenderOptions& frame, const std::vector<MethodEntry>& entries,
                             const ReferenceSettings& settings, const std::vector<ReferenceKind>& kinds,
                             const std::optional<SceneSizes>& seamless_scene) {
  const auto has = [&](ReferenceKind kind) { return std::find(kinds.begin(), kinds.end(), kind) != kinds.end(); };
  const bool analytic = has(ReferenceKind::Analytic);
  const bool seamless = has(ReferenceKind::Seamless);
  if (seamless && !seamless_scene) throw std::logic_error("compare_memory: the seamless reference needs its scene's sizes");
  const bool high_res = std::any_of(kinds.begin(), kinds.end(), [](ReferenceKind k) { return k != ReferenceKind::Seamless; });
  if (kinds.empty()) throw std::logic_error("compare_memory: no reference");

  CompareMemory out;
  RenderOptions face_map_options = frame;  // as render_face_map renders it
  face_map_options.msaa = 1;
  face_map_options.shading = ShadingMode::Pixel;
  out.face_map = render_memory(scene, face_map_options);
  if (high_res) out.reference = render_memory(scene, reference_render_options(frame, settings));
  if (analytic) {
    ReferenceSettings one_sample = settings;  // reference_images renders the analytic frame at 1 sample
    one_sample.msaa = 1;
    out.analytic = render_memory(scene, reference_render_options(frame, one_sample));
  }

  // Phase 0, the masks: prepare_targets' footprint masks, one per rate (footprint_seam_mask), after
  // the scene is loaded (and a face map, where one is made). They pack the adjacency, which the
  // Renderer keeps through the references and, unless a method repacks, the methods; their frame
  // buffers and the mask are released before the references.
  PhaseDevice phase0, phase1, phase3;
  RenderOptions loaded = frame;  // load_scene packs the frame's format without a band, as any method but guardband
  loaded.method = Method::Discard;
  phase0.include(render_memory(scene, loaded));
  phase0.include(out.face_map);
  size_t largest_packed = std::max(out.face_map.host_packed, out.reference.host_packed);
  for (const MethodEntry& entry : entries) {
    RenderOptions mask_options = entry.options;
    mask_options.method = Method::Black;
    const RenderMemory mask = render_memory(scene, mask_options, true);
    largest_packed = std::max(largest_packed, mask.host_packed);
    phase0.include(mask);
    phase1.include_scene(mask);
    phase3.include_scene(mask);
  }
  // Phase 1, the references.
  phase1.include(render_memory(scene, loaded));
  if (high_res) phase1.include(out.reference);
  if (analytic) phase1.include(out.analytic);
  int largest_rate = 1;
  std::vector<int> rates;
  for (const MethodEntry& entry : entries) {
    out.entries.push_back(render_memory(scene, entry.options));
    phase3.include(out.entries.back());
    RenderOptions warm_up = entry.options;  // Renderer::warm_up: one tile
    warm_up.width = SEAMCL_TILE_SIZE;
    warm_up.height = SEAMCL_TILE_SIZE;
    phase3.include(render_memory(scene, warm_up));
    largest_packed = std::max(largest_packed, out.entries.back().host_packed);
    largest_rate = std::max(largest_rate, entry.options.msaa);
    if (std::find(rates.begin(), rates.end(), entry.options.msaa) == rates.end()) rates.push_back(entry.options.msaa);
  }
  // Phase 2: the first Renderer keeps its scene (frame buffers released); the seamless one packs
  // its single face and renders the frame at each rate with discard, its buffers only growing.
  size_t phase2_device = 0;
  if (seamless) {
    RenderOptions seamless_frame = frame;
    seamless_frame.method = Method::Discard;
    seamless_frame.msaa = largest_rate;
    out.seamless = render_memory(*seamless_scene, seamless_frame);
    phase2_device = add(add(phase1.scene, phase1.constants), out.seamless.device_bytes_bound());
  }
  out.device_bytes = std::max({phase0.bytes(false), phase1.bytes(false), phase2_device, phase3.bytes(false)});
  out.device_bytes_bound = std::max({phase0.bytes(true), phase1.bytes(true), phase2_device, phase3.bytes(true)});

  const size_t pixels = mul(static_cast<size_t>(std::max(frame.width, 1)), static_cast<size_t>(std::max(frame.height, 1)));
  const size_t frame_image = mul(pixels, sizeof(glm::vec4));
  const size_t mask = pixels;  // one byte a pixel
  const size_t masks = mul(mask, std::max<size_t>(rates.size(), 1));  // one seam mask per measured rate
  // Every reference is kept at the frame's size: one per high-resolution kind, one per rate for seamless.
  const size_t high_res_kinds = static_cast<size_t>(
      std::count_if(kinds.begin(), kinds.end(), [](ReferenceKind k) { return k != ReferenceKind::Seamless; }));
  const size_t references = mul(frame_image, add(high_res_kinds, seamless ? rates.size() : 0));
  // render_face_map: its image, the winners and setups read back, the face per slot, the map.
  const size_t face_map = add(add(out.face_map.host_image, mul(pixels, sizeof(uint32_t))),
                              add(out.face_map.setups, add(mul(mul(scene.triangle_count(), SEAMCL_CLIP_SLOTS), sizeof(uint32_t)),
                                                                   mul(pixels, sizeof(int32_t)))));
  // The 8x read-back and the downsample's two frame-sized buffers; with the analytic reference,
  // also its 8x render's read-back, winners (one uint a pixel at 1 sample), setups and albedo image.
  size_t high_res_host = high_res ? add(out.reference.host_image, mul(frame_image, 2)) : 0;
  if (analytic) {
    const size_t fine_pixels = out.analytic.host_image / sizeof(glm::vec4);
    high_res_host = add(high_res_host, add(add(out.analytic.host_image, mul(fine_pixels, sizeof(uint32_t))),
                                           add(out.analytic.setups, out.analytic.host_image)));
  }
  const size_t seamless_held = seamless ? out.seamless.host_scene : 0;  // seamless_scene's result
  const size_t phase1_host = add(std::max(add(face_map, masks), add(high_res_host, add(masks, references))), seamless_held);
  // Phase 2: the seamless Scene, the second Renderer's copy and packing, one image per rate.
  const size_t phase2_host = seamless ? add(add(mul(seamless_held, 2), out.seamless.host_packed), add(masks, references)) : 0;
  size_t phase3_host = add(add(references, masks), out.entries.empty() ? 0 : frame_image);  // references, masks, a read-back
  for (size_t i = 0; i < entries.size(); ++i) phase3_host = add(phase3_host, add(frame_image, mul(pixels, sizeof(float))));
  out.host_bytes = add(add(out.face_map.host_scene, largest_packed),
                       std::max({phase1_host, phase2_host, phase3_host}));
  return out;
}

std::string compare_memory_field(const CompareMemory& memory) {
  const auto frame_buffers = [](const RenderMemory& m) { return add(add(m.samples, m.image), m.seam_mask); };
  const auto scene_part = [](const RenderMemory& m) { return add(m.scene_device_bytes(), add(m.setups, m.tile_lists)); };
  size_t scene_driven = 0, reference_frame = 0, entry_frame = 0;
  bool entry_multisampled = false;
  for (const RenderMemory* part : {&memory.face_map, &memory.reference, &memory.analytic, &memory.seamless}) {
    scene_driven = std::max(scene_driven, scene_part(*part));
    reference_frame = std::max(reference_frame, frame_buffers(*part));
  }
  for (const RenderMemory& entry : memory.entries) {
    scene_driven = std::max(scene_driven, scene_part(entry));
    if (frame_buffers(entry) > entry_frame) {
      entry_frame = frame_buffers(entry);
      entry_multisampled = entry.samples > entry.image / 4;  // a uint per sample against a float4 per pixel
    }
  }
  if (scene_driven > std::max(reference_frame, entry_frame)) return "scene";
  return entry_frame > reference_frame && entry_multisampled ? "msaa" : "size";
}

}  // namespace seamcl
