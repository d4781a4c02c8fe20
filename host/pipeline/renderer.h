// Runs the pipeline on the device: setup -> binning -> raster -> shade/resolve, queued back to
// back and waited for once per frame. A Renderer owns its kernel objects and buffers, so one per
// thread (they may share a ClRuntime: contexts, queues and programs are thread-safe, kernel
// arguments are not).
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <future>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Tile-list entries a Renderer allocates for a scene of `triangles` before it learns better: a few
// per triangle plus a floor, at most 2^30 (render_memory counts the same).
inline uint32_t initial_tile_list_entries(size_t triangles) {
  const size_t capped = size_t{1} << 30;
  return static_cast<uint32_t>(triangles >= (capped - 65536) / 8 ? capped : triangles * 8 + 65536);
}

// Milliseconds from OpenCL profiling events.
struct StageTimes {
  double setup = 0;     // triangle setup (transform, clip, edge functions, planes)
  double binning = 0;   // clear + count + scan + fill
  double raster = 0;    // coverage and depth per sample
  double shade = 0;     // shading and resolve
  double readback = 0;  // image to host
  double total = 0;     // first command's start to last command's end
  double tessellate = 0;  // displacement renders: the tessellation kernel (its setup counts in setup)
  double downsample = 0;  // render_downsampled: the downsample stage's two passes
};

// One axis's filter of the downsample stage (host/pipeline/stages/downsample_twin.h).
struct DownsampleTaps;
// A .ptx as Ptex's own filters read it (host/ptexfilter/ptex_filter_texture.h).
struct PtexFilterData;

struct RenderResult {
  int width = 0;
  int height = 0;
  std::vector<glm::vec4> pixels;  // linear RGBA, row-major, row 0 at the top
  StageTimes ms;
  FrameStats stats{};
  int attempts = 1;               // > 1 when the tile lists had to grow
  // With render(..., with_seam_mask): per pixel, SEAMCL_MASK_SEAM (1) where some fragment's texture
  // footprint crosses an edge shared by two faces, SEAMCL_MASK_BOUNDARY (2) where footprints
  // cross mesh boundary edges only, SEAMCL_MASK_NONE (0) elsewhere (see kernels/shade_resolve.cl);
  // empty otherwise.
  std::vector<uint8_t> seam_mask;
};

// The build options of the program variant that reads `format` texels with `sampler`'s filter,
// address mode, renormalisation and zero-coverage rule fixed at build time (max_aniso stays a
// run-time parameter). See the specialisation note in kernels/texture_sample.cl.
// with_seam_mask builds the shade stage that also writes the seam mask; with `environment`, the
// shade stage's environment branch is compiled in (-DSEAMCL_CUBE=1).
std::string program_options(TexelFormat format, const SamplerParams& sampler, bool with_seam_mask = false,
                            bool environment = false);

// A render about to be made, for build_programs_ahead.
struct ProgramNeed {
  RenderOptions options;
  bool with_seam_mask = false;
  bool downsampled = false;  // reduced on the device afterwards (a reference): the downsample program too
};

// Starts building (or loading from a cache) the geometry program and then the shading program
// variants of `needs` on `scene` (and the downsample program after the first need downsampled),
// in the order given, one after another on one thread of its own, and returns at once: work that
// needs no kernel (making and packing the scene) overlaps the builds, which a first render would
// otherwise wait for. One thread, not one per variant: the packing keeps the other cores, and LLVM builds
// hold memory no plan counts. The future is ready (and its destructor returns) when every build has
// ended, so a caller that stops early still waits for the build under way. A build that fails is
// not reported here: the render that uses the variant builds it again and throws its error with
// the build log. Once `stop` (when given; it must outlive the future) is set, the builds not yet
// begun are left out: a cancelled job waits for the build under way only.
std::future<void> build_programs_ahead(ClRuntime& runtime, const Scene& scene, const std::vector<ProgramNeed>& needs,
                                       const std::atomic<bool>* stop = nullptr);

class Renderer {
 public:
  explicit Renderer(ClRuntime& runtime);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Packs and uploads the scene (validated first). Later renders use it until the next call; a
  // render asking for another texel format packs it again.
  void load_scene(const Scene& scene, TexelFormat format = TexelFormat::Rgba8);
  // The same, taking the scene over instead of copying it: a caller that does not need its scene
  // again (scene() gives it back) holds no second copy of its float texels (image faces).
  void load_scene(Scene&& scene, TexelFormat format = TexelFormat::Rgba8);
  const Scene& scene() const;
  // What the kernels read. Its adjacency (neighbors) is empty until a render reads it (traverse,
  // traverse-edges, a seam mask), and again after a repack for one that does not.
  const PackedScene& packed_scene() const;
  // The cube map of the last render's cube method as uploaded (pack_cube_texels), for the twins;
  // empty for a scene without an environment.
  const std::vector<float>& cube_texels() const;
  bool has_scene() const;

