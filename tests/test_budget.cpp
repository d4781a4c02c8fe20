// Memory budgets (host/memory/render_memory.h, host/memory/compare_memory.h) against what the
// library really allocates; Renderer's release of request-sized buffers; the reference cache's
// bound (LRU); the cancellation hook of compare_methods.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstring>
#include <type_traits>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <seamcl/batch/scaling_sweep.h>
#include <seamcl/core/cancelled.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/over_budget.h>
#include <seamcl/memory/bench_memory.h>
#include <seamcl/memory/compare_memory.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>

#include "pipeline/stages/downsample_twin.h"
#include "test_support.h"

namespace {

using namespace seamcl;
namespace fs = std::filesystem;

// A 2x2 grid of quads in the z = 0 plane (shared vertices, so every inner edge has a neighbour)
// whose faces have the given texture sizes: non-square and 1-texel sides included.
Scene grid_scene(const std::vector<std::pair<int, int>>& sizes) {
  Scene scene;
  scene.name = "grid";
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) scene.positions.emplace_back(static_cast<float>(i - 1), static_cast<float>(j - 1), 0.0f);
  for (int f = 0; f < 4; ++f) {
    const uint32_t i = static_cast<uint32_t>(f % 2), j = static_cast<uint32_t>(f / 2);
    Face face;
    face.vertices = {j * 3 + i, j * 3 + i + 1, (j + 1) * 3 + i + 1, (j + 1) * 3 + i};
    const auto [w, h] = sizes[static_cast<size_t>(f)];
    TextureLevel level0;
    level0.width = w;
    level0.height = h;
    for (int t = 0; t < w * h; ++t) level0.texels.emplace_back(0.1f + 0.8f * static_cast<float>(t % 7) / 6.0f, 0.5f, 0.3f + 0.1f * f, 1.0f);
    face.texture = build_mip_chain(std::move(level0));
    scene.faces.push_back(std::move(face));
  }
  return scene;
}

std::vector<Scene> test_scenes() {
  std::vector<Scene> scenes;
  for (const char* name : {"quad2", "plane", "cube", "paper"}) scenes.push_back(generate_scene(name, {}));
  scenes.push_back(grid_scene({{8, 2}, {1, 16}, {4, 4}, {1, 1}}));
  scenes.push_back(grid_scene({{32, 1}, {2, 64}, {16, 8}, {2, 2}}));
  return scenes;
}

RenderOptions options_of(Method method, TexelFormat texels, int msaa, int width, int height, int guard_band = 4) {
  RenderOptions o;
  o.method = method;
  o.texels = texels;
  o.msaa = msaa;
  o.width = width;
  o.height = height;
  o.guard_band = guard_band;
  return o;
}

size_t scene_copy_bytes(const Scene& scene) {
  size_t bytes = scene.positions.size() * sizeof(glm::vec3) + scene.faces.size() * sizeof(Face);
  for (const Face& face : scene.faces)
    for (const TextureLevel& level : face.texture.levels) bytes += sizeof(TextureLevel) + level.texels.size() * sizeof(glm::vec4);
  return bytes;
}

size_t packed_host_bytes(const PackedScene& p) {
  return p.positions.size() * sizeof(p.positions[0]) + p.faces.size() * sizeof(FaceGpu) +
         p.neighbors.size() * sizeof(FaceNeighbors) + p.level_offsets.size() * sizeof(uint32_t) + p.texture_bytes();
}

// ---------------------------------------------------------------- estimates vs pack_scene

