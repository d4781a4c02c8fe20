// The memory a render needs, computed from the inputs alone (no texture is built, no buffer is
// allocated), so that a service can refuse a request before any allocation. Every figure is the
// size of something the library really allocates; tests/test_budget.cpp holds them to
// PackedScene's byte counts and to Renderer::device_bytes() for many scenes, formats and bands.
//
// How exact:
// - Device bytes are exact (byte for byte what Renderer allocates: the same element counts, the
//   same one-element minimum OpenCL needs for empty arrays) for a Renderer that has loaded this
//   scene and rendered this request first, or right after release_frame_buffers(), with one
//   exception: the tile lists start at initial_tile_list_entries(triangles) entries and grow (to
//   5/4 of what the frame needed, and the frame is rendered again) when the scene's triangles
//   touch more tiles than that. `tile_lists_bound` is the upper bound after any growth: every
//   clip slot of every triangle on every tile; Renderer::set_device_byte_limit refuses growth past
//   a limit (OverBudget) instead. A Renderer that keeps its buffers between
//   requests holds, per buffer, the largest size any of them needed (the adjacency too: once a
//   request read it, it stays until a repack for one that does not).
// - Host bytes are the payload of the arrays the Renderer holds (its Scene copy, the packed
//   arrays, the read-back image): exact in element bytes; vector headers, capacity beyond size
//   and heap overhead are not counted. The caller's own Scene is not counted either
//   (scene_host_bytes() says what one costs).
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// What memory depends on in a scene, known before its textures exist (e.g. from a scene JSON):
// the vertex count and each face's level-0 texture size. Every face has the full chain down to
// 1x1 (MipChain). Sides are expected to be powers of two (validate_scene refuses others); any
// positive size is accepted here, sides below 1 count as 1, and sums saturate at SIZE_MAX rather
// than wrap, so absurd sizes give an absurd (refusable) estimate, never a small one.
struct SceneSizes {
  size_t vertices = 0;
  std::vector<std::pair<int, int>> faces;  // level-0 texture width x height, per face
  size_t reflective_faces = 0;             // faces with roughness >= 0
  int cube_size = 0;                       // the environment's cube size; 0: no environment
  // A scene whose textures are made while it is packed (Scene::texture_source) holds no float
  // texels: neither it nor the Renderer's copy of it. What it holds instead: the bytes its source
  // keeps (a deferred .ptx's whole file), and, while packing, the faces being made at once
  // (for_each_face_in_budget): the heaviest faces' texture_making_bytes, largest first, as many as
  // packing runs at once (face_workers()).
  bool deferred_textures = false;
  size_t source_bytes = 0;
  std::vector<size_t> heaviest_making;

  size_t triangle_count() const { return faces.size() * 2; }
};

SceneSizes scene_sizes(const Scene& scene);

// Packed textures in a format with a guard band (0: none): what pack_scene makes.
struct PackedTextureMemory {
  size_t levels = 0;           // mip levels of all faces (level_offsets entries)
  size_t texels = 0;           // stored texels, bands included
  size_t band_texels = 0;      // of those, the ones in guard bands
  size_t texture_bytes = 0;    // == PackedScene::texture_bytes()
  size_t padding_bytes = 0;    // == PackedScene::padding_bytes() (part of texture_bytes)
  size_t adjacency_bytes = 0;  // == PackedScene::adjacency_bytes() of pack_scene(scene, format, band);
                               // a Renderer keeps it only where it is read (RenderMemory::neighbors)
};

// Exact. Throws std::invalid_argument for a band outside 0..kMaxGuardBand, as pack_scene does.
PackedTextureMemory packed_texture_memory(const SceneSizes& scene, TexelFormat format, int guard_band);

