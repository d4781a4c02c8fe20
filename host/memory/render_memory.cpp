#include <seamcl/memory/render_memory.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <seamcl/core/over_budget.h>
#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/packed_cube.h>
#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/pipeline/renderer.h>
#include "memory/process_overhead.h"
#include "pipeline/frame_params.h"
#include "scene/budgeted_faces.h"

#include <sys/resource.h>
#include <unistd.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <fstream>
#include <sstream>
#include <string>

namespace seamcl {
namespace {

size_t add(size_t a, size_t b) { return saturating_add(a, b); }
size_t mul(size_t a, size_t b) { return saturating_mul(a, b); }

// The level sizes of a full chain (MipChain): halve each side, a side stops at 1, down to 1x1.
template <typename Visit>
void for_each_level(int width, int height, Visit visit) {
  size_t w = static_cast<size_t>(std::max(width, 1)), h = static_cast<size_t>(std::max(height, 1));
  for (;;) {
    visit(w, h);
    if (w == 1 && h == 1) return;
    w = std::max<size_t>(w / 2, 1);
    h = std::max<size_t>(h / 2, 1);
  }
}

// A device buffer of `count` elements: OpenCL refuses zero bytes, so Renderer allocates one.
size_t device_array(size_t count, size_t element_bytes) { return mul(std::max<size_t>(count, 1), element_bytes); }

}  // namespace

size_t saturating_add(size_t a, size_t b) {
  constexpr size_t kMax = std::numeric_limits<size_t>::max();
  return a > kMax - b ? kMax : a + b;
}

size_t saturating_mul(size_t a, size_t b) {
  constexpr size_t kMax = std::numeric_limits<size_t>::max();
  return (a != 0 && b > kMax / a) ? kMax : a * b;
}

void MemoryShares::add(const std::string& field, size_t bytes) {
  for (auto& [name, share] : shares_) {
    if (name == field) {
      share = saturating_add(share, bytes);
      return;
    }
  }
  shares_.emplace_back(field, bytes);
}

void MemoryShares::add(const MemoryShares& other) {
  for (const auto& [name, share] : other.shares_) add(name, share);
}

size_t MemoryShares::total() const {
  size_t sum = 0;
  for (const auto& entry : shares_) sum = saturating_add(sum, entry.second);
  return sum;
}

size_t MemoryShares::share(const std::string& field) const {
  for (const auto& [name, share] : shares_)
    if (name == field) return share;
  return 0;
}

std::string MemoryShares::field() const {
  const std::pair<std::string, size_t>* largest = nullptr;
  for (const auto& entry : shares_)
    if (largest == nullptr || entry.second > largest->second) largest = &entry;
  return largest ? largest->first : std::string();
}

void MemoryShares::remove(const std::string& field, size_t bytes) {
  for (auto& [name, share] : shares_)
    if (name == field) share -= std::min(share, bytes);
}

nlohmann::json estimate_json(const MemoryShares& device, const MemoryShares& host, const MemoryShares& total, bool unified) {
  nlohmann::json shares = nlohmann::json::object();
  for (const auto& [field, bytes] : total.entries()) shares[field] = bytes;
  return {{"device_bytes", device.total()}, {"host_bytes", host.total()}, {"total_bytes", total.total()},
          {"unified", unified}, {"total_shares", shares}};
}

const MemoryShares& larger(const MemoryShares& a, const MemoryShares& b) { return b.total() > a.total() ? b : a; }

size_t RenderMemory::scene_device_bytes() const {
  return add(add(add(add(positions, faces), add(neighbors, level_offsets)), texels), environment);
}
size_t RenderMemory::frame_device_bytes() const {
  return add(add(add(setups, tiles), add(tile_lists, samples)), add(image, seam_mask));
}
size_t RenderMemory::device_bytes() const { return add(add(scene_device_bytes(), constants), frame_device_bytes()); }
size_t RenderMemory::device_bytes_bound() const {
  return add(add(scene_device_bytes(), constants),
             add(add(add(setups, tiles), add(tile_lists_bound, samples)), add(image, seam_mask)));
}
size_t RenderMemory::host_bytes() const { return add(add(add(host_scene, host_packed), host_image), host_making); }

MemoryShares RenderMemory::device_shares(const std::string& multisample_field, bool tile_lists_at_bound) const {
  // One sample per pixel grows with the size, as the image does; only the samples beyond it are
  // what a lower sample count gives back.
  const size_t one_sample_per_pixel = std::min(samples, image / (sizeof(cl_float4) / sizeof(cl_uint)));
  MemoryShares shares("size", add(add(tiles, one_sample_per_pixel), add(image, seam_mask)));
  shares.add(multisample_field, samples - one_sample_per_pixel);
  shares.add("scene", add(add(scene_device_bytes(), constants), add(setups, tile_lists)));
  if (tile_lists_at_bound && tile_lists_bound > tile_lists) shares.add("size", tile_lists_bound - tile_lists);
  return shares;
}

MemoryShares RenderMemory::host_shares() const {
  MemoryShares shares("size", host_image);
  shares.add("scene", add(add(host_scene, host_packed), host_making));
  return shares;
}

MemoryShares RenderMemory::process_shares(const std::string& multisample_field, bool unified) const {
  const size_t scene_buffers = add(scene_device_bytes(), constants);
  const size_t shared = unified ? std::min(shared_scene, scene_buffers) : 0;
  MemoryShares held("scene", add(add(host_scene, host_packed), scene_buffers - shared));
  RenderMemory frame_only = *this;  // device_shares of the frame's buffers alone
  frame_only.positions = frame_only.faces = frame_only.neighbors = frame_only.level_offsets = frame_only.texels =
      frame_only.environment = frame_only.constants = 0;
  MemoryShares rendering = frame_only.device_shares(multisample_field);
  rendering.add("size", host_image);
  held.add(larger(rendering, MemoryShares("scene", host_making)));
  add_process_overhead(held);
  return held;
}

void add_process_overhead(MemoryShares& figure) {
  // RSS beyond the arrays and buffers themselves: allocator and driver bookkeeping, page rounding,
  // the packing threads' arenas. Without this share tests/estimate_table.py found renders growing
  // by a little more than their exact buffers (docs/compare.md has the figures).
  figure.add(figure.field(), figure.total() / 64);
}

SceneSizes scene_sizes(const Scene& scene) {
  SceneSizes sizes;
  sizes.vertices = scene.positions.size();
  sizes.faces.reserve(scene.faces.size());
  for (const Face& face : scene.faces) {
    sizes.faces.emplace_back(face.texture.width(), face.texture.height());
    if (face.roughness >= 0.0f) ++sizes.reflective_faces;
  }
  sizes.cube_size = scene.environment ? scene.environment->cube_size : 0;
  sizes.deferred_textures = has_deferred_textures(scene);
  sizes.source_bytes = scene.texture_source_bytes;
  if (sizes.deferred_textures) {
    std::vector<size_t> making(scene.faces.size());
    for (size_t f = 0; f < making.size(); ++f) making[f] = texture_making_bytes(scene, f);
    const size_t kept = std::min<size_t>(making.size(), face_threads());
    std::partial_sort(making.begin(), making.begin() + static_cast<std::ptrdiff_t>(kept), making.end(), std::greater<>());
    making.resize(kept);
    sizes.heaviest_making = std::move(making);
  }
  return sizes;
}

size_t face_workers() { return face_threads(); }

size_t making_bytes(const SceneSizes& scene, size_t packed_texture_bytes) {
  // for_each_face_in_budget: faces start while those running weigh at most the budget together,
  // or alone; at most face_workers() run at once.
  size_t together = 0, heaviest = 0;
  for (size_t i = 0; i < scene.heaviest_making.size() && i < face_workers(); ++i) {
    together = add(together, scene.heaviest_making[i]);
    heaviest = std::max(heaviest, scene.heaviest_making[i]);
  }
  return std::max(heaviest, std::min(together, packed_texture_bytes));
}

PackedTextureMemory packed_texture_memory(const SceneSizes& scene, TexelFormat format, int guard_band) {
  if (guard_band < 0 || guard_band > kMaxGuardBand) throw std::invalid_argument("guard band out of range");
  PackedTextureMemory m;
  const size_t band = static_cast<size_t>(guard_band);
  for (const auto& [width, height] : scene.faces) {
    for_each_level(width, height, [&](size_t w, size_t h) {
      const size_t own = mul(w, h);
      const size_t stored = mul(add(w, 2 * band), add(h, 2 * band));
      m.levels = add(m.levels, 1);
      m.texels = add(m.texels, stored);
      m.band_texels = add(m.band_texels, stored - own);
    });
  }
  const size_t texel_bytes = format == TexelFormat::Rgba8 ? sizeof(uint32_t) : 4 * sizeof(float);
  m.texture_bytes = mul(m.texels, texel_bytes);
  m.padding_bytes = mul(m.band_texels, texel_bytes);
  m.adjacency_bytes = mul(scene.faces.size(), sizeof(FaceNeighbors));
  return m;
}

size_t scene_host_bytes(const SceneSizes& scene) {
  size_t bytes = add(mul(scene.vertices, sizeof(glm::vec3)), mul(scene.faces.size(), sizeof(Face)));
  const size_t texel_bytes = scene.deferred_textures ? 0 : sizeof(glm::vec4);
  for (const auto& [width, height] : scene.faces) {
    for_each_level(width, height, [&](size_t w, size_t h) {
      bytes = add(bytes, add(sizeof(TextureLevel), mul(mul(w, h), texel_bytes)));
    });
  }
  return bytes;
}

size_t scene_held_bytes(const Scene& scene) { return add(scene_host_bytes(scene_sizes(scene)), scene.texture_source_bytes); }

RenderMemory render_memory(const SceneSizes& scene, const RenderOptions& options, bool with_seam_mask) {
  RenderMemory m;
  m.textures = packed_texture_memory(scene, options.texels, sampler_params(options).guard_band);

  const size_t faces = scene.faces.size();
  m.positions = device_array(scene.vertices, sizeof(cl_float4));
  m.faces = device_array(faces, sizeof(FaceGpu));
  const size_t adjacency_faces = reads_adjacency(options.method) || with_seam_mask ? faces : 0;
  m.neighbors = device_array(adjacency_faces, sizeof(FaceNeighbors));
  m.level_offsets = device_array(m.textures.levels, sizeof(uint32_t));
  m.texels = device_array(m.textures.texels, options.texels == TexelFormat::Rgba8 ? sizeof(uint32_t) : 4 * sizeof(float));
  // cube-border's faces carry a one-texel border at every level.
  const size_t cube_texels = cube_texel_count(scene.cube_size, cube_preparation(options.cube_method).border);
  m.environment = add(device_array(scene.reflective_faces, sizeof(ReflectiveFace)),
                      device_array(mul(cube_texels, 4), sizeof(float)));

  m.constants = 256 * sizeof(float) + sizeof(FrameParams) + sizeof(FrameStats);

  const size_t width = static_cast<size_t>(std::max(options.width, 1));
  const size_t height = static_cast<size_t>(std::max(options.height, 1));
  const size_t pixels = mul(width, height);
  const size_t tile_count = mul((width + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE, (height + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE);
  // A displacement render sets up T^2 micro-triangles per triangle (kernels/tessellate.cl), and
  // holds the tessellated vertices (32 bytes each) and their normals (16 bytes each), counted with
  // the setups, and the corner table (a uint per mesh vertex and per patch corner).
  const size_t tess = options.displacement ? static_cast<size_t>(std::max(options.tessellation, 1)) : 1;
  const size_t slots = mul(mul(scene.triangle_count(), mul(tess, tess)), SEAMCL_CLIP_SLOTS);
  m.setups = device_array(slots, sizeof(TriangleSetup));
  // and how many slots setup wrote per input triangle (Renderer's slot_counts, a uint each).
  m.setups = add(m.setups, device_array(slots / SEAMCL_CLIP_SLOTS, sizeof(cl_uint)));
  if (options.displacement) {
    m.setups = add(m.setups, mul(mul(faces, mul(tess + 1, tess + 1)), 32 + 16));
    m.setups = add(m.setups, mul(add(add(scene.vertices, 1), mul(faces, 4)), sizeof(cl_uint)));
  }
  // Tile counts and offsets, and binning's counters: one per tile for each chunk of input triangles.
  const size_t chunks = std::max<size_t>(bin_chunks(slots / SEAMCL_CLIP_SLOTS, tile_count).chunks, 1);
  m.tiles = mul(mul(2 + chunks, sizeof(cl_uint)), tile_count);
  const size_t initial_entries = initial_tile_list_entries(scene.triangle_count());
  // A list entry: the slot (uint) and its rows in the tile (Renderer's tile_entry_rows, a ushort).
  constexpr size_t entry_bytes = sizeof(cl_uint) + sizeof(cl_ushort);
  m.tile_lists = mul(initial_entries, entry_bytes);
  m.samples = device_array(mul(pixels, static_cast<size_t>(std::max(options.msaa, 1))), sizeof(cl_uint));
  m.image = device_array(pixels, sizeof(cl_float4));
  m.seam_mask = with_seam_mask ? device_array(pixels, sizeof(cl_uchar)) : 0;
  // Render grows the lists to bin_entries * 5/4 + 1024 (at most 2^31), and bin_entries is at most
  // one per slot per tile.
  const size_t grown_entries = std::min<size_t>(add(mul(mul(slots, tile_count) / 4 + 1, 5), 1024), size_t{1} << 31);
  m.tile_lists_bound = mul(std::max(initial_entries, grown_entries), entry_bytes);

  m.host_scene = add(scene_host_bytes(scene), scene.source_bytes);
  m.host_packed = add(add(mul(scene.vertices, sizeof(cl_float4)),
                          add(mul(faces, sizeof(FaceGpu)), mul(adjacency_faces, sizeof(FaceNeighbors)))),
                      add(add(mul(m.textures.levels, sizeof(uint32_t)), m.textures.texture_bytes),
                          add(mul(scene.reflective_faces, sizeof(ReflectiveFace)), mul(cube_texels, 4 * sizeof(float)))));
  m.host_image = add(mul(pixels, sizeof(glm::vec4)), with_seam_mask ? pixels : 0);
  m.host_making = making_bytes(scene, m.textures.texture_bytes);
  // Every scene buffer but the constants is upload_shared from a packed array (positions as float4).
  m.shared_scene = m.scene_device_bytes();
  return m;
}

RenderMemory render_memory(const Scene& scene, const RenderOptions& options, bool with_seam_mask) {
  return render_memory(scene_sizes(scene), options, with_seam_mask);
}

RenderMemory scene_render_memory(const SceneSizes& scene, const RenderOptions& options) {
  RenderOptions smallest = options;
  smallest.width = smallest.height = smallest.msaa = 1;
  return render_memory(scene, smallest);
}

namespace {

// "VmHWM:     123456 kB" -> bytes; 0 when the line is not there.
size_t status_kilobytes(const std::string& status, const std::string& key) {
  std::istringstream lines(status);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(key + ":", 0) != 0) continue;
    std::istringstream fields(line.substr(key.size() + 1));
    size_t kilobytes = 0;
    std::string unit;
    if (fields >> kilobytes >> unit && unit == "kB") return saturating_mul(kilobytes, 1024);
    return 0;
  }
  return 0;
}

}  // namespace

void set_allocator_thresholds() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  mallopt(M_TRIM_THRESHOLD, 4 << 20);
#endif
}