TEST(Budget, PackedTextureMemoryIsExactForEveryScenesFormatAndBand) {
  int checked = 0;
  for (const Scene& scene : test_scenes()) {
    const SceneSizes sizes = scene_sizes(scene);
    ASSERT_EQ(sizes.faces.size(), scene.faces.size());
    EXPECT_EQ(sizes.vertices, scene.positions.size());
    for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
      // plane and paper have many faces: wide bands take seconds to build there, so narrow ones.
      const bool large = scene.name == "plane" || scene.name == "paper";
      const std::vector<int> bands = large ? std::vector<int>{0, 2} : std::vector<int>{0, 1, 3, 16};
      for (int band : bands) {
        SCOPED_TRACE(scene.name + " band " + std::to_string(band) + (format == TexelFormat::Rgba8 ? " rgba8" : " rgba32f"));
        const PackedScene packed = pack_scene(scene, format, band);
        const PackedTextureMemory m = packed_texture_memory(sizes, format, band);
        EXPECT_EQ(m.texture_bytes, packed.texture_bytes());
        EXPECT_EQ(m.padding_bytes, packed.padding_bytes());
        EXPECT_EQ(m.adjacency_bytes, packed.adjacency_bytes());
        EXPECT_EQ(m.texels, packed.texel_count());
        EXPECT_EQ(m.band_texels, packed.band_texels);
        EXPECT_EQ(m.levels, packed.level_offsets.size());
        if (band > 0) EXPECT_GT(m.padding_bytes, 0u);
        // pack_scene reserves exactly what it stores.
        if (format == TexelFormat::Rgba8) EXPECT_EQ(packed.texels8.capacity(), packed.texels8.size());
        else EXPECT_EQ(packed.texels32.capacity(), packed.texels32.size());
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 4 * 2 * 4 + 2 * 2 * 2);
}

TEST(Budget, SizesAloneGiveTheSameEstimateAsTheScene) {
  // What a service knows of an inline scene before building it: vertex count and texture sizes.
  const Scene scene = grid_scene({{8, 2}, {1, 16}, {4, 4}, {1, 1}});
  SceneSizes sizes;
  sizes.vertices = 9;
  sizes.faces = {{8, 2}, {1, 16}, {4, 4}, {1, 1}};
  const RenderOptions o = options_of(Method::Guardband, TexelFormat::Rgba32f, 4, 100, 60, 16);
  const RenderMemory from_sizes = render_memory(sizes, o), from_scene = render_memory(scene, o);
  EXPECT_EQ(from_sizes.device_bytes(), from_scene.device_bytes());
  EXPECT_EQ(from_sizes.host_bytes(), from_scene.host_bytes());
  // Hand count of the textures: levels 8x2,4x1,2x1,1x1 | 1x16,1x8,1x4,1x2,1x1 | 4x4,2x2,1x1 | 1x1,
  // each stored (w+32)x(h+32), 16 bytes a texel.
  const int levels[][2] = {{8, 2}, {4, 1}, {2, 1}, {1, 1}, {1, 16}, {1, 8}, {1, 4}, {1, 2}, {1, 1}, {4, 4}, {2, 2}, {1, 1}, {1, 1}};
  size_t stored = 0, own = 0;
  for (const auto& l : levels) stored += static_cast<size_t>((l[0] + 32) * (l[1] + 32)), own += static_cast<size_t>(l[0] * l[1]);
  EXPECT_EQ(from_sizes.textures.levels, 13u);
  EXPECT_EQ(from_sizes.textures.texture_bytes, stored * 16);
  EXPECT_EQ(from_sizes.textures.padding_bytes, (stored - own) * 16);
  // The frame: 7x4 tiles, 100*60*4 samples, 8 triangles' clip slots.
  EXPECT_EQ(from_sizes.samples, 100u * 60u * 4u * 4u);
  EXPECT_EQ(from_sizes.image, 100u * 60u * 16u);
  EXPECT_EQ(from_sizes.tiles, 7u * 4u * 3u * 4u);
  // Setups: the clip slots and a written-slot count (uint) per triangle. A list entry: the slot
  // (uint) and its rows in the tile (ushort).
  EXPECT_EQ(from_sizes.setups, 8u * SEAMCL_CLIP_SLOTS * sizeof(TriangleSetup) + 8u * sizeof(cl_uint));
  EXPECT_EQ(from_sizes.tile_lists, (8u * 8u + 65536u) * (sizeof(cl_uint) + sizeof(cl_ushort)));
  EXPECT_GE(from_sizes.tile_lists_bound, from_sizes.tile_lists);
  EXPECT_EQ(from_sizes.host_image, 100u * 60u * 16u);
  // The band counts only for guardband.
  RenderOptions discard = o;
  discard.method = Method::Discard;
  EXPECT_EQ(render_memory(sizes, discard).textures.padding_bytes, 0u);
  EXPECT_EQ(render_memory(sizes, discard).textures.texture_bytes, own * 16);
}

TEST(Budget, AbsurdSizesSaturateInsteadOfWrapping) {
  SceneSizes sizes;
  sizes.vertices = 4;
  sizes.faces.assign(1024, {1 << 30, 1 << 30});
  const RenderMemory m = render_memory(sizes, options_of(Method::Guardband, TexelFormat::Rgba32f, 16, 16384, 16384, 16));
  EXPECT_EQ(m.textures.texture_bytes, std::numeric_limits<size_t>::max());
  EXPECT_EQ(m.device_bytes(), std::numeric_limits<size_t>::max());
  EXPECT_EQ(m.host_bytes(), std::numeric_limits<size_t>::max());
  // The issue's case: 1024 faces of 2048x1, guardband 16, rgba32f: gigabytes, not the 2 M texels
  // that a level-0 texel count sees.
  SceneSizes thin;
  thin.vertices = 2050;
  thin.faces.assign(1024, {2048, 1});
  const RenderMemory issue = render_memory(thin, options_of(Method::Guardband, TexelFormat::Rgba32f, 1, 64, 64, 16));
  EXPECT_GT(issue.textures.texture_bytes, size_t{1} << 30);
  EXPECT_GT(issue.host_scene, size_t{1} << 25);  // the Renderer's float copy of every level
}

// ---------------------------------------------------------------- estimates vs the Renderer

TEST(Budget, RenderMemoryIsWhatAFreshRendererAllocates) {
  struct Case {
    const char* scene;
    RenderOptions options;
  };
  const std::vector<Case> cases = {
      {"quad2", options_of(Method::Discard, TexelFormat::Rgba8, 1, 64, 48)},
      {"quad2", options_of(Method::Guardband, TexelFormat::Rgba32f, 4, 37, 21, 8)},
      {"cube", options_of(Method::Traverse, TexelFormat::Rgba8, 8, 120, 90)},
      {"grid", options_of(Method::Guardband, TexelFormat::Rgba8, 2, 16, 16, 16)},
      {"grid", options_of(Method::Clamp, TexelFormat::Rgba32f, 16, 5, 3)},
      // 4,948 triangles: binning's counters for five chunks (frame_params.h, bin_chunks).
      {"paper", options_of(Method::Discard, TexelFormat::Rgba8, 1, 96, 64)},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(std::string(c.scene) + " " + to_json(c.options).dump());
    const Scene scene = std::string(c.scene) == "grid" ? grid_scene({{8, 2}, {1, 16}, {4, 4}, {1, 1}})
                                                       : generate_scene(c.scene, {});
    const RenderMemory expected = render_memory(scene, c.options);
    Renderer renderer(seamcl_tests::shared_runtime());
    EXPECT_EQ(renderer.device_bytes(), expected.constants);  // before any scene
    renderer.load_scene(scene, c.options.texels);
    const RenderResult result = renderer.render(scene.camera, c.options);
    ASSERT_EQ(result.attempts, 1);  // tile lists at their initial size
    EXPECT_EQ(renderer.device_bytes(), expected.device_bytes());
    EXPECT_LE(renderer.device_bytes(), expected.device_bytes_bound());
    EXPECT_EQ(result.pixels.size() * sizeof(glm::vec4), expected.host_image);
    EXPECT_EQ(packed_host_bytes(renderer.packed_scene()), expected.host_packed);
    EXPECT_EQ(scene_copy_bytes(renderer.scene()), expected.host_scene);
    EXPECT_EQ(renderer.packed_scene().texture_bytes(), expected.textures.texture_bytes);
  }
}

TEST(Budget, ReleaseFrameBuffersFreesThemAndTheNextRenderIsIdentical) {
  const Scene scene = generate_scene("quad2", {});
  const RenderOptions big = options_of(Method::Discard, TexelFormat::Rgba8, 8, 512, 384);
  const RenderOptions small = options_of(Method::Discard, TexelFormat::Rgba8, 1, 32, 32);
  const RenderMemory big_memory = render_memory(scene, big), small_memory = render_memory(scene, small);
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  const RenderResult first = renderer.render(scene.camera, big);
  const size_t held = renderer.device_bytes();
  EXPECT_EQ(held, big_memory.device_bytes());
  EXPECT_GT(held, size_t{512 * 384 * 8 * 4});

  // A small frame afterwards still holds the big one's buffers: they only grow.
  renderer.render(scene.camera, small);
  EXPECT_EQ(renderer.device_bytes(), held);

  renderer.release_frame_buffers();
  EXPECT_EQ(renderer.device_bytes(), small_memory.scene_device_bytes() + small_memory.constants);
  EXPECT_EQ(renderer.last_frame_params().width, 0);
  EXPECT_TRUE(renderer.read_sample_triangles().empty());
  EXPECT_TRUE(renderer.read_tile_lists().empty());
  EXPECT_TRUE(renderer.read_setups().empty());
  renderer.render(scene.camera, small);
  EXPECT_EQ(renderer.device_bytes(), small_memory.device_bytes());

  renderer.release_frame_buffers();
  const RenderResult again = renderer.render(scene.camera, big);
  EXPECT_EQ(renderer.device_bytes(), held);
  ASSERT_EQ(again.pixels.size(), first.pixels.size());
  EXPECT_EQ(std::memcmp(again.pixels.data(), first.pixels.data(), first.pixels.size() * sizeof(glm::vec4)), 0);

  // Dropping the scene too leaves only the per-Renderer constants; rendering needs a scene again.
  renderer.release_scene();
  EXPECT_FALSE(renderer.has_scene());
  EXPECT_EQ(renderer.device_bytes(), big_memory.constants);
  EXPECT_EQ(renderer.packed_scene().texture_bytes(), 0u);
  EXPECT_THROW(renderer.render(scene.camera, big), std::logic_error);
  renderer.load_scene(scene);
  const RenderResult reloaded = renderer.render(scene.camera, big);
  EXPECT_EQ(std::memcmp(reloaded.pixels.data(), first.pixels.data(), first.pixels.size() * sizeof(glm::vec4)), 0);
  EXPECT_EQ(renderer.device_bytes(), held);
}

TEST(Budget, RepackInAnotherFormatOrBandHoldsOnlyTheNewPacking) {
  // load_scene and a render in another format or band free the old packing before the new one.
  const Scene scene = generate_scene("cube", {});
  const RenderOptions banded = options_of(Method::Guardband, TexelFormat::Rgba32f, 1, 32, 32, 16);
  const RenderOptions plain = options_of(Method::Discard, TexelFormat::Rgba8, 1, 32, 32);
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  renderer.render(scene.camera, banded);
  EXPECT_EQ(renderer.device_bytes(), render_memory(scene, banded).device_bytes());
  renderer.render(scene.camera, plain);
  EXPECT_EQ(renderer.device_bytes(), render_memory(scene, plain).device_bytes());
}

TEST(Budget, TheAdjacencyIsPackedOnlyForTheRendersThatReadIt) {
  // 48 bytes a face (4.75 MB at 99,037 faces): discard, clamp and black never read it.
  const Scene scene = generate_scene("paper", {});
  const RenderOptions discard = options_of(Method::Discard, TexelFormat::Rgba8, 4, 64, 48);
  RenderOptions traverse = discard;
  traverse.method = Method::Traverse;
  RenderOptions black = discard;
  black.method = Method::Black;
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  renderer.render(scene.camera, discard);
  EXPECT_TRUE(renderer.packed_scene().neighbors.empty());
  const RenderMemory without = render_memory(scene, discard);
  EXPECT_EQ(without.neighbors, sizeof(FaceNeighbors));  // OpenCL's one-element minimum
  EXPECT_EQ(renderer.device_bytes(), without.device_bytes());
  EXPECT_EQ(packed_host_bytes(renderer.packed_scene()), without.host_packed);

  // A seam mask reads it: the first such render adds it to the packing, as the estimate says.
  const RenderResult masked = renderer.render(scene.camera, black, true);
  ASSERT_EQ(renderer.packed_scene().neighbors.size(), scene.faces.size());
  const RenderMemory with_mask = render_memory(scene, black, true);
  EXPECT_EQ(with_mask.neighbors, scene.faces.size() * sizeof(FaceNeighbors));
  EXPECT_EQ(with_mask.seam_mask, size_t{64 * 48});
  EXPECT_EQ(renderer.device_bytes(), with_mask.device_bytes());
  EXPECT_EQ(packed_host_bytes(renderer.packed_scene()), with_mask.host_packed);

  // Added later or packed with the textures (a Renderer loaded in RGBA32F repacks for this RGBA8
  // render), it is pack_scene's adjacency: traverse renders identically, and the mask is the same.
  const RenderResult later = renderer.render(scene.camera, traverse);
  Renderer fresh(seamcl_tests::shared_runtime());
  fresh.load_scene(scene, TexelFormat::Rgba32f);
  const RenderResult first = fresh.render(scene.camera, traverse);
  EXPECT_EQ(fresh.device_bytes(), render_memory(scene, traverse).device_bytes());
  const std::vector<FaceNeighbors> packed_with_textures = pack_scene(scene).neighbors;
  ASSERT_EQ(packed_with_textures.size(), scene.faces.size());
  EXPECT_EQ(std::memcmp(packed_with_textures.data(), renderer.packed_scene().neighbors.data(),
                        scene.faces.size() * sizeof(FaceNeighbors)),
            0);
  ASSERT_EQ(later.pixels.size(), first.pixels.size());
  EXPECT_EQ(std::memcmp(later.pixels.data(), first.pixels.data(), first.pixels.size() * sizeof(glm::vec4)), 0);
  EXPECT_TRUE(std::memcmp(fresh.packed_scene().neighbors.data(), renderer.packed_scene().neighbors.data(),
                          scene.faces.size() * sizeof(FaceNeighbors)) == 0);
  EXPECT_EQ(fresh.render(scene.camera, black, true).seam_mask, masked.seam_mask);

  // A repack for a method without it leaves it out again.
  RenderOptions discard32 = discard;
  discard32.texels = TexelFormat::Rgba32f;
  renderer.release_frame_buffers();
  renderer.render(scene.camera, discard32);
  EXPECT_TRUE(renderer.packed_scene().neighbors.empty());
  EXPECT_EQ(renderer.device_bytes(), render_memory(scene, discard32).device_bytes());

  // Guardband builds it for its bands and keeps none (its kernels never read it); its bands are
  // those of a packing made with it.
  const RenderOptions banded = options_of(Method::Guardband, TexelFormat::Rgba8, 1, 64, 48, 4);
  renderer.release_frame_buffers();
  renderer.render(scene.camera, banded);
  EXPECT_TRUE(renderer.packed_scene().neighbors.empty());
  EXPECT_EQ(renderer.device_bytes(), render_memory(scene, banded).device_bytes());
  EXPECT_TRUE(renderer.packed_scene().texels8 == pack_scene(scene, TexelFormat::Rgba8, 4).texels8);
}

// `count` screen-filling quads stacked towards the camera: every triangle lands on every tile, so
// the tile lists outgrow their initial size.
Scene stacked_quads(int count) {
  Scene scene;
  scene.name = "stacked";
  for (int k = 0; k < count; ++k) {
    const float z = -0.01f * static_cast<float>(k);
    const uint32_t base = static_cast<uint32_t>(scene.positions.size());
    for (const auto& [x, y] : {std::pair{-3.0f, -3.0f}, {3.0f, -3.0f}, {3.0f, 3.0f}, {-3.0f, 3.0f}}) scene.positions.emplace_back(x, y, z);
    Face face;
    face.vertices = {base, base + 1, base + 2, base + 3};
    TextureLevel texel;
    texel.width = texel.height = 1;
    texel.texels = {glm::vec4(0.5f, 0.4f, 0.3f, 1.0f)};
    face.texture = build_mip_chain(std::move(texel));
    scene.faces.push_back(std::move(face));
  }
  return scene;
}

TEST(Budget, TileListGrowthStaysUnderTheBoundAndALimitRefusesIt) {
  const Scene scene = stacked_quads(24);
  const RenderOptions options = options_of(Method::Discard, TexelFormat::Rgba8, 1, 1024, 1024);
  const RenderMemory expected = render_memory(scene, options);
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  const RenderResult grown = renderer.render(scene.camera, options);
  ASSERT_EQ(grown.attempts, 2);  // the lists overflowed once
  EXPECT_GT(renderer.device_bytes(), expected.device_bytes());
  EXPECT_LE(renderer.device_bytes(), expected.device_bytes_bound());

  // With the estimate as the limit, the growth is refused before it is allocated.
  Renderer limited(seamcl_tests::shared_runtime());
  limited.set_device_byte_limit(expected.device_bytes());
  limited.load_scene(scene);
  try {
    limited.render(scene.camera, options);
    ADD_FAILURE() << "no OverBudget";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "size");
    EXPECT_EQ(e.limit_bytes(), expected.device_bytes());
    EXPECT_GT(e.needed_bytes(), expected.device_bytes());
  }
  EXPECT_EQ(limited.device_bytes(), expected.device_bytes());
  // A limit that allows the growth renders the same image.
  limited.set_device_byte_limit(expected.device_bytes_bound());
  const RenderResult again = limited.render(scene.camera, options);
  EXPECT_EQ(std::memcmp(again.pixels.data(), grown.pixels.data(), grown.pixels.size() * sizeof(glm::vec4)), 0);
}