// A figure of memory split by the request field that drives each share ("scene", "size", "msaa",
// "frames"): the field to change to need fewer of those bytes. A refusal of the figure names its
// largest share's field, so the field named and the bytes compared are the same bytes and cannot
// disagree. Sums saturate at SIZE_MAX like every figure here.
class MemoryShares {
 public:
  MemoryShares() = default;
  MemoryShares(const std::string& field, size_t bytes) { add(field, bytes); }
  void add(const std::string& field, size_t bytes);
  void add(const MemoryShares& other);
  size_t total() const;
  size_t share(const std::string& field) const;  // 0 for a field with no share
  // The field of the largest share; on a tie the one added first. Empty without any share.
  std::string field() const;
  // Takes up to `bytes` from the field's share (never below 0): bytes another figure holds too.
  void remove(const std::string& field, size_t bytes);
  const std::vector<std::pair<std::string, size_t>>& entries() const { return shares_; }

 private:
  std::vector<std::pair<std::string, size_t>> shares_;  // in the order the fields were first added
};

// The one of the two with the larger total (`a` on a tie): a run's peak is its most demanding phase.
const MemoryShares& larger(const MemoryShares& a, const MemoryShares& b);

// One render's memory, itemised. Device buffers in the order Renderer holds them.
struct RenderMemory {
  PackedTextureMemory textures;  // in the request's texel format and guard band (0 unless guardband)

  // Device: the scene, as uploaded (each buffer at least one element).
  size_t positions = 0;      // float4 per vertex
  size_t faces = 0;          // FaceGpu per face
  size_t neighbors = 0;      // FaceNeighbors per face (adjacency_bytes) for a method that reads_adjacency
                             // or a seam-mask render; one element otherwise
  size_t level_offsets = 0;  // uint per level
  size_t texels = 0;         // texture_bytes
  size_t environment = 0;    // ReflectiveFace per reflective face + the cube map's RGBA32F texels
  // Device: per Renderer, whatever the request.
  size_t constants = 0;      // sRGB table, FrameParams, FrameStats
  // Device: sized by the request (what release_frame_buffers frees).
  size_t setups = 0;         // TriangleSetup per clip slot (triangles x SEAMCL_CLIP_SLOTS)
  size_t tiles = 0;          // tile counts and offsets, and binning's per-chunk counters: uints per 16x16 tile
  size_t tile_lists = 0;     // uint per entry, initial_tile_list_entries
  size_t samples = 0;        // the winning triangle per sample: uint x width x height x msaa
  size_t image = 0;          // float4 per pixel
  size_t seam_mask = 0;      // a byte per pixel, for a render with the seam mask only
  size_t tile_lists_bound = 0;  // upper bound of tile_lists after growth (see above)

  // Host.
  // The Renderer's Scene copy: positions, faces, float RGBA texels of every level unless they are
  // deferred (scene_host_bytes), and the bytes its texture source keeps (SceneSizes::source_bytes,
  // shared with the caller's copy: counted here once).
  size_t host_scene = 0;
  size_t host_packed = 0;  // PackedScene's arrays (the device scene buffers without their minimum)
  size_t host_image = 0;   // RenderResult::pixels, float4 per pixel (and seam_mask, a byte per pixel)
  // While load_scene packs a deferred scene, before any frame buffer exists: the faces' float
  // chains being made at once (at most the packed texels' bytes, or the one heaviest face).
  size_t host_making = 0;
  // Device bytes that are host bytes too: on a device sharing the host's memory the scene buffers
  // are the packed arrays themselves (Renderer's CL_MEM_USE_HOST_PTR), counted once by process_shares.
  size_t shared_scene = 0;

  // The sums saturate at SIZE_MAX like every figure here.
  size_t scene_device_bytes() const;  // positions + faces + neighbors + level_offsets + texels + environment
  size_t frame_device_bytes() const;  // setups + tiles + tile_lists + samples + image + seam_mask
  // Exact as described above (tile lists at their initial size).
  size_t device_bytes() const;        // scene + constants + frame
  // The same with the tile lists at their bound: no render of this request can need more.
  size_t device_bytes_bound() const;
  size_t host_bytes() const;          // host_scene + host_packed + host_image + host_making

