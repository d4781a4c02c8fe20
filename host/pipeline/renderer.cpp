#include <seamcl/pipeline/renderer.h>

#include <algorithm>
#include <optional>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <utility>

#include <seamcl/core/input_error.h>
#include <seamcl/core/over_budget.h>
#include "core/srgb.h"
#include "pipeline/adjacency.h"
#include "pipeline/frame_params.h"
#include "pipeline/stages/binning_launcher.h"
#include "pipeline/stages/downsample_launcher.h"
#include "pipeline/stages/ptex_filter_twin.h"
#include "pipeline/stages/raster_launcher.h"
#include "pipeline/stages/shade_inspect_launcher.h"
#include "pipeline/stages/shade_resolve_launcher.h"
#include "pipeline/stages/stage_buffers.h"
#include "pipeline/stages/tessellate_launcher.h"
#include "pipeline/stages/triangle_setup_launcher.h"
#include "pipeline/tessellation_factors.h"
#include <seamcl/pipeline/packed_cube.h>
#include <seamcl/pipeline/stage_stop.h>

namespace seamcl {

struct Renderer::Impl {
  ClRuntime& runtime;

  std::unique_ptr<Scene> scene;
  // Declared before the buffers that may be these arrays themselves (upload_shared), so that they
  // are destroyed after them.
  PackedScene packed;
  std::vector<float> cube_host;
  bool uploaded = false;  // packed and its buffers are current (a failed pack leaves neither)
  cl::Buffer positions, faces, neighbors, level_offsets, texels, srgb_table;
  // The environment: reflective faces (with the scene) and the cube map baked for the method.
  cl::Buffer reflective_faces, cube_texels;
  std::optional<CubePreparation> cube_bake_uploaded;

  // The frame's constants and counters, which every stage reads; each stage's launcher holds the
  // buffers it writes, grown on demand.
  cl::Buffer frame_params, stats;
  TriangleSetupLauncher setup{runtime};
  BinningLauncher binning{runtime};
  RasterLauncher raster{runtime};
  ShadeResolveLauncher shade{runtime};
  uint32_t bin_capacity = 0;  // tile-list entries the next frame asks for
  FrameParams last_params{};
  size_t device_byte_limit = 0;  // 0: none
  // Displacement renders only: the tessellation stage replaces triangle setup.
  TessellateLauncher tessellation{runtime};
  std::optional<DisplacementSettings> tessellation_settings;  // what `tessellation` holds
  bool displaced = false;        // this frame runs the tessellation stage
  bool displaced_normals = false;  // and lights with the displaced surface's normals
  std::string program_key;       // the current shading program variant's build options
  bool direction_output = false;  // render_directions: SEAMCL_CUBE_DIRECTION
  bool mask_only = false;         // seam_mask: FrameParams.mask_only
  // render_downsampled: the stage that reduces the image on the device before the read-back.
  DownsampleLauncher downsampler{runtime};
  const DownsampleTaps* downsample_taps = nullptr;
  // Ptex's own filters: the file's faces as they read them (set_ptex_texture), uploaded once, and
  // this frame's settings (null buffers and zeros for the other filters).
  std::shared_ptr<const PtexFilterData> ptex;
  std::string ptex_file;
  cl::Buffer ptex_faces, ptex_level_offsets, ptex_texels;
  PtexShading ptex_shading{};
  bool ptex_frame = false;

  explicit Impl(ClRuntime& rt) : runtime(rt) {
    const auto& table = srgb_to_linear_table();
    srgb_table = cl::Buffer(runtime.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(float) * table.size(),
                            const_cast<float*>(table.data()));
    frame_params = cl::Buffer(runtime.context(), CL_MEM_READ_ONLY, sizeof(FrameParams));
    stats = cl::Buffer(runtime.context(), CL_MEM_READ_WRITE, sizeof(FrameStats));
  }

  // Makes the shading kernel of the program variant for this texel format and sampler current,
  // and builds the option-free programs the frame's other stages take their kernels from: here,
  // before the frame queues anything, so a build that fails or is slow does so before the frame.
  void use_kernels(TexelFormat format, const SamplerParams& sampler, bool with_seam_mask) {
    const std::string options = program_options(format, sampler, with_seam_mask, scene->environment.has_value());
    program_key = options;
    runtime.program(KernelProgram::Geometry);
    if (downsample_taps) runtime.program(KernelProgram::Downsample);
    shade.use_program(options);
  }