// Every Renderer the command line makes is held to the machine (limit_to_machine): a crowded
// frame's tile lists may not grow past it. A device of just the estimate's bytes stands in for a
// machine that cannot hold the growth, which the limit then refuses as it refuses render's.
TEST(Budget, CommandLineRenderersAreHeldToTheMachine) {
  const Scene scene = stacked_quads(24);
  const RenderOptions options = options_of(Method::Discard, TexelFormat::Rgba8, 1, 1024, 1024);
  const RenderMemory expected = render_memory(scene, options);
  DeviceInfo cpu;
  cpu.host_unified_memory = true;
  DeviceInfo small_gpu;
  small_gpu.global_memory_bytes = expected.device_bytes();
  Renderer renderer(seamcl_tests::shared_runtime());
  EXPECT_EQ(renderer.device_byte_limit(), 0u);  // a Renderer of its own is unbounded
  limit_to_machine(renderer, cpu);
  EXPECT_EQ(renderer.device_byte_limit(), physical_memory_bytes());
  limit_to_machine(renderer, small_gpu);
  EXPECT_EQ(renderer.device_byte_limit(), expected.device_bytes());
  renderer.load_scene(scene);
  try {
    renderer.render(scene.camera, options);
    ADD_FAILURE() << "tile lists grew past the device's memory";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "size");
    EXPECT_EQ(e.limit_bytes(), small_gpu.global_memory_bytes);
    EXPECT_NE(std::string(e.what()).find("this frame's tile lists"), std::string::npos) << e.what();
  }
}