  // device_bytes() (with tile_lists_at_bound, device_bytes_bound()) split: the pixels' buffers
  // (tiles, one sample per pixel, image, seam mask) by "size", added first; the samples beyond one
  // per pixel by `multisample_field` (frame_buffers_field of the render's rate: "msaa" where the
  // request sets it; "size" for a reference, whose rate it does not); the scene's buffers,
  // constants, setups and the tile lists at their initial size (a few entries per triangle) by
  // "scene"; the lists' growth to their bound by "size": it is every slot on every tile of the
  // frame, and Renderer::render refuses that growth naming "size" too.
  MemoryShares device_shares(const std::string& multisample_field, bool tile_lists_at_bound = false) const;
  // host_bytes() split: host_image "size", then host_scene and host_packed "scene".
  MemoryShares host_shares() const;
  // What the process holds at the render's peak beyond what it held before, host and device
  // together as one memory (the figure a CPU device's render is held to, and what `render --json`
  // reports as its estimate): the scene's arrays and buffers (each shared one once, for a
  // `unified` device), then the larger of packing's faces in flight and the frame's buffers with
  // the read-back image, which never coexist (load_scene packs before the first render).
  MemoryShares process_shares(const std::string& multisample_field, bool unified) const;
};

// The request's own options decide everything: size, msaa, texels, and the guard band when the
// method is guardband (sampler_params). The scene must be non-empty in the sense of validate_scene
// only for the render itself; the estimate takes any sizes. with_seam_mask: as Renderer::render's
// (the mask's buffers and the adjacency it reads).
RenderMemory render_memory(const SceneSizes& scene, const RenderOptions& options, bool with_seam_mask = false);
RenderMemory render_memory(const Scene& scene, const RenderOptions& options, bool with_seam_mask = false);

// What the scene alone makes a render of it cost, whatever frame is asked for: the request at 1x1
// pixel without MSAA (the scene's arrays and packed textures, the setups and tile lists of its
// triangles). A budget this is over is the scene's doing, not the size's; a service checks it on
// SceneSizes from a deferred scene (GeneratorOptions::defer_textures) before anything is baked.
RenderMemory scene_render_memory(const SceneSizes& scene, const RenderOptions& options);

// What `render --json` and `compare --json` print as "estimate", the figures the run was admitted
// on: {"device_bytes", "host_bytes", "total_bytes" (device and host as one memory, each byte once),
// "unified" (the device's buffers are host memory), "total_shares": {field: bytes}}.
nlohmann::json estimate_json(const MemoryShares& device, const MemoryShares& host, const MemoryShares& total, bool unified);

// a + b and a * b, at most SIZE_MAX: budgets must never wrap to a small number.
size_t saturating_add(size_t a, size_t b);
size_t saturating_mul(size_t a, size_t b);

// What one Scene holds in memory (positions, faces, every level's float RGBA texels unless they
// are deferred): the Renderer's copy, or the caller's.
size_t scene_host_bytes(const SceneSizes& scene);

// How many faces packing makes at once (for_each_face_in_parallel's threads on this machine).
size_t face_workers();

// The peak of the faces being made at once while a deferred scene of `scene` packs into
// `packed_texture_bytes` (for_each_face_in_budget's budget): 0 for a scene of stored textures.
size_t making_bytes(const SceneSizes& scene, size_t packed_texture_bytes);

// What a loaded Scene holds while it is kept: scene_host_bytes plus the bytes its texture_source
// keeps to make deferred faces from (a deferred .ptx's whole file).
size_t scene_held_bytes(const Scene& scene);

// What this process holds, as Linux counts it: VmHWM and VmRSS of /proc/self/status (where that
// cannot be read, getrusage's ru_maxrss for the peak and 0 for the current). The peak includes the
// OpenCL runtime's own, which on PoCL is most of a small render's peak (docs/compare.md gives the
// measured floor, the quad2 render).
struct ProcessMemory {
  size_t peak_rss_bytes = 0;
  size_t rss_bytes = 0;
};
ProcessMemory process_memory();

// The machine's physical memory (sysconf), 0 when it cannot be told: what a command-line render
// may use at most, where the service has a budget of its own.
size_t physical_memory_bytes();

// The most device bytes a render may take on `device`: physical memory on a device that shares
// the host's (a CPU), else the device's global memory (0: unknown, no bound).
size_t device_memory_bound(const DeviceInfo& device);

