#include <seamcl/memory/compare_memory.h>

#include <algorithm>
#include <stdexcept>

#include <seamcl/pipeline/gpu_types.h>
#include "memory/process_overhead.h"
#include "pipeline/stages/downsample_twin.h"

namespace seamcl {

SceneSizes seamless_scene_sizes(const Scene& scene) {
  SceneSizes sizes;
  sizes.vertices = 4;
  sizes.faces = {seamless_texture_size(scene)};
  return sizes;
}

namespace {

// What a phase of one Renderer holds at most: the largest packing, each frame buffer at its max.
// The frame buffers are driven by what drives the render that needs the most of them.
struct PhaseDevice {
  size_t scene = 0, constants = 0;  // the largest packing's buffers, and the per-Renderer constants
  RenderMemory frames;              // the largest of each frame buffer (its scene buffers stay 0)
  std::string multisample_field = "size";  // of the render with the most samples
  size_t downsample = 0;                    // render_downsampled's row-pass and result buffers
  void include(const RenderMemory& m, const std::string& field) {
    if (m.samples > frames.samples) multisample_field = field;
    include_scene(m);
    frames.setups = std::max(frames.setups, m.setups);
    frames.tiles = std::max(frames.tiles, m.tiles);
    frames.tile_lists = std::max(frames.tile_lists, m.tile_lists);
    frames.tile_lists_bound = std::max(frames.tile_lists_bound, m.tile_lists_bound);
    frames.samples = std::max(frames.samples, m.samples);
    frames.image = std::max(frames.image, m.image);
    frames.seam_mask = std::max(frames.seam_mask, m.seam_mask);
  }
  // The scene's buffers only: a packing held over from an earlier phase.
  void include_scene(const RenderMemory& m) {
    scene = std::max(scene, m.scene_device_bytes());
    constants = std::max(constants, m.constants);
  }
  // Split as RenderMemory::device_shares splits one render's.
  MemoryShares shares(bool tile_lists_at_bound) const {
    MemoryShares out = frames.device_shares(multisample_field, tile_lists_at_bound);
    out.add("scene", saturating_add(scene, constants));
    out.add("size", downsample);
    return out;
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

  const size_t pixels = saturating_mul(static_cast<size_t>(std::max(frame.width, 1)), static_cast<size_t>(std::max(frame.height, 1)));
  const size_t frame_image = saturating_mul(pixels, sizeof(glm::vec4));

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
  phase0.include(render_memory(scene, loaded), "size");
  phase0.include(out.face_map, "size");
  size_t largest_packed = std::max(out.face_map.host_packed, out.reference.host_packed);
  for (const MethodEntry& entry : entries) {
    RenderOptions mask_options = entry.options;
    mask_options.method = Method::Black;
    const RenderMemory mask = render_memory(scene, mask_options, true);
    largest_packed = std::max(largest_packed, mask.host_packed);
    phase0.include(mask, frame_buffers_field(entry.options.msaa));
    phase1.include_scene(mask);
    phase3.include_scene(mask);
  }
  // Phase 1, the references.
  phase1.include(render_memory(scene, loaded), "size");
  if (high_res) {
    phase1.include(out.reference, "size");
    // The row pass keeps the 8x frame's height at the frame's width; the result is frame-sized;
    // the taps' weights are the largest filter's.
    size_t weights = 0;
    for (ReferenceKind kind : kinds) {
      if (kind == ReferenceKind::Box) weights = std::max(weights, box_taps().weights.size());
      if (kind == ReferenceKind::Paper) weights = std::max(weights, mitchell_taps().weights.size());
    }
    phase1.downsample = saturating_add(saturating_mul(frame_image, kReferenceScale + 1), saturating_mul(weights, sizeof(float)));
  }
  if (analytic) phase1.include(out.analytic, "size");
  int largest_rate = 1;
  std::vector<int> rates;
  for (const MethodEntry& entry : entries) {
    out.entries.push_back(render_memory(scene, entry.options));
    phase3.include(out.entries.back(), frame_buffers_field(entry.options.msaa));
    RenderOptions warm_up = entry.options;  // Renderer::warm_up: one tile
    warm_up.width = SEAMCL_TILE_SIZE;
    warm_up.height = SEAMCL_TILE_SIZE;
    phase3.include(render_memory(scene, warm_up), frame_buffers_field(entry.options.msaa));
    largest_packed = std::max(largest_packed, out.entries.back().host_packed);
    largest_rate = std::max(largest_rate, entry.options.msaa);
    if (std::find(rates.begin(), rates.end(), entry.options.msaa) == rates.end()) rates.push_back(entry.options.msaa);
  }
  // Phase 2: the first Renderer keeps its scene (frame buffers released); the seamless one packs
  // its single face and renders the frame at each rate with discard, its buffers only growing.
  MemoryShares phase2_device;
  if (seamless) {
    RenderOptions seamless_frame = frame;
    seamless_frame.method = Method::Discard;
    seamless_frame.msaa = largest_rate;
    out.seamless = render_memory(*seamless_scene, seamless_frame);
    phase2_device = out.seamless.device_shares(frame_buffers_field(largest_rate), true);
    phase2_device.add("scene", saturating_add(phase1.scene, phase1.constants));
  }
  const auto largest_phase = [&](bool tile_lists_at_bound) {
    return larger(larger(phase0.shares(tile_lists_at_bound), phase1.shares(tile_lists_at_bound)),
                  larger(phase2_device, phase3.shares(tile_lists_at_bound)));
  };
  out.device_shares = largest_phase(false);
  out.device_bound_shares = largest_phase(true);
  out.device_bytes = out.device_shares.total();
  out.device_bytes_bound = out.device_bound_shares.total();

  const size_t mask = pixels;  // one byte a pixel
  const size_t masks = saturating_mul(mask, std::max<size_t>(rates.size(), 1));  // one seam mask per measured rate
  // Every reference is kept at the frame's size: one per high-resolution kind, one per rate for seamless.
  const size_t high_res_kinds = static_cast<size_t>(
      std::count_if(kinds.begin(), kinds.end(), [](ReferenceKind k) { return k != ReferenceKind::Seamless; }));
  const size_t references = saturating_mul(frame_image, saturating_add(high_res_kinds, seamless ? rates.size() : 0));
  // render_face_map: its image, the winners and setups read back, the face per slot, the map.
  MemoryShares face_map(
      "size", saturating_add(saturating_add(out.face_map.host_image, saturating_mul(pixels, sizeof(uint32_t))), saturating_mul(pixels, sizeof(int32_t))));
  face_map.add("scene", saturating_add(out.face_map.setups, saturating_mul(saturating_mul(scene.triangle_count(), SEAMCL_CLIP_SLOTS), sizeof(uint32_t))));
  face_map.add("size", masks);
  // The device reduces the 8x frame (render_downsampled): its read-back is frame-sized, kept once
  // and copied to each kind. The analytic reference reads back its 8x render, the winners (one
  // uint a pixel at 1 sample), the setups, and makes an albedo image of the 8x frame.
  MemoryShares high_res_host("size", saturating_add(masks, references));
  if (high_res) high_res_host.add("size", saturating_mul(frame_image, 2));
  if (analytic) {
    const size_t fine_pixels = out.analytic.host_image / sizeof(glm::vec4);
    high_res_host.add("size", saturating_add(saturating_mul(out.analytic.host_image, 2), saturating_mul(fine_pixels, sizeof(uint32_t))));
    high_res_host.add("scene", out.analytic.setups);
  }
  const size_t seamless_held = seamless ? out.seamless.host_scene : 0;  // seamless_scene's result
  MemoryShares phase1_host = larger(face_map, high_res_host);
  phase1_host.add("scene", seamless_held);
  // Phase 2: the seamless Scene, the second Renderer's copy and packing, one image per rate.
  MemoryShares phase2_host;
  if (seamless) {
    phase2_host.add("size", saturating_add(masks, references));
    phase2_host.add("scene", saturating_add(saturating_mul(seamless_held, 2), out.seamless.host_packed));
  }
  MemoryShares phase3_host("size", saturating_add(saturating_add(references, masks), out.entries.empty() ? 0 : frame_image));  // and a read-back
  for (size_t i = 0; i < entries.size(); ++i) phase3_host.add("size", saturating_add(frame_image, saturating_mul(pixels, sizeof(float))));
  out.host_shares = larger(larger(phase1_host, phase2_host), phase3_host);
  out.host_shares.add("scene", saturating_add(out.face_map.host_scene, largest_packed));  // the Renderer's Scene copy and packing
  // Each load_scene of a deferred scene makes its faces again while it packs (RenderMemory::host_making).
  size_t making = std::max(out.face_map.host_making, out.reference.host_making);
  for (const RenderMemory& entry : out.entries) making = std::max(making, entry.host_making);
  out.host_shares.add("scene", making);
  out.host_bytes = out.host_shares.total();
  out.shared_scene = std::min(std::max({phase0.scene, phase1.scene, phase3.scene}), largest_packed);
  return out;
}

MemoryShares CompareMemory::process_shares(bool unified) const {
  MemoryShares together = device_shares;
  together.add(host_shares);
  if (unified) together.remove("scene", shared_scene);
  add_process_overhead(together);
  return together;
}

}  // namespace seamcl