// The Renderers that library code makes for the command line take the limit from their settings:
// a sweep's (bench --sweep) refuses the same growth.
TEST(Budget, SweepRenderersAreHeldToTheGivenLimit) {
  const RenderOptions crowded = options_of(Method::Discard, TexelFormat::Rgba8, 1, 1024, 1024);
  SweepSettings settings;
  settings.base = crowded;
  settings.base.scene = "stacked";
  settings.methods = {"discard"};
  settings.repeats = 1;
  settings.make_scene = [](const GeneratorOptions&) { return stacked_quads(24); };
  settings.device_byte_limit = render_memory(stacked_quads(24), crowded).device_bytes();
  try {
    run_scaling_sweeps(seamcl_tests::shared_runtime(), {SweepAxis::Msaa}, settings);
    ADD_FAILURE() << "the sweep's tile lists grew past its limit";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "size");
    EXPECT_EQ(e.limit_bytes(), settings.device_byte_limit);
  }
}

// A 24x16 discard frame of the built-in scene `name`, as a compare's frame.
RenderOptions compare_frame(const std::string& name) {
  RenderOptions frame = options_of(Method::Discard, TexelFormat::Rgba8, 1, 24, 16);
  frame.scene = name;
  return frame;
}

ReferenceSettings uncached_reference(int msaa) {
  ReferenceSettings settings;
  settings.use_cache = false;
  settings.msaa = msaa;
  return settings;
}

TEST(Budget, CompareMemoryBoundsWhatTheCompareHolds) {
  const Scene scene = generate_scene("quad2", {});
  const RenderOptions frame = compare_frame("quad2");
  const ReferenceSettings settings = uncached_reference(1);
  const std::vector<MethodEntry> entries =
      method_entries(to_json(frame), {"discard", "guardband", "clamp"}, {1, 4});
  const CompareMemory expected = compare_memory(scene_sizes(scene), frame, entries, settings);
  ASSERT_EQ(expected.entries.size(), 6u);
  EXPECT_EQ(expected.reference.image, 24u * 8u * 16u * 8u * 16u);
  EXPECT_GE(expected.device_bytes_bound, expected.device_bytes);

  // The compare as the CLI and the service run it, with the device bytes seen at every step.
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene, frame.texels);
  size_t phase1 = renderer.device_bytes();
  const std::vector<uint8_t> mask = seam_mask(render_face_map(renderer, scene.camera, frame));
  phase1 = std::max(phase1, renderer.device_bytes());
  // prepare_targets' footprint masks, one per rate: they pack the adjacency (discard's packing has none).
  EXPECT_EQ(renderer.packed_scene().neighbors.size(), 0u);
  std::set<int> masked_rates;
  for (const MethodEntry& entry : entries) {
    if (!masked_rates.insert(entry.options.msaa).second) continue;
    EXPECT_EQ(footprint_seam_mask(renderer, scene.camera, entry.options).size(), size_t{24 * 16});
    phase1 = std::max(phase1, renderer.device_bytes());
  }
  EXPECT_EQ(renderer.packed_scene().neighbors.size(), scene.faces.size());
  renderer.release_frame_buffers();  // as prepare_targets does before the references
  // The reference as reference_images makes it: the 8x frame reduced on the device.
  const RenderResult reference = renderer.render_downsampled(scene.camera, reference_render_options(frame, settings),
                                                             mitchell_taps());
  ASSERT_EQ(reference.pixels.size(), size_t{24 * 16});
  phase1 = std::max(phase1, renderer.device_bytes());
  renderer.release_frame_buffers();
  EXPECT_EQ(phase1, expected.device_bytes);  // the reference phase is the larger, and exact
  size_t phase2 = 0;
  const std::vector<EntryResult> results =
      compare_methods(renderer, scene, scene.camera, entries, &reference.pixels, &mask, 2, [&] {
        phase2 = std::max(phase2, renderer.device_bytes());
        return false;
      });
  phase2 = std::max(phase2, renderer.device_bytes());
  EXPECT_EQ(results.size(), 6u);
  EXPECT_GT(phase2, 0u);
  EXPECT_LE(phase2, expected.device_bytes);
  // Host: at least the reduced reference, read back and copied, and the scene.
  EXPECT_GE(expected.host_bytes, 2 * reference.pixels.size() * sizeof(glm::vec4) + expected.reference.host_scene);
}