  // Packs and uploads the loaded scene in `format` with `guard_band` texels of band per level, from
  // `adjacency` (build_adjacency, or empty: none), which is kept only if `keep_adjacency`.
  void pack_and_upload(TexelFormat format, int guard_band, std::vector<FaceNeighbors> adjacency, bool keep_adjacency) {
    // The old packing goes first, so a repack never holds two scenes' textures at once.
    release_scene_buffers();
    packed = pack_scene(*scene, format, guard_band, std::move(adjacency));
    if (!keep_adjacency) packed.neighbors = {};  // guardband's bands are made: its kernels never read it
    positions = upload_shared(packed.positions);
    faces = upload_shared(packed.faces);
    neighbors = upload_shared(packed.neighbors);
    level_offsets = upload_shared(packed.level_offsets);
    texels = format == TexelFormat::Rgba8 ? upload_shared(packed.texels8) : upload_shared(packed.texels32);
    reflective_faces = upload_shared(packed.reflective_faces);
    uploaded = true;
  }

  // Adds the adjacency to a packing made without it (the first render that reads it).
  void add_adjacency(std::vector<FaceNeighbors> adjacency) {
    drain_queue();  // queued frames may read the one-element stand-in
    uploaded = false;  // until the buffer is there: a failed upload repacks on the next render
    neighbors = cl::Buffer();
    packed.neighbors = std::move(adjacency);
    fill_edge_reach(packed.faces, packed.neighbors);
    neighbors = upload_shared(packed.neighbors);
    uploaded = true;
  }

  // load_scene: the old scene and its buffers go before make_scene makes the new copy, so a
  // reload never holds two scenes.
  template <typename MakeScene>
  void replace_scene(const Scene& checked, TexelFormat format, MakeScene make_scene) {
    validate_scene(checked);
    release_scene_buffers();
    scene.reset();
    scene = make_scene();
    pack_and_upload(format, 0, {}, false);  // no adjacency until a render reads it
    // Start the tile lists at a few entries per triangle slot; render() grows them when needed.
    bin_capacity = std::max<uint32_t>(bin_capacity, initial_tile_list_entries(scene->triangle_count()));
    binning.release_tile_lists();
  }

  // Waits for queued commands, which may read the shared arrays (upload_shared), before one is
  // freed: a frame that threw part-way may have left kernels queued.
  void drain_queue() { runtime.queue().finish(); }

  ~Impl() {
    try {
      drain_queue();
    } catch (...) {  // a failing device cannot be waited for; nothing else to do in a destructor
    }
  }

  void release_scene_buffers() {
    drain_queue();
    uploaded = false;
    // The buffers first: they may be the packed arrays themselves (upload_shared).
    positions = faces = neighbors = level_offsets = texels = reflective_faces = cube_texels = cl::Buffer();
    packed = PackedScene{};
    cube_bake_uploaded.reset();
    cube_host = {};
    tessellation.release();
    tessellation_settings.reset();
  }

  // Bakes and uploads the environment's cube map as `preparation` says unless it is the one
  // there; a scene without an environment gets a one-element stand-in (the kernels never read it).
  void upload_cube(std::optional<CubePreparation> preparation) {
    if (cube_texels() != nullptr && cube_bake_uploaded == preparation) return;
    drain_queue();
    cube_texels = cl::Buffer();
    cube_host = {};
    if (preparation) {
      const Environment& environment = *scene->environment;
      CubeMap cube =
          bake_cube_map(environment_function(environment), environment.cube_size, preparation->bake, environment.bake_samples);
      if (preparation->average_edges) average_cube_edges(cube);
      cube_host = pack_cube_texels(cube, preparation->border);
    }
    cube_texels = upload_shared(cube_host);
    cube_bake_uploaded = preparation;
  }

  void release_frame_buffers() {
    setup.release();
    binning.release();
    raster.release();
    shade.release();
    downsampler.release();
    // The tessellated vertices are sized by the request too (packed again on the next render).
    tessellation.release();
    tessellation_settings.reset();
    // What a scene needed once is not kept either: the lists start again at the initial size
    // (render_memory's estimate) and grow if this scene needs it.
    bin_capacity = scene ? initial_tile_list_entries(scene->triangle_count()) : 0;
    last_params = FrameParams{};
  }

