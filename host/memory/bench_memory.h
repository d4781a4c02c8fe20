// The memory of a bench (seamcl bench: an orbit, or one part of it, rendering every method x MSAA
// rate on every frame and measuring errors against each error frame's reference), computed from
// the inputs alone so that the command line can refuse a bench its machine cannot hold before
// anything is allocated, --check included. At once it holds: the face-map and reference Renderer
// (with errors: a compare's without entries, compare_memory), one Renderer per method with its
// largest entry's buffers, every entry's last two images, and the distances and seam masks pooled
// over the frames (each entry's errors on every error frame; each discard / traverse pair's
// difference on every frame of the range, without errors too), plus the largest pool's summary copies.
#pragma once
#include <cstddef>
#include <vector>

#include <seamcl/eval/comparison.h>
#include <seamcl/eval/reference.h>
#include <seamcl/memory/render_memory.h>

namespace seamcl {

// What a bench's run is made of, besides its scene, frame and entries.
struct BenchRun {
  bool with_errors = true;      // references rendered (false: --no-errors)
  int error_frames = 0;         // frames of the range measured against a reference
  size_t difference_pairs = 0;  // discard / traverse pairs at one rate, pooled on every frame
  int range_frames = 0;         // frames of the range (the part's, for --shard)
};

// Each figure split by the request field that drives it (MemoryShares), for refuse_beyond_machine
// to name the one over its limit: on the device, the Renderers' scene buffers, setups and tile
// lists "scene", their frame buffers "size" (the face map's, the references') or "msaa" (a method
// whose largest entry is at a rate above 1); on the host, the Scene copies and packings "scene",
// the read-backs and images "size", the pooled distances and masks "frames".
struct BenchMemory {
  MemoryShares device, host;
};

BenchMemory bench_memory(const SceneSizes& scene, const RenderOptions& frame, const std::vector<MethodEntry>& entries,
                         const ReferenceSettings& settings, const BenchRun& run);

}  // namespace seamcl