TEST(Budget, CompareMemoryCountsTheAnalyticAndSeamlessReferences) {
  const Scene scene = generate_scene("closeup-corner", {});
  const RenderOptions frame = compare_frame("closeup-corner");
  const ReferenceSettings settings = uncached_reference(4);
  const std::vector<MethodEntry> entries = method_entries(to_json(frame), {"discard"}, {1, 4});
  const SceneSizes sizes = scene_sizes(scene);

  // The seamless scene's sizes from the grid alone are those of the scene seamless_scene makes.
  const SceneSizes seamless_sizes = seamless_scene_sizes(scene);
  const Scene seamless = seamless_scene(scene);
  EXPECT_EQ(seamless_sizes.faces, scene_sizes(seamless).faces);
  EXPECT_EQ(seamless_sizes.vertices, scene_sizes(seamless).vertices);
  try {
    seamless_scene_sizes(generate_scene("paper", {}));
    ADD_FAILURE() << "paper has no seamless grid";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "reference");
  }
  EXPECT_THROW(compare_memory(sizes, frame, entries, settings, {ReferenceKind::Seamless}), std::logic_error);

  const CompareMemory paper = compare_memory(sizes, frame, entries, settings);
  const CompareMemory all = compare_memory(sizes, frame, entries, settings,
                                           {ReferenceKind::Paper, ReferenceKind::Analytic, ReferenceKind::Seamless},
                                           seamless_sizes);
  EXPECT_EQ(paper.analytic.image, 0u);
  EXPECT_EQ(paper.seamless.image, 0u);
  // The analytic reference renders the 8x frame at 1 sample, reads back its winners, setups and
  // image, and makes an albedo image as large: all of it on the host at once.
  EXPECT_EQ(all.analytic.samples, 24u * 8u * 16u * 8u * sizeof(uint32_t));
  EXPECT_EQ(all.analytic.image, 24u * 8u * 16u * 8u * sizeof(glm::vec4));
  EXPECT_GE(all.host_bytes, paper.host_bytes + 2 * all.analytic.host_image + all.analytic.setups);
  // The seamless Renderer at the largest rate, its scene the one face.
  EXPECT_EQ(all.seamless.samples, 24u * 16u * 4u * sizeof(uint32_t));
  EXPECT_EQ(all.seamless.scene_device_bytes(), render_memory(seamless, frame).scene_device_bytes());

  // The seamless phase as prepare_targets runs it: the first Renderer keeps its scene, the second
  // renders each rate; together they stay within the bound.
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene, frame.texels);
  const std::vector<ReferenceImage> high =
      reference_images(renderer, scene.camera, frame, settings, {ReferenceKind::Paper, ReferenceKind::Analytic});
  ASSERT_EQ(high.size(), 2u);
  Renderer second(seamcl_tests::shared_runtime());
  second.load_scene(seamless, frame.texels);
  size_t together = 0, second_peak = 0;
  for (int rate : {1, 4}) {
    RenderOptions measured = frame;
    measured.msaa = rate;
    seamless_reference(second, scene.camera, measured);
    together = std::max(together, renderer.device_bytes() + second.device_bytes());
    second_peak = std::max(second_peak, second.device_bytes());
  }
  EXPECT_EQ(second_peak, all.seamless.device_bytes());  // its buffers at the largest rate, exactly
  EXPECT_GT(together, renderer.device_bytes());
  EXPECT_LE(together, all.device_bytes_bound);
}

// ---------------------------------------------------------------- the reference cache's bound