  template <typename T, typename Allocator>
  cl::Buffer upload(const std::vector<T, Allocator>& data) {
    // OpenCL refuses zero-sized buffers; one element of padding keeps empty arrays legal.
    const size_t bytes = std::max<size_t>(data.size(), 1) * sizeof(T);
    cl::Buffer buffer(runtime.context(), CL_MEM_READ_ONLY, bytes);
    if (!data.empty()) runtime.queue().enqueueWriteBuffer(buffer, CL_TRUE, 0, data.size() * sizeof(T), data.data());
    return buffer;
  }

  // A packed array that stays on the host (every array of `packed`, the cube's texels): on a device
  // that shares the host's memory (PoCL on the CPU) the buffer is the array itself
  // (CL_MEM_USE_HOST_PTR), so it is held once rather than twice (issue 14: a second copy of
  // large scenes' tables showed in the peak memory); the array outlives the buffer
  // (release_scene_buffers and upload_cube drop the buffers first, and renders wait for their
  // commands). Elsewhere a device copy, as upload() makes.
  template <typename T, typename Allocator>
  cl::Buffer upload_shared(const std::vector<T, Allocator>& data) {
    if (data.empty() || runtime.device().getInfo<CL_DEVICE_HOST_UNIFIED_MEMORY>() != CL_TRUE) return upload(data);
    return cl::Buffer(runtime.context(), CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, data.size() * sizeof(T),
                      const_cast<T*>(data.data()));
  }

  void reserve_frame_buffers(const FrameParams& p) {
    setup.reserve(static_cast<size_t>(p.input_triangles));
    binning.reserve(p);
    raster.reserve(p);
    shade.reserve(p);
  }

  ShadeSceneBuffers shade_scene_buffers() const {
    static const cl::Buffer none;
    DisplacedShading lit{};
    if (displaced && displaced_normals) {
      lit.tessellation = tessellation.packed().params.tessellation;
      lit.adaptive = tessellation.packed().adaptive() ? 1 : 0;
    }
    const bool smooth = lit.tessellation > 0;
    return ShadeSceneBuffers{faces,        neighbors,   level_offsets, texels, srgb_table, reflective_faces, cube_texels,
                             ptex_frame ? ptex_faces : none, ptex_frame ? ptex_level_offsets : none,
                             ptex_frame ? ptex_texels : none, ptex_frame ? ptex_shading : PtexShading{}, lit,
                             smooth ? tessellation.vertex_buffer() : none, smooth ? tessellation.normal_buffer() : none};
  }

  // The checks and settings of a frame with one of Ptex's own filters; InputError naming the field.
  void prepare_ptex_frame(const RenderOptions& options, bool with_seam_mask) {
    const std::string filter = to_string(options.filter);
    if (with_seam_mask) {
      throw InputError("filter", filter + ": the seam mask measures the footprints of the packed texture's filters, "
                                          "which Ptex's filters do not read");
    }
    const int seams = ptex_seam_rule(options.method);
    if (scene->ptex_file.empty()) {
      throw InputError("filter", filter + " filters the faces of a .ptx file, and scene '" + scene->name +
                                     "' has none: give a mesh with a .ptx texture (--scene MESH.obj --texture FILE.ptx) "
                                     "or a .ptx that holds its mesh");
    }
    if (!ptex || ptex_file != scene->ptex_file) {
      // A job that does not load the file for Ptex's filters (only render does).
      throw InputError("filter", filter + ": '" + scene->ptex_file + "' is not loaded for Ptex's filters here; "
                                          "`render` offers them");
    }
    if (ptex->faces.size() != scene->faces.size()) {
      throw InputError("texture", "'" + ptex_file + "' has " + std::to_string(ptex->faces.size()) +
                                      " faces but the scene has " + std::to_string(scene->faces.size()));
    }
    ptex_shading = PtexShading{};
    ptex_shading.texture = ptex->texture;
    ptex_shading.texture.seams = seams;
    ptex_shading.filter = ptex_filter_code(options.filter, ptex_shading.sharpness);
    ptex_shading.width_scale = std::exp2(options.lod_bias);
    const std::array<cl_int, 3> rgb = ptex_rgb_source(ptex->texture.channels, ptex->alpha_channel);
    for (int o = 0; o < 3; ++o) ptex_shading.rgb_source[o] = rgb[o];
  }