size_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return 0;
  return mul(static_cast<size_t>(pages), static_cast<size_t>(page));
}

size_t device_memory_bound(const DeviceInfo& device) {
  return device.host_unified_memory ? physical_memory_bytes() : device.global_memory_bytes;
}

void limit_to_machine(Renderer& renderer, const DeviceInfo& device) {
  renderer.set_device_byte_limit(device_memory_bound(device));
}

std::string frame_buffers_field(int msaa) { return msaa > 1 ? "msaa" : "size"; }

void refuse_beyond_machine(const RenderMemory& memory, int msaa, const DeviceInfo& device, const std::string& what) {
  const std::string field = frame_buffers_field(msaa);
  const size_t host = physical_memory_bytes();
  if (device.host_unified_memory) {
    // One memory: each byte once, at the render's peak (process_shares).
    const MemoryShares together = memory.process_shares(field, true);
    if (host != 0 && together.total() > host) throw OverBudget(together.field(), what, together.total(), host);
    return;
  }
  refuse_beyond_machine(memory.device_shares(field), memory.host_shares(), device, what);
}

void refuse_beyond_machine(const MemoryShares& device_bytes, const MemoryShares& host_bytes, const DeviceInfo& device,
                           const std::string& what) {
  const size_t host = physical_memory_bytes(), device_bound = device_memory_bound(device);
  if (device.host_unified_memory) {
    MemoryShares together = device_bytes;
    together.add(host_bytes);
    if (host != 0 && together.total() > host) throw OverBudget(together.field(), what, together.total(), host);
    return;
  }
  if (host != 0 && host_bytes.total() > host)
    throw OverBudget(host_bytes.field(), what + " (host memory)", host_bytes.total(), host);
  if (device_bound != 0 && device_bytes.total() > device_bound)
    throw OverBudget(device_bytes.field(), what + " (device memory)", device_bytes.total(), device_bound);
}