fs::path fresh_dir(const std::string& stem) {
  const fs::path dir = fs::temp_directory_path() / (stem + "-" + std::to_string(::getpid()) + "-" +
                                                    std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  fs::create_directories(dir);
  return dir;
}

struct FakeReferences {
  Scene scene = generate_scene("quad2", {});
  RenderOptions frame;
  int renders = 0;
  FakeReferences() {
    frame.scene = "quad2";
    frame.width = 8;
    frame.height = 8;
  }
  // Camera i is its own cache key; every image has the same content, so every file the same size.
  Camera camera(int i) const {
    Camera c = scene.camera;
    c.eye.x = static_cast<float>(i);
    return c;
  }
  ReferenceImage get(int i, const ReferenceSettings& s) {
    return reference_image(scene, camera(i), frame, s, [&](const RenderOptions& high) {
      ++renders;
      RenderResult r;
      r.width = high.width;
      r.height = high.height;
      r.pixels.assign(static_cast<size_t>(high.width) * high.height, glm::vec4(0.25f, 0.5f, 0.75f, 1.0f));
      return r;
    });
  }
};

void set_last_use(const std::string& path, int seconds_ago) {
  fs::last_write_time(path, fs::file_time_type::clock::now() - std::chrono::seconds(seconds_ago));
}

TEST(ReferenceCache, BoundedLeastRecentlyUsedFirstAndAHitRefreshes) {
  const fs::path dir = fresh_dir("seamcl_cache_lru");
  FakeReferences refs;
  ReferenceSettings s;
  s.cache_dir = dir.string();
  s.msaa = 1;
  s.cache_max_bytes = 0;  // unbounded while measuring one entry
  const ReferenceImage a = refs.get(1, s);
  ASSERT_FALSE(a.cache_path.empty());
  const std::uintmax_t entry_bytes = fs::file_size(a.cache_path);
  ASSERT_GT(entry_bytes, 0u);

  s.cache_max_bytes = 3 * entry_bytes + entry_bytes / 2;  // room for three
  const ReferenceImage b = refs.get(2, s), c = refs.get(3, s);
  ASSERT_FALSE(b.cache_path.empty());
  ASSERT_FALSE(c.cache_path.empty());
  // Last uses in a known order, oldest first: a, b, c.
  set_last_use(a.cache_path, 300);
  set_last_use(b.cache_path, 200);
  set_last_use(c.cache_path, 100);
  EXPECT_EQ(refs.renders, 3);

  // A hit on a makes it the most recently used, and renders nothing.
  EXPECT_TRUE(refs.get(1, s).from_cache);
  EXPECT_EQ(refs.renders, 3);

  // A fourth entry: b, now the least recently used, goes; the others and the newest stay.
  const ReferenceImage d = refs.get(4, s);
  EXPECT_EQ(refs.renders, 4);
  EXPECT_FALSE(d.cache_path.empty());
  EXPECT_TRUE(fs::exists(a.cache_path));
  EXPECT_FALSE(fs::exists(b.cache_path));
  EXPECT_TRUE(fs::exists(c.cache_path));
  EXPECT_TRUE(fs::exists(d.cache_path));

  // And the next one removes c (a was used after c).
  set_last_use(d.cache_path, 10);
  const ReferenceImage e = refs.get(5, s);
  EXPECT_FALSE(fs::exists(c.cache_path));
  EXPECT_TRUE(fs::exists(a.cache_path));
  EXPECT_TRUE(fs::exists(d.cache_path));
  EXPECT_TRUE(fs::exists(e.cache_path));
  EXPECT_FALSE(refs.get(2, s).from_cache);  // b was really removed: rendered again

  // The total never exceeds the bound.
  std::uintmax_t total = 0;
  for (const auto& f : fs::directory_iterator(dir)) total += f.file_size();
  EXPECT_LE(total, s.cache_max_bytes);
  fs::remove_all(dir);
}

TEST(ReferenceCache, EntryCountBoundZeroMeansUnboundedAndOversizeIsNotKept) {
  const fs::path dir = fresh_dir("seamcl_cache_count");
  FakeReferences refs;
  ReferenceSettings s;
  s.cache_dir = dir.string();
  s.msaa = 1;
  s.cache_max_bytes = 0;
  s.cache_max_entries = 0;
  for (int i = 0; i < 6; ++i) refs.get(i, s);
  auto count = [&] {
    size_t n = 0;
    for (const auto& f : fs::directory_iterator(dir)) n += f.path().extension() == ".exr";
    return n;
  };
  EXPECT_EQ(count(), 6u);

  // Files that are not references are never touched; a dead writer's old temporary file is.
  std::ofstream(dir / "notes.txt") << "keep me";
  const fs::path stale_temp = dir / "reference-0123456789abcdef.exr.tmp1-2.exr";
  const fs::path live_temp = dir / "reference-fedcba9876543210.exr.tmp3-4.exr";
  std::ofstream(stale_temp) << "x";
  std::ofstream(live_temp) << "x";
  fs::last_write_time(stale_temp, fs::file_time_type::clock::now() - std::chrono::hours(2));

  const CacheTrim trim = trim_reference_cache(dir.string(), 0, 2);
  EXPECT_EQ(trim.kept_entries, 2u);
  EXPECT_EQ(trim.removed_entries, 4u);
  EXPECT_TRUE(fs::exists(dir / "notes.txt"));
  EXPECT_FALSE(fs::exists(stale_temp));
  EXPECT_TRUE(fs::exists(live_temp));
  fs::remove(live_temp);
  EXPECT_EQ(count(), 2u);

  // An entry alone over the byte bound is not kept; the reference is still returned.
  s.cache_max_bytes = 1;
  const ReferenceImage big = refs.get(42, s);
  EXPECT_TRUE(big.cache_path.empty());
  EXPECT_EQ(big.pixels.size(), 64u);
  EXPECT_EQ(count(), 0u);
  fs::remove_all(dir);
}

TEST(ReferenceCache, CompareCliTakesTheBoundAndRefusesANegativeOne) {
  const fs::path dir = fresh_dir("seamcl_cache_cli");
  const std::string run = "cd '" + dir.string() + "' && '" + SEAMCL_BINARY + "' compare --scene quad2 --size 8x8 ";
  const int bad = std::system((run + "--cache-max-mib -1 >out.txt 2>err.txt").c_str());
  EXPECT_EQ(WEXITSTATUS(bad), 2);
  std::ifstream err(dir / "err.txt");
  const std::string message((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find("cache_max_mib"), std::string::npos) << message;
  const int help = std::system((run + "--help >help.txt 2>&1").c_str());
  EXPECT_EQ(WEXITSTATUS(help), 0);
  std::ifstream help_text(dir / "help.txt");
  const std::string text((std::istreambuf_iterator<char>(help_text)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("--cache-max-mib"), std::string::npos);
  EXPECT_NE(text.find("--cache-max-entries"), std::string::npos);
  fs::remove_all(dir);
}

// ---------------------------------------------------------------- cancellation

TEST(Cancel, CompareMethodsStopsBetweenEntriesAndRepeats) {
  const Scene scene = generate_scene("quad2", {});
  RenderOptions frame = options_of(Method::Discard, TexelFormat::Rgba8, 1, 16, 16);
  const std::vector<MethodEntry> entries = method_entries(to_json(frame), {"discard", "clamp"}, {1});
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);

  // Never stopping: asked before each entry and before each of its `repeat` renders.
  int asked = 0;
  const auto results = compare_methods(renderer, scene, scene.camera, entries, nullptr, nullptr, 2, [&] {
    ++asked;
    return false;
  });
  EXPECT_EQ(results.size(), 2u);
  EXPECT_EQ(asked, 2 * (1 + 2));

  // Stop at the third question: before entry 1, before its render 1 (done), before its render 2.
  asked = 0;
  try {
    compare_methods(renderer, scene, scene.camera, entries, nullptr, nullptr, 2, [&] { return ++asked == 3; });
    ADD_FAILURE() << "not cancelled";
  } catch (const Cancelled& e) {
    EXPECT_NE(std::string(e.what()).find("discard"), std::string::npos) << e.what();
  }
  EXPECT_EQ(asked, 3);

  // Stop between entries: the fourth question is before the second entry.
  asked = 0;
  EXPECT_THROW(compare_methods(renderer, scene, scene.camera, entries, nullptr, nullptr, 2, [&] { return ++asked == 4; }),
               Cancelled);
  EXPECT_EQ(asked, 4);
  // Cancelled is neither an InputError nor caught as one.
  static_assert(!std::is_base_of_v<InputError, Cancelled>);
  // The Renderer is usable afterwards.
  EXPECT_EQ(renderer.render(scene.camera, frame).pixels.size(), 256u);
}

}  // namespace

// The command line's bound: a render is refused before it allocates when it would not fit the
// machine (physical memory; a separate device's own memory for its buffers), naming size when the
// frame drives it and scene otherwise.
TEST(Budget, CommandLineRendersMustFitTheMachine) {
  const size_t machine = physical_memory_bytes();
  ASSERT_GT(machine, size_t{1} << 26) << "sysconf reports the physical memory";
  DeviceInfo cpu;
  cpu.host_unified_memory = true;
  RenderMemory small;
  small.texels = 1 << 20;
  small.image = 1 << 20;
  EXPECT_NO_THROW(refuse_beyond_machine(small, 1, cpu, "this render"));
  RenderMemory big_scene = small;
  big_scene.setups = machine;  // a mesh's setup records
  try {
    refuse_beyond_machine(big_scene, 1, cpu, "this render");
    ADD_FAILURE() << "a render larger than the machine was let through";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "scene");  // the triangles' setups: a smaller image would not help
    EXPECT_EQ(e.limit_bytes(), machine);
    EXPECT_GT(e.needed_bytes(), machine);
  }
  RenderMemory big_image = small;
  big_image.samples = machine;  // a huge --size at 16x
  try {
    refuse_beyond_machine(big_image, 1, cpu, "this render");
    ADD_FAILURE() << "a frame larger than the machine was let through";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "size");
  }
  RenderMemory big_textures = small;
  big_textures.texels = machine;
  EXPECT_THROW(refuse_beyond_machine(big_textures, 1, cpu, "this render"), OverBudget);
  // A separate device: its buffers against its own memory, the host's bytes against the machine's.
  DeviceInfo gpu;
  gpu.global_memory_bytes = size_t{1} << 24;
  try {
    refuse_beyond_machine(big_textures, 1, gpu, "this render");
    ADD_FAILURE() << "device bytes past the device's memory were let through";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "scene");
    EXPECT_EQ(e.limit_bytes(), gpu.global_memory_bytes);
  }
  EXPECT_EQ(device_memory_bound(cpu), machine);
  EXPECT_EQ(device_memory_bound(gpu), gpu.global_memory_bytes);
}