  // Queues one frame; returns the events of each stage in order.
  struct StageEvents {
    std::vector<cl::Event> setup, binning, raster, shade, readback, tessellate, downsample;
  };

  StageEvents enqueue_frame(const FrameParams& p, std::vector<glm::vec4>& pixels, std::vector<uint8_t>* mask) {
    cl::CommandQueue& queue = runtime.queue();
    StageEvents ev;
    ev.setup.reserve(3);
    ev.binning.reserve(3);
    queue.enqueueWriteBuffer(frame_params, CL_FALSE, 0, sizeof(FrameParams), &p, nullptr, &ev.setup.emplace_back());
    const FrameStats zero_stats{};
    queue.enqueueWriteBuffer(stats, CL_FALSE, 0, sizeof(FrameStats), &zero_stats, nullptr, &ev.setup.emplace_back());

    if (displaced) {
      tessellation.enqueue(frame_params, setup.setups(), setup.slot_counts(), stats, p.input_triangles,
                           displaced_normals, ev.tessellate, ev.setup);
    } else {
      setup.enqueue(frame_params, positions, faces, stats, p.input_triangles, ev.setup);
    }
    binning.enqueue(frame_params, setup.setups(), setup.slot_counts(), stats, p, ev.binning);
    raster.enqueue(frame_params, setup.setups(), binning, p, ev.raster);
    shade.enqueue(frame_params, setup.setups(), shade_scene_buffers(), raster.sample_triangle(), stats, p, mask != nullptr,
                  ev.shade);
    if (downsample_taps) {
      downsampler.enqueue(shade.image(), p.width, p.height, *downsample_taps, pixels, ev.downsample, ev.readback);
    } else {
      shade.enqueue_readback(p, pixels, mask, ev.readback);
    }
    queue.finish();
    return ev;
  }