class Renderer;

// Sets the renderer's device byte limit to device_memory_bound(device). refuse_beyond_machine
// checks a render's estimate beforehand, but a crowded frame's tile lists grow past any estimate:
// the limit refuses that growth (OverBudget "size") instead of exhausting the machine. For every
// Renderer the command line makes (the service holds its own to its per-request budget).
void limit_to_machine(Renderer& renderer, const DeviceInfo& device);

// What drives a render's samples beyond one per pixel at `msaa` samples per pixel: "msaa" above 1,
// else "size" (there are none). RenderMemory::device_shares's multisample_field for a render.
std::string frame_buffers_field(int msaa);

// OverBudget when `memory`, a render at `msaa` samples per pixel, would not fit this machine: on a
// device that shares the host's memory, device and host bytes together against
// physical_memory_bytes(); elsewhere the host bytes against it and the device bytes against the
// device's. The limit exceeded names the largest share of what it compares (device_shares with
// frame_buffers_field(msaa), host_shares), as a compare's and a bench's refusals do, so that a
// device over its memory is never blamed on the host's image. For the command line, before any
// allocation (the service has a budget of its own).
void refuse_beyond_machine(const RenderMemory& memory, int msaa, const DeviceInfo& device, const std::string& what);
// The same for a run of several renders (a compare's, a bench's) from its figures: the limit that
// is exceeded names the largest share of what it compares (device and host together on a device
// that shares the host's memory, else each figure on its own).
void refuse_beyond_machine(const MemoryShares& device_bytes, const MemoryShares& host_bytes, const DeviceInfo& device,
                           const std::string& what);

// Sets the allocator's thresholds for packing (glibc; nothing elsewhere). Blocks of 1 MiB and
// more go back to the system as soon as they are freed: glibc raises its mmap threshold to the
// largest block freed so far, so the float chains and decoded images of large deferred faces, made
// and freed one by one while packing, were kept in its arenas and held through the render, raising
// the peak RSS of scenes with large image faces (measured in docs/compare.md). Fixing that
// threshold also fixes the trim threshold at glibc's 128 KiB, so each smaller face's chain, freed
// at the top of its thread's arena, was handed back to the kernel and faulted in again for the
// next face; up to 4 MiB of free top is kept instead (docs/performance.md, "What was tried"). For a
// process's start, before any thread allocates.
void set_allocator_thresholds();
[[deprecated("use set_allocator_thresholds")]] inline void return_large_blocks_at_once() { set_allocator_thresholds(); }

// What one loaded scene costs, measured after a render: for `render --json` and the benches.
struct MeasuredMemory {
  ProcessMemory process;
  size_t packed_texels = 0;         // stored texels of every level of every face, guard bands included
  size_t packed_texel_bytes = 0;    // their bytes (PackedScene::texture_bytes)
  size_t host_packed_bytes = 0;     // every packed array the Renderer holds (texels, tables, positions, faces)
  // The Renderer's device buffers (Renderer::device_bytes). On a device sharing host memory every
  // scene buffer is the packed array itself, so these bytes overlap host_packed_bytes there.
  size_t device_bytes = 0;
  size_t scene_float_texel_bytes = 0;     // float RGBA texels the caller's Scene holds (0: deferred)
  size_t renderer_float_texel_bytes = 0;  // the same in the Renderer's copy of the scene
};

// Reads the process's memory now; the packed and device figures of the renderer's loaded scene.
MeasuredMemory measure_memory(const Scene& caller_scene, const Renderer& renderer);
// For a caller that holds no scene of its own (it handed it over: Renderer::load_scene(Scene&&)).
MeasuredMemory measure_memory(const Renderer& renderer);
// {"peak_rss_bytes", "rss_bytes", "packed_texels", "packed_texel_bytes", "host_packed_bytes",
//  "device_bytes", "scene_float_texel_bytes", "renderer_float_texel_bytes"}
nlohmann::json to_json(const MeasuredMemory& memory);

}  // namespace seamcl