// A render is refused naming the largest share of the figure over its limit, as a compare and a
// bench are: the samples of a multisampled frame are msaa's doing (the old refusal said size for
// any frame), a single-sampled frame's buffers size's, a scene's packing and setups scene's, at
// any rate. Each on a device one byte too small for the render's device bytes.
TEST(Budget, ARenderIsRefusedNamingTheLargestShareOfTheLimitItExceeds) {
  GeneratorOptions deferred;
  deferred.defer_textures = true;
  const SceneSizes quad2 = scene_sizes(generate_scene("quad2", deferred));
  const SceneSizes paper = scene_sizes(generate_scene("paper", deferred));
  struct Case {
    const SceneSizes* scene;
    int size, msaa;
    std::string field;
  };
  for (const Case& c : {Case{&quad2, 512, 16, "msaa"}, Case{&quad2, 512, 1, "size"}, Case{&paper, 16, 1, "scene"},
                        Case{&paper, 16, 16, "scene"}}) {
    SCOPED_TRACE(std::to_string(c.scene->faces.size()) + " faces at " + std::to_string(c.size) + " msaa " + std::to_string(c.msaa));
    RenderOptions options;
    options.width = options.height = c.size;
    options.msaa = c.msaa;
    const RenderMemory memory = render_memory(*c.scene, options);
    DeviceInfo small_gpu;
    small_gpu.global_memory_bytes = memory.device_bytes() - 1;
    try {
      refuse_beyond_machine(memory, options.msaa, small_gpu, "this render");
      ADD_FAILURE() << "a render past the device's memory was let through";
    } catch (const OverBudget& e) {
      EXPECT_EQ(e.field(), c.field);
      EXPECT_EQ(e.needed_bytes(), memory.device_bytes());
      EXPECT_EQ(e.limit_bytes(), small_gpu.global_memory_bytes);
      EXPECT_NE(std::string(e.what()).find("this render (device memory) needs"), std::string::npos) << e.what();
    }
    DeviceInfo fitting_gpu;
    fitting_gpu.global_memory_bytes = memory.device_bytes();
    EXPECT_NO_THROW(refuse_beyond_machine(memory, options.msaa, fitting_gpu, "this render"));
  }
}

// compare and bench refuse a run the machine cannot hold as render does, from the run's figures
// split by what drives them: the limit exceeded names the largest share of what it compares (the
// device and host figures together where the device shares the host's memory).
TEST(Budget, CommandLineComparesAndBenchesMustFitTheMachine) {
  const size_t machine = physical_memory_bytes();
  DeviceInfo cpu;
  cpu.host_unified_memory = true;
  EXPECT_NO_THROW(refuse_beyond_machine(MemoryShares("size", 1 << 20), MemoryShares("size", 1 << 20), cpu, "this compare"));
  // Together: the host's frames outweigh the device's scene, though neither is over alone.
  try {
    refuse_beyond_machine(MemoryShares("scene", machine / 2 - 1), MemoryShares("frames", machine / 2 + 2), cpu, "this bench");
    ADD_FAILURE() << "a bench larger than the machine was let through";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "frames");
    EXPECT_EQ(e.needed_bytes(), machine + 1);
    EXPECT_NE(std::string(e.what()).find("this bench needs"), std::string::npos) << e.what();
  }
  MemoryShares device_by_msaa("size", size_t{1} << 23);
  device_by_msaa.add("msaa", size_t{1} << 24);
  device_by_msaa.add("scene", size_t{1} << 22);
  DeviceInfo gpu;
  gpu.global_memory_bytes = size_t{1} << 24;
  try {
    refuse_beyond_machine(device_by_msaa, MemoryShares("frames", 1 << 20), gpu, "this bench");
    ADD_FAILURE() << "device bytes past the device's memory were let through";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "msaa");  // the device's own largest share, not the host's
    EXPECT_EQ(e.limit_bytes(), gpu.global_memory_bytes);
    EXPECT_EQ(e.needed_bytes(), device_by_msaa.total());
    EXPECT_NE(std::string(e.what()).find("(device memory)"), std::string::npos) << e.what();
  }
  // Host memory over on a separate device: the host's largest share, whatever drives the device.
  MemoryShares host_by_frames("size", 1 << 20);
  host_by_frames.add("frames", machine);
  try {
    refuse_beyond_machine(device_by_msaa, host_by_frames, gpu, "this bench");
    ADD_FAILURE() << "host bytes past the machine's memory were let through";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "frames");
    EXPECT_EQ(e.limit_bytes(), machine);
    EXPECT_NE(std::string(e.what()).find("(host memory)"), std::string::npos) << e.what();
  }

}