  // The tile-list entries the last frame wrote (bin_entries counts the ones that did not fit too).
  size_t written_bin_entries() {
    FrameStats written{};
    runtime.queue().enqueueReadBuffer(stats, CL_TRUE, 0, sizeof(FrameStats), &written);
    return std::min(written.bin_entries, bin_capacity);
  }
};

Renderer::Renderer(ClRuntime& runtime) : impl_(std::make_unique<Impl>(runtime)) {}
Renderer::~Renderer() = default;

void Renderer::load_scene(const Scene& scene, TexelFormat format) {
  impl_->replace_scene(scene, format, [&] { return std::make_unique<Scene>(scene); });
}

void Renderer::load_scene(Scene&& scene, TexelFormat format) {
  impl_->replace_scene(scene, format, [&] { return std::make_unique<Scene>(std::move(scene)); });
}

void Renderer::set_device_byte_limit(size_t bytes) { impl_->device_byte_limit = bytes; }
size_t Renderer::device_byte_limit() const { return impl_->device_byte_limit; }

bool Renderer::has_scene() const { return impl_->scene != nullptr; }

void Renderer::release_frame_buffers() { impl_->release_frame_buffers(); }

void Renderer::release_scene() {
  set_ptex_texture(nullptr, "");
  impl_->release_scene_buffers();
  impl_->scene.reset();
  impl_->release_frame_buffers();
}

size_t Renderer::device_bytes() const {
  const Impl& i = *impl_;
  size_t bytes = 0;
  for (const cl::Buffer* buffer : {&i.positions, &i.faces, &i.neighbors, &i.level_offsets, &i.texels, &i.reflective_faces,
                                   &i.cube_texels, &i.srgb_table, &i.frame_params, &i.stats, &i.ptex_faces,
                                   &i.ptex_level_offsets, &i.ptex_texels}) {
    bytes += buffer_bytes(*buffer);
  }
  return bytes + i.setup.device_bytes() + i.binning.device_bytes() + i.raster.device_bytes() + i.shade.device_bytes() +
         i.tessellation.device_bytes() + i.downsampler.device_bytes();
}

const Scene& Renderer::scene() const {
  if (!impl_->scene) throw std::logic_error("Renderer::scene before load_scene");
  return *impl_->scene;
}

const PackedScene& Renderer::packed_scene() const { return impl_->packed; }

const std::vector<float>& Renderer::cube_texels() const { return impl_->cube_host; }

void Renderer::set_ptex_texture(std::shared_ptr<const PtexFilterData> data, const std::string& file) {
  Impl& i = *impl_;
  i.drain_queue();  // queued frames may read the old buffers
  i.ptex_faces = i.ptex_level_offsets = i.ptex_texels = cl::Buffer();
  i.ptex = std::move(data);
  i.ptex_file = i.ptex ? file : std::string();
  if (!i.ptex) return;
  i.ptex_faces = i.upload(i.ptex->faces);
  i.ptex_level_offsets = i.upload(i.ptex->level_offsets);
  i.ptex_texels = i.upload(i.ptex->texels);
}

const std::string& Renderer::ptex_texture_file() const { return impl_->ptex_file; }
const PtexShading& Renderer::ptex_shading() const { return impl_->ptex_shading; }

RenderResult Renderer::render(const Camera& camera, const RenderOptions& options, bool with_seam_mask) {
  if (!impl_->scene) throw std::logic_error("Renderer::render before load_scene");
  impl_->ptex_frame = is_ptex_filter(options.filter);
  if (impl_->ptex_frame) impl_->prepare_ptex_frame(options, with_seam_mask);
  if (with_seam_mask && options.method == Method::Guardband) {
    throw InputError("method", "the seam mask is measured on the faces' own texels; guardband's bands would count as "
                               "inside (any other method gives the same mask)");
  }
  const SamplerParams sampler = sampler_params(options);
  if (options.method == Method::Guardband && !(sampler.guard_band >= 1 && sampler.guard_band <= kMaxGuardBand)) {
    throw InputError("guard_band", "must be 1.." + std::to_string(kMaxGuardBand) + " texels for guardband, got " +
                                       std::to_string(sampler.guard_band));
  }
  const bool repack =
      !impl_->uploaded || options.texels != impl_->packed.format || sampler.guard_band != impl_->packed.guard_band;
  // The adjacency is built by the first render that reads it (held here, not packed, until the
  // checks pass) and kept; a repack for a render that does not read it leaves it out, and
  // guardband's packing builds it for its bands only.
  const bool keep_adjacency = reads_adjacency(options.method) || with_seam_mask;
  std::vector<FaceNeighbors> adjacency;
  if ((keep_adjacency && (repack || impl_->packed.neighbors.empty())) || (repack && sampler.guard_band > 0)) {
    // A repack in another format or band keeps the same adjacency: a copy of the one held (the
    // held one stays until the checks pass), else built.
    adjacency = impl_->packed.neighbors.empty() ? build_adjacency(*impl_->scene) : impl_->packed.neighbors;
  }
  // Neither built nor kept: a banded packing, whose adjacency was checked when it was made.
  if (needs_adjacency(options.method) && !has_adjacency(adjacency.empty() ? impl_->packed.neighbors : adjacency)) {
    const Scene& scene = *impl_->scene;
    const std::string reads = to_string(options.method) + " reads each face's edge neighbours, and ";
    // Faces that do share edges, but only edges of three or more faces, have no single neighbour
    // across any: saying that no two share an edge would send the user looking for split vertices.
    if (const NonManifoldEdges non_manifold = non_manifold_edges(scene); non_manifold.count > 0) {
      const std::string example = "between vertices " + std::to_string(non_manifold.first_vertex) + " and " +
                                  std::to_string(non_manifold.second_vertex) + " (0-based)";
      const std::string faces = std::to_string(non_manifold.example_faces) + " faces";
      throw InputError("method", reads + "no edge of scene '" + scene.name + "' links two faces: " +
                                     (non_manifold.count == 1
                                          ? "its only shared edge, " + example + ", is shared by " + faces
                                          : "its " + std::to_string(non_manifold.count) +
                                                " shared edges are each shared by more than two faces (the first, " +
                                                example + ", by " + faces + ")") +
                                     "; an edge links faces only when exactly two share it");
    }
    throw InputError("method", reads + "no two of the " + std::to_string(scene.faces.size()) + " faces of scene '" +
                                   scene.name + "' share an edge (faces are neighbours through shared vertex indices)");
  }
  throw_if_stage_stopped("packing");
  if (repack) {
    impl_->pack_and_upload(options.texels, sampler.guard_band, std::move(adjacency), keep_adjacency);
  } else if (!adjacency.empty()) {
    impl_->add_adjacency(std::move(adjacency));
  }
  throw_if_stage_stopped("the cube map");
  impl_->upload_cube(impl_->scene->environment ? std::optional(cube_preparation(options.cube_method)) : std::nullopt);
  throw_if_stage_stopped("the kernels");
  impl_->use_kernels(options.texels, sampler, with_seam_mask);
  throw_if_stage_stopped("the frame");
  impl_->displaced = options.displacement.has_value();
  impl_->displaced_normals = options.displacement_normals == DisplacementNormals::Displaced;
  if (impl_->displaced) {
    // Screen-space factors follow the camera: a frame whose factors differ loads them anew.
    DisplacementSettings settings = displacement_settings(*impl_->scene, options, camera);
    const auto& held = impl_->tessellation_settings;
    if (!held || *held != settings) {
      impl_->tessellation.load(pack_displacement(*impl_->scene, settings));
      impl_->tessellation_settings = settings;
    }
  }
  RenderResult result;
  result.width = options.width;
  result.height = options.height;
  for (result.attempts = 1;; ++result.attempts) {
    FrameParams params = make_frame_params(*impl_->scene, camera, options, impl_->bin_capacity);
    if (impl_->displaced) params.input_triangles = static_cast<cl_int>(impl_->tessellation.packed().triangle_count());
    if (impl_->direction_output) params.environment.sampler.method = SEAMCL_CUBE_DIRECTION;
    params.mask_only = with_seam_mask && impl_->mask_only ? 1 : 0;
    impl_->reserve_frame_buffers(params);
    impl_->bin_capacity = params.bin_capacity;
    impl_->last_params = params;
    const Impl::StageEvents ev = impl_->enqueue_frame(params, result.pixels, with_seam_mask ? &result.seam_mask : nullptr);
    impl_->runtime.queue().enqueueReadBuffer(impl_->stats, CL_TRUE, 0, sizeof(FrameStats), &result.stats);
    if (result.stats.bin_entries > params.bin_capacity) {
      // The lists overflowed (the kernels stayed in bounds): grow with headroom and render again.
      if (result.attempts >= 3) throw std::runtime_error("tile lists overflowed three times");
      const uint32_t grown = static_cast<uint32_t>(std::min<uint64_t>(uint64_t{result.stats.bin_entries} * 5 / 4 + 1024, 1u << 31));
      if (impl_->device_byte_limit != 0) {
        // A list entry is a slot index and its rows (tile_entry_rows).
        constexpr size_t entry_bytes = sizeof(cl_uint) + sizeof(cl_ushort);
        const size_t needed = device_bytes() - size_t{impl_->binning.tile_list_capacity()} * entry_bytes + size_t{grown} * entry_bytes;
        if (needed > impl_->device_byte_limit) {
          throw OverBudget("size", "this frame's tile lists (" + std::to_string(result.stats.bin_entries) + " entries)",
                           needed, impl_->device_byte_limit);
        }
      }
      impl_->bin_capacity = grown;
      continue;
    }
    auto sum = [](const std::vector<cl::Event>& events) {
      double ms = 0;
      for (const cl::Event& e : events) ms += event_milliseconds(e);
      return ms;
    };
    result.ms.setup = sum(ev.setup);
    result.ms.binning = sum(ev.binning);
    result.ms.raster = sum(ev.raster);
    result.ms.shade = sum(ev.shade);
    result.ms.readback = sum(ev.readback);
    result.ms.tessellate = sum(ev.tessellate);
    result.ms.downsample = sum(ev.downsample);
    const cl_ulong first = ev.setup.front().getProfilingInfo<CL_PROFILING_COMMAND_START>();
    const cl_ulong last = ev.readback.back().getProfilingInfo<CL_PROFILING_COMMAND_END>();
    result.ms.total = static_cast<double>(last - first) * 1e-6;
    return result;
  }
}

std::future<void> build_programs_ahead(ClRuntime& runtime, const Scene& scene, const std::vector<ProgramNeed>& needs,
                                       const std::atomic<bool>* stop) {
  using Build = std::pair<KernelProgram, std::string>;
  std::vector<Build> builds{{KernelProgram::Geometry, ""}};  // every render's first stages
  auto add = [&builds](Build build) {
    if (std::find(builds.begin(), builds.end(), build) == builds.end()) builds.push_back(std::move(build));
  };
  for (const ProgramNeed& need : needs) {
    add({KernelProgram::Shading, program_options(need.options.texels, sampler_params(need.options), need.with_seam_mask,
                                                 scene.environment.has_value())});
    if (need.downsampled) add({KernelProgram::Downsample, ""});
  }
  return std::async(std::launch::async, [&runtime, stop, builds = std::move(builds)] {
    // A build that fails is left to the render that uses it, which builds it again and reports
    // the error; the builds after it still run.
    auto build = [&runtime, stop](KernelProgram program, const std::string& options) {
      if (stop && stop->load()) return;
      try {
        runtime.program(program, options);
      } catch (...) {
      }
    };
    for (const auto& [program, options] : builds) build(program, options);
  });
}

std::string program_options(TexelFormat format, const SamplerParams& sampler, bool with_seam_mask, bool environment) {
  return std::string(format == TexelFormat::Rgba32f ? "-DSEAMCL_TEXELS_F32=1" : "-DSEAMCL_TEXELS_F32=0") +
         " -DSEAMCL_SAMPLER_FILTER=" + std::to_string(sampler.filter) +
         " -DSEAMCL_SAMPLER_ADDRESS=" + std::to_string(sampler.address) +
         " -DSEAMCL_SAMPLER_RENORMALIZE=" + std::to_string(sampler.renormalize) +
         " -DSEAMCL_SAMPLER_ZERO_COVERAGE=" + std::to_string(sampler.zero_coverage) +
         " -DSEAMCL_SAMPLER_TRAVERSE=" + std::to_string(sampler.traverse) +
         " -DSEAMCL_SAMPLER_GUARD_BAND=" + std::to_string(sampler.guard_band) +
         (with_seam_mask ? " -DSEAMCL_SEAM_MASK=1" : "") + (environment ? " -DSEAMCL_CUBE=1" : "");
}

namespace {
// A render mode flag of the Renderer's, set for one render and cleared however it ends.
struct FlagForOneRender {
  bool& flag;
  explicit FlagForOneRender(bool& f) : flag(f) { flag = true; }
  ~FlagForOneRender() { flag = false; }
};
}  // namespace

RenderResult Renderer::render_directions(const Camera& camera, const RenderOptions& options) {
  if (!has_scene() || !impl_->scene->environment) throw std::logic_error("render_directions needs an environment");
  const FlagForOneRender directions(impl_->direction_output);
  return render(camera, options);
}

std::vector<uint8_t> Renderer::render_seam_mask(const Camera& camera, const RenderOptions& options) {
  const FlagForOneRender mask_only(impl_->mask_only);
  return std::move(render(camera, options, true).seam_mask);
}

RenderResult Renderer::render_downsampled(const Camera& camera, const RenderOptions& options, const DownsampleTaps& taps) {
  const int f = taps.factor;
  if (f < 1 || options.width % f != 0 || options.height % f != 0) {
    throw std::invalid_argument("render_downsampled: " + std::to_string(options.width) + "x" +
                                std::to_string(options.height) + " is not a multiple of " + std::to_string(f));
  }
  impl_->downsample_taps = &taps;
  try {
    RenderResult result = render(camera, options);
    impl_->downsample_taps = nullptr;
    result.width = options.width / f;
    result.height = options.height / f;
    return result;
  } catch (...) {
    impl_->downsample_taps = nullptr;
    throw;
  }
}

RenderResult Renderer::downsample_last_frame(const DownsampleTaps& taps) {
  const FrameParams& p = impl_->last_params;
  if (p.width == 0 || impl_->program_key.empty()) throw std::logic_error("downsample_last_frame without a frame");
  RenderResult result;
  std::vector<cl::Event> passes, readback;
  impl_->downsampler.enqueue(impl_->shade.image(), p.width, p.height, taps, result.pixels, passes, readback);
  impl_->runtime.queue().finish();
  for (const cl::Event& e : passes) result.ms.downsample += event_milliseconds(e);
  for (const cl::Event& e : readback) result.ms.readback += event_milliseconds(e);
  result.ms.total = static_cast<double>(readback.back().getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                                        passes.front().getProfilingInfo<CL_PROFILING_COMMAND_START>()) * 1e-6;
  result.width = p.width / taps.factor;
  result.height = p.height / taps.factor;
  return result;
}

void Renderer::warm_up(const RenderOptions& options) {
  if (is_ptex_filter(options.filter) && (scene().ptex_file.empty() || impl_->ptex_file != scene().ptex_file)) {
    // No .ptx to render here (a built-in scene warming every variant): the program alone.
    impl_->use_kernels(options.texels, sampler_params(options), false);
    return;
  }
  RenderOptions tiny = options;
  tiny.width = SEAMCL_TILE_SIZE;
  tiny.height = SEAMCL_TILE_SIZE;
  render(scene().camera, tiny);
}

std::vector<InspectSample> Renderer::inspect_last_frame(int x, int y, int width, int height) {
  Impl& i = *impl_;
  const FrameParams& p = i.last_params;
  if (p.width == 0 || i.program_key.empty() || !i.uploaded) throw std::logic_error("inspect_last_frame without a frame");
  if (width < 1 || x < 0 || x > p.width - width) {
    throw InputError("x", "must lie in 0.." + std::to_string(p.width - 1) + " with the window inside the image, got " +
                              std::to_string(x) + " (window " + std::to_string(width) + " wide)");
  }
  if (height < 1 || y < 0 || y > p.height - height) {
    throw InputError("y", "must lie in 0.." + std::to_string(p.height - 1) + " with the window inside the image, got " +
                              std::to_string(y) + " (window " + std::to_string(height) + " high)");
  }
  ShadeInspectLauncher launcher(i.runtime);
  std::vector<InspectSample> records =
      launcher.inspect(i.program_key, i.frame_params, i.setup.setups(), i.shade_scene_buffers(), i.raster.sample_triangle(),
                       p, !i.packed.neighbors.empty(), PixelWindow{x, y, width, height});
  // The slots as read_setups and read_sample_triangles number them (input order).
  for (InspectSample& r : records) r.triangle = input_order_slot(r.triangle, static_cast<uint32_t>(p.input_triangles));
  return records;
}

FrameParams Renderer::last_frame_params() const { return impl_->last_params; }

std::vector<TriangleSetup> Renderer::read_setups() {
  // Input triangle t's face: t's face (two triangles each), or for micro-triangles their patch
  // (2 T^2 each).
  const size_t triangles_per_face =
      impl_->displaced && impl_->tessellation_settings
          ? 2 * static_cast<size_t>(impl_->tessellation.packed().params.tessellation) *
                static_cast<size_t>(impl_->tessellation.packed().params.tessellation)
          : 2;
  return impl_->setup.read_setups(static_cast<size_t>(impl_->last_params.input_triangles), triangles_per_face);
}
std::vector<uint32_t> Renderer::read_tile_counts() {
  return impl_->binning.read_tile_counts(static_cast<size_t>(impl_->last_params.tiles_x) * impl_->last_params.tiles_y);
}
std::vector<uint32_t> Renderer::read_tile_offsets() {
  return impl_->binning.read_tile_offsets(static_cast<size_t>(impl_->last_params.tiles_x) * impl_->last_params.tiles_y);
}
std::vector<uint32_t> Renderer::read_tile_lists() {
  if (impl_->binning.tile_lists()() == nullptr || impl_->last_params.width == 0) return {};  // released (or none yet)
  return impl_->binning.read_tile_lists(impl_->written_bin_entries(),
                                        static_cast<uint32_t>(impl_->last_params.input_triangles));
}
std::vector<uint16_t> Renderer::read_tile_entry_rows() {
  if (impl_->binning.tile_entry_rows()() == nullptr || impl_->last_params.width == 0) return {};  // released (or none yet)
  return impl_->binning.read_tile_entry_rows(impl_->written_bin_entries());
}
std::vector<uint32_t> Renderer::read_sample_triangles() { return impl_->raster.read_sample_triangles(impl_->last_params); }

}  // namespace seamcl