  // Ptex's own filters (the ptex-* filters, docs/ptex-filters.md) read `data`: the file
  // `file` as build_ptex_filter_data makes it, uploaded here and kept across scenes. A render with
  // one of them needs the scene's ptex_file to be `file` (InputError("filter") for a scene without
  // one); null drops it. RenderJob::run sets it from the scene.
  void set_ptex_texture(std::shared_ptr<const PtexFilterData> data, const std::string& file);
  const std::string& ptex_texture_file() const;  // empty: none set
  // The last frame's Ptex settings (the seam rule, filter, widths' scale, channels), for the twins.
  const PtexShading& ptex_shading() const;

  // Frees the buffers sized by a request (triangle setups, tiles and tile lists, the sample
  // buffer, the image) so that a kept Renderer does not hold the largest frame it ever rendered;
  // the next render allocates them again at its own size (the tile lists back at their initial
  // size for the scene, initial_tile_list_entries). The last_frame_params and read_* views are empty
  // until then. The scene stays loaded.
  void release_frame_buffers();
  // Frees the loaded scene too: the Renderer's Scene copy, the packed arrays and their device
  // buffers (and the frame buffers). Rendering needs a load_scene again.
  void release_scene();

  // Bytes of the device buffers this Renderer holds now (CL_MEM_SIZE of each): what
  // render_memory(...).device_bytes() predicts for a fresh Renderer after one render.
  size_t device_bytes() const;

  // A ceiling for device_bytes() (0, the default: none). render_memory() predicts every buffer
  // but the tile lists' growth on crowded frames; with a limit, a render whose lists would have
  // to grow past it throws OverBudget (field "size") instead of allocating. The rest is the
  // caller's to check beforehand with render_memory().
  void set_device_byte_limit(size_t bytes);
  size_t device_byte_limit() const;

  // with_seam_mask also reads back RenderResult::seam_mask (a program variant of its own, so the
  // renders without it pay nothing). The mask reads the faces' own texels without guard bands:
  // with Method::Guardband it throws InputError("method"); any other method gives the same mask.
  RenderResult render(const Camera& camera, const RenderOptions& options, bool with_seam_mask = false);
  // The seam mask alone (render with_seam_mask, the fragments left unshaded: FrameParams.mask_only).
  std::vector<uint8_t> render_seam_mask(const Camera& camera, const RenderOptions& options);

  // The frame at `options`' size, resolved on the device and reduced there by taps.factor on
  // both axes (kernels/downsample.cl), then read back small: the result's width, height and
  // pixels are the reduced image's, ms.downsample its two passes, ms.readback the small read.
  // The references' 8x frames never cross to the host. The size must be a multiple of the factor
  // (std::invalid_argument otherwise).
  RenderResult render_downsampled(const Camera& camera, const RenderOptions& options, const DownsampleTaps& taps);
  // The last frame's image (still on the device until release_frame_buffers) reduced again with
  // other taps: a second filter of one 8x render (the paper and box references). Only width,
  // height, pixels, ms.downsample, ms.readback and ms.total are set. std::logic_error without a frame.
  RenderResult downsample_last_frame(const DownsampleTaps& taps);

  // For the analytic reference of scenes with an environment (host/eval/cube_metrics.h): every
  // environment lookup (reflective fragments, skybox) writes its unit direction times
  // 1 + roughness instead of a colour (SEAMCL_CUBE_DIRECTION). Use msaa 1: a resolve would mix
  // directions. Throws std::logic_error for a scene without an environment.
  RenderResult render_directions(const Camera& camera, const RenderOptions& options);

  // Renders one tiny frame of the loaded scene with these options (method, filter, texels) so
  // that the program variant is built and PoCL compiles every kernel for its local size now
  // (slow on a cold cache) rather than inside the first timed frame.
  void warm_up(const RenderOptions& options);

  // The pixel inspector: per pixel of the window [x, x + width) x [y, y + height) of the last
  // frame, its sample_count records (kernels/shade_inspect.cl: each sample's triangle, face,
  // coverage, shading point, uv, levels, footprint and the taps' faces and weights), pixel-major,
  // from the buffers that frame's shading read. InputError("x" or "y") for a window outside the
  // image; std::logic_error without a frame.
  std::vector<InspectSample> inspect_last_frame(int x, int y, int width, int height);

  // The intermediate buffers of the last frame, for the kernel tests.
  FrameParams last_frame_params() const;
  std::vector<TriangleSetup> read_setups();
  std::vector<uint32_t> read_tile_counts();
  std::vector<uint32_t> read_tile_offsets();
  std::vector<uint32_t> read_tile_lists();
  // Per tile-list entry: the tile's rows and columns its slot's box covers (kernels/binning.cl).
  std::vector<uint16_t> read_tile_entry_rows();
  std::vector<uint32_t> read_sample_triangles();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace seamcl