// A bench is refused naming what drives the figure over its limit: the Renderers' samples at a
// measured rate of 16 on a device too small for them (msaa), the distances pooled over a million
// frames on the host (frames), the 8x reference's buffers (size), a scene's textures (scene).
TEST(Budget, BenchMemoryNamesWhatDrivesTheLimitItExceeds) {
  const SceneSizes quad2 = scene_sizes(generate_scene("quad2", GeneratorOptions{}));
  RenderOptions frame;
  frame.width = frame.height = 256;
  const std::vector<MethodEntry> entries = method_entries(to_json(frame), {"discard", "traverse"}, {16});
  const BenchRun one_frame{false, 0, 1, 1};
  const BenchMemory multisampled = bench_memory(quad2, frame, entries, ReferenceSettings{}, one_frame);
  EXPECT_EQ(multisampled.device.field(), "msaa");
  // two methods' samples beyond one per pixel
  EXPECT_EQ(multisampled.device.share("msaa"), 2 * size_t{256} * 256 * 15 * sizeof(uint32_t));
  DeviceInfo small_gpu;
  small_gpu.global_memory_bytes = multisampled.device.total() - 1;
  try {
    refuse_beyond_machine(multisampled.device, multisampled.host, small_gpu, "this bench");
    ADD_FAILURE() << "a bench past the device's memory was let through";
  } catch (const OverBudget& e) {
    EXPECT_EQ(e.field(), "msaa");
    EXPECT_EQ(e.needed_bytes(), multisampled.device.total());
    EXPECT_NE(std::string(e.what()).find("this bench (device memory) needs"), std::string::npos) << e.what();
  }

  // A million frames: the difference pool holds a distance and a mask byte per pixel and frame.
  const BenchRun million{false, 0, 1, 1000000};
  const BenchMemory pooled = bench_memory(quad2, frame, entries, ReferenceSettings{}, million);
  EXPECT_EQ(pooled.device.total(), multisampled.device.total());  // the Renderers are the same
  EXPECT_EQ(pooled.host.field(), "frames");
  EXPECT_GE(pooled.host.share("frames"), size_t{256} * 256 * 5 * 1000000);
  DeviceInfo cpu;
  cpu.host_unified_memory = true;
  DeviceInfo large_gpu;
  large_gpu.global_memory_bytes = size_t{1} << 40;
  for (const DeviceInfo& device : {cpu, large_gpu}) {
    try {
      refuse_beyond_machine(pooled.device, pooled.host, device, "this bench");
      ADD_FAILURE() << "a bench past the machine's memory was let through";
    } catch (const OverBudget& e) {
      EXPECT_EQ(e.field(), "frames");
      EXPECT_EQ(e.limit_bytes(), physical_memory_bytes());
    }
  }

  // With errors the reference's Renderer renders the 8x frame: its buffers outweigh the methods'.
  const BenchMemory referenced = bench_memory(quad2, frame, entries, ReferenceSettings{}, {true, 1, 1, 1});
  EXPECT_EQ(referenced.device.field(), "size");
  // Large textures: every Renderer's packing and Scene copy.
  SceneSizes textured = quad2;
  for (auto& face : textured.faces) face = {4096, 4096};
  const BenchMemory heavy = bench_memory(textured, frame, entries, ReferenceSettings{}, one_frame);
  EXPECT_EQ(heavy.device.field(), "scene");
  EXPECT_EQ(heavy.host.field(), "scene");
}

// A compare's figures split by what drives them: the phase that needs most, its frame buffers the
// size's (the 8x reference's) or the msaa's (a measured rate's above 1), its scene's buffers,
// setups and tile lists the scene's. The shares add up to the figure they split.
TEST(Budget, CompareMemoryNamesWhatDrivesEachFigure) {
  const SceneSizes quad2 = scene_sizes(generate_scene("quad2", GeneratorOptions{}));
  RenderOptions frame;
  frame.width = 64;
  frame.height = 64;
  const std::vector<MethodEntry> entries = method_entries(nlohmann::json{{"size", "64x64"}}, {"discard"}, {1, 16});
  const CompareMemory small = compare_memory(quad2, frame, entries, ReferenceSettings{});
  EXPECT_EQ(small.device_shares.field(), "size");
  EXPECT_EQ(small.device_bound_shares.field(), "size");
  EXPECT_EQ(small.host_shares.field(), "size");
  EXPECT_EQ(small.device_shares.total(), small.device_bytes);
  EXPECT_EQ(small.device_bound_shares.total(), small.device_bytes_bound);
  EXPECT_EQ(small.host_shares.total(), small.host_bytes);
  // The totals above are set from the shares, so those checks pin nothing; these can fail: a figure
  // holds at least each render it includes, and its bound at least the figure.
  for (const RenderMemory& entry : small.entries) EXPECT_GE(small.device_bytes, entry.device_bytes());
  EXPECT_GE(small.device_bytes, small.reference.device_bytes());
  EXPECT_GE(small.device_bytes_bound, small.device_bytes);
  // The device reduces the 8x frame: the host reads back, keeps and copies a frame-sized image.
  const size_t frame_image = size_t{64} * 64 * sizeof(glm::vec4);
  EXPECT_GE(small.host_bytes, 2 * frame_image);
  // The 8x reference's phase: its samples and image, and the downsample's row pass (8 frame
  // images), result and weights, are all of the frame's share.
  EXPECT_EQ(small.device_shares.share("size"), small.reference.tiles + small.reference.samples +
                                                   small.reference.image + 9 * frame_image +
                                                   mitchell_taps().weights.size() * sizeof(float));
  // A scene whose packing outweighs the frames, on the device and in the Renderer's packed copy.
  SceneSizes textured = quad2;
  for (auto& face : textured.faces) face = {4096, 4096};
  const CompareMemory heavy = compare_memory(textured, frame, entries, ReferenceSettings{});
  EXPECT_EQ(heavy.device_shares.field(), "scene");
  EXPECT_EQ(heavy.host_shares.field(), "scene");
  // Without an 8x reference (seamless only), a measured rate of 16 has the largest frame buffers.
  const Scene corner = generate_scene("closeup-corner", {});
  RenderOptions large = frame;
  large.width = large.height = 1024;
  const CompareMemory multisampled =
      compare_memory(scene_sizes(corner), large, method_entries(to_json(large), {"discard"}, {1, 16}), ReferenceSettings{},
                     {ReferenceKind::Seamless}, seamless_scene_sizes(corner));
  EXPECT_EQ(multisampled.device_shares.field(), "msaa");
  // the 16x entry's samples beyond one per pixel
  EXPECT_EQ(multisampled.device_shares.share("msaa"), size_t{1024} * 1024 * 15 * sizeof(uint32_t));
  EXPECT_EQ(multisampled.host_shares.field(), "size");  // the host holds no samples
}

// The service refuses a compare on device_bytes_bound, with the tile lists at their bound: the
// field it names weighs them at that bound too. The paper scene's 4,948 triangles at 128x128:
// with the lists at their first size its packing drives the figure (scene), at their bound (every
// slot on every tile of the 8x reference's frame, 13x the figure) the frame's tiles do (size),
// as the Renderer names a refused growth of its lists.
TEST(Budget, CompareMemoryNamesWhatDrivesTheTileListBound) {
  GeneratorOptions deferred;
  deferred.defer_textures = true;
  const SceneSizes paper = scene_sizes(generate_scene("paper", deferred));
  RenderOptions frame;
  frame.width = frame.height = 128;
  const CompareMemory m =
      compare_memory(paper, frame, method_entries(nlohmann::json{{"size", "128x128"}}, {"discard"}, {1}), ReferenceSettings{});
  ASSERT_GT(m.device_bytes_bound, 10 * m.device_bytes);
  EXPECT_EQ(m.device_shares.field(), "scene");
  EXPECT_EQ(m.device_bound_shares.field(), "size");
  EXPECT_EQ(m.device_bound_shares.share("size") - m.device_shares.share("size"),
            m.reference.tile_lists_bound - m.reference.tile_lists);  // the reference's phase, its lists grown
  EXPECT_EQ(m.device_bound_shares.share("scene"), m.device_shares.share("scene"));
}
