// The memory of a compare (compare_methods with its seam mask and 8x reference, as `seamcl
// compare` and POST /v1/compare run it on one Renderer), computed from the inputs alone, before
// any texture or buffer exists. The parts are render_memory()s (host/memory/render_memory.h);
// the totals are over the phases of the run:
//   1. load_scene, the 1-sample face-map frame (seam mask), the 8x reference render and its
//      Mitchell downsample (with the analytic reference: the 8x frame at 1 sample, its winners
//      and setups read back and its albedo image); reference_images then releases the frame
//      buffers. With the seamless reference, its Scene (made first) is held through phase 2;
//   2. with the seamless reference: a second Renderer loads the seamless scene and renders it at
//      each measured rate, beside the first Renderer's scene;
//   3. per entry: load_scene in the entry's format, a 16x16 warm-up, `repeat` renders; each
//      entry's image and error distances are kept until the end.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <seamcl/eval/comparison.h>
#include <seamcl/eval/reference.h>
#include <seamcl/memory/render_memory.h>

namespace seamcl {

struct CompareMemory {
  RenderMemory face_map;              // the seam mask's frame: msaa 1, pixel shading
  RenderMemory reference;             // the 8x render (reference_render_options)
  RenderMemory analytic;              // the analytic reference's 8x render at 1 sample (zero without it)
  RenderMemory seamless;              // the seamless Renderer at the largest measured rate (zero without it)
  std::vector<RenderMemory> entries;  // one per method x rate

  // Upper bound of the device bytes the compare's Renderer holds at any moment: the larger
  // phase, each counted as its largest scene packing plus each frame buffer at its largest size
  // within the phase (a Renderer's frame buffers only grow until released), tile lists at their
  // initial size (see render_memory.h on their growth). It equals the Renderer's real peak when,
  // within the larger phase, one render has both the largest packing and the largest buffers
  // (phase 1 whenever the frame's method packs like the reference's, e.g. not guardband).
  size_t device_bytes = 0;
  // The same with the tile lists at their bound.
  size_t device_bytes_bound = 0;
  // Estimate of the largest host payload: the Renderer's Scene copy and packed arrays, the
  // face map and seam mask, the 8x read-back with the downsample's two frame-sized buffers
  // (phase 1), or the reference, every entry's image and distances and one read-back (phase 2).
  // Heap overhead, OpenImageIO's own working memory and the caller's Scene are not counted.
  size_t host_bytes = 0;

  // The three figures above (their totals), each split by the request field that drives it, for a
  // refusal to name the largest share of the figure it compares. A device figure is its largest
  // phase's: its frame buffers "msaa" where the render with the largest of them is at a measured
  // rate above 1 (an entry, a seam mask, the seamless reference), else "size" (the face map, the
  // 8x reference); its scene's buffers, setups and tile lists at their initial size "scene"; in
  // device_bound_shares the lists' growth to their bound "size" (RenderMemory::device_shares). The
  // host figure: the Scene copies, packing and read-back setups "scene"; images, masks,
  // references and error distances "size".
  MemoryShares device_shares, device_bound_shares, host_shares;
  // Device bytes that are host bytes too on a device sharing the host's memory: the largest
  // packing's scene buffers are its packed arrays (RenderMemory::shared_scene).
  size_t shared_scene = 0;

  // device_shares and host_shares as one memory, each shared byte once for a `unified` device:
  // what the process holds at the compare's peak beyond what it held before (the "estimate" of
  // `compare --json`). Tile lists at their initial size: a Renderer's device byte limit refuses
  // their growth past it.
  MemoryShares process_shares(bool unified) const;
};

// The sizes seamless_scene(scene) would have (one face of the combined texture), from the grid
// alone, before any texel is copied. Refuses as seamless_scene does.
SceneSizes seamless_scene_sizes(const Scene& scene);

// Assumes the references are rendered (a cache hit needs less). `kinds` are the references
// measured against (as prepare_targets takes them); `seamless_scene`, seamless_scene_sizes of the
// scene, is needed when they include the seamless one (std::logic_error without it). Throws what
// reference_render_options throws (InputError "size", "reference_method", "reference_msaa").
CompareMemory compare_memory(const SceneSizes& scene, const RenderOptions& frame, const std::vector<MethodEntry>& entries,
                             const ReferenceSettings& settings,
                             const std::vector<ReferenceKind>& kinds = {ReferenceKind::Paper},
                             const std::optional<SceneSizes>& seamless_scene = std::nullopt);

}  // namespace seamcl