ProcessMemory process_memory() {
  ProcessMemory memory;
  std::ifstream file("/proc/self/status");
  if (file) {
    std::ostringstream text;
    text << file.rdbuf();
    memory.peak_rss_bytes = status_kilobytes(text.str(), "VmHWM");
    memory.rss_bytes = status_kilobytes(text.str(), "VmRSS");
  }
  if (memory.peak_rss_bytes == 0) {
    rusage usage{};
    if (getrusage(RUSAGE_SELF, &usage) == 0) memory.peak_rss_bytes = saturating_mul(static_cast<size_t>(usage.ru_maxrss), 1024);
  }
  return memory;
}

MeasuredMemory measure_memory(const Scene& caller_scene, const Renderer& renderer) {
  MeasuredMemory m;
  m.process = process_memory();
  const PackedScene& packed = renderer.packed_scene();
  m.packed_texels = packed.texel_count();
  m.packed_texel_bytes = packed.texture_bytes();
  m.host_packed_bytes = packed.positions.size() * sizeof(cl_float4) + packed.faces.size() * sizeof(FaceGpu) +
                        packed.adjacency_bytes() + packed.level_offsets.size() * sizeof(uint32_t) +
                        packed.texture_bytes() + packed.reflective_faces.size() * sizeof(ReflectiveFace);
  m.device_bytes = renderer.device_bytes();
  m.scene_float_texel_bytes = caller_scene.stored_texel_count() * sizeof(glm::vec4);
  if (renderer.has_scene()) m.renderer_float_texel_bytes = renderer.scene().stored_texel_count() * sizeof(glm::vec4);
  return m;
}

MeasuredMemory measure_memory(const Renderer& renderer) { return measure_memory(Scene{}, renderer); }

nlohmann::json to_json(const MeasuredMemory& m) {
  return {{"peak_rss_bytes", m.process.peak_rss_bytes},
          {"rss_bytes", m.process.rss_bytes},
          {"packed_texels", m.packed_texels},
          {"packed_texel_bytes", m.packed_texel_bytes},
          {"host_packed_bytes", m.host_packed_bytes},
          {"device_bytes", m.device_bytes},
          {"scene_float_texel_bytes", m.scene_float_texel_bytes},
          {"renderer_float_texel_bytes", m.renderer_float_texel_bytes}};
}

}  // namespace seamcl
