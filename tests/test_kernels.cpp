// Every kernel held to its scalar C++ twin: each stage's twin is fed the GPU's input to that
// stage (so a difference points at one stage) on built-in scenes and on random ones.
// Tolerances: integers (edge functions, boxes, bins, winners, fragment counts) must match
// exactly; floats within a few ulps (the kernels build with FP_CONTRACT OFF, so they round as
// the twins do; a tolerance only absorbs the device's math-library builtins such as log2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/frame_params.h"
#include "test_support.h"
#include "pipeline/stages/binning_twin.h"
#include "pipeline/stages/raster_twin.h"
#include "pipeline/stages/sample_pattern.h"
#include "pipeline/stages/shade_resolve_twin.h"
#include "pipeline/stages/texture_sample_twin.h"
#include "pipeline/stages/triangle_setup_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

TextureLevel random_level(std::mt19937& rng, int width, int height) {
  TextureLevel level{width, height, {}};
  for (int i = 0; i < width * height; ++i) {
    level.texels.emplace_back(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1), 1.0f);
  }
  return level;
}

// Quads of random size, orientation and texture size scattered around the origin, some facing
// away, some crossing the camera's near plane, some far outside the view.
Scene random_scene(uint32_t seed, int quads) {
  std::mt19937 rng(seed);
  Scene scene;
  scene.name = "random";
  for (int q = 0; q < quads; ++q) {
    const glm::vec3 center(uniform(rng, -6, 6), uniform(rng, -6, 6), uniform(rng, -6, 6));
    const glm::vec3 a = glm::normalize(glm::vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)) + 1e-3f);
    glm::vec3 b = glm::cross(a, glm::normalize(glm::vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), 1.0f)));
    b = glm::normalize(b);
    const float su = uniform(rng, 0.05f, 4.0f), sv = uniform(rng, 0.002f, 4.0f);  // slivers too
    const uint32_t base = static_cast<uint32_t>(scene.positions.size());
    scene.positions.push_back(center - a * su - b * sv);
    scene.positions.push_back(center + a * su - b * sv);
    scene.positions.push_back(center + a * su + b * sv);
    scene.positions.push_back(center - a * su + b * sv);
    Face face;
    face.vertices = {base, base + 1, base + 2, base + 3};
    face.texture = build_mip_chain(random_level(rng, 1 << (rng() % 6), 1 << (rng() % 6)));
    scene.faces.push_back(std::move(face));
  }
  scene.camera.eye = glm::vec3(uniform(rng, -4, 4), uniform(rng, -4, 4), uniform(rng, 3, 8));
  scene.camera.target = glm::vec3(0.0f);
  scene.camera.fov_y_degrees = uniform(rng, 30, 90);
  return scene;
}

void expect_plane_near(const cl_float* gpu, const cl_float* twin, const char* what, size_t slot) {
  for (int i = 0; i < 3; ++i) {
    const float scale = std::max({std::fabs(twin[i]), std::fabs(gpu[i]), 1e-6f});
    EXPECT_LE(std::fabs(gpu[i] - twin[i]) / scale, 1e-5f) << what << "[" << i << "] of slot " << slot;
  }
}

struct KernelCase {
  std::string name;
  Scene scene;
  RenderOptions options;
};

std::vector<KernelCase> kernel_cases() {
  std::vector<KernelCase> out;
  auto options = [](int w, int h, int msaa, ShadingMode shading) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.msaa = msaa;
    o.shading = shading;
    return o;
  };
  out.push_back({"paper", generate_scene("paper", {}), options(120, 135, 4, ShadingMode::Pixel)});
  out.push_back({"quad2", generate_scene("quad2", {}), options(67, 45, 8, ShadingMode::Centroid)});
  out.push_back({"plane", generate_scene("plane", {}), options(96, 64, 2, ShadingMode::Pixel)});
  out.push_back({"cube", generate_scene("cube", {}), options(50, 50, 16, ShadingMode::Sample)});
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    const int msaa = 1 << (seed % 5);
    out.push_back({"random" + std::to_string(seed), random_scene(seed, 40),
                   options(40 + static_cast<int>(seed) * 13, 37 + static_cast<int>(seed) * 7, msaa,
                           static_cast<ShadingMode>(seed % 3))});
  }
  return out;
}

}  // namespace

TEST(KernelVsTwin, EveryStageOnBuiltInAndRandomScenes) {
  Renderer renderer(shared_runtime());
  for (const KernelCase& c : kernel_cases()) {
    SCOPED_TRACE(c.name);
    renderer.load_scene(c.scene);
    const RenderResult result = renderer.render(c.scene.camera, c.options);
    const FrameParams frame = renderer.last_frame_params();
    const PackedScene& packed = renderer.packed_scene();

    // Setup: integers exact, planes within a few ulps.
    const std::vector<TriangleSetup> gpu_setups = renderer.read_setups();
    const std::vector<TriangleSetup> twin_setups = setup_triangles_reference(packed, frame);
    ASSERT_EQ(gpu_setups.size(), twin_setups.size());
    uint32_t non_empty = 0;
    for (size_t slot = 0; slot < gpu_setups.size(); ++slot) {
      const TriangleSetup& g = gpu_setups[slot];
      const TriangleSetup& t = twin_setups[slot];
      ASSERT_EQ(setup_is_empty(g), setup_is_empty(t)) << "slot " << slot;
      if (setup_is_empty(g)) continue;
      ++non_empty;
      for (int i = 0; i < 3; ++i) {
        ASSERT_EQ(g.edge_a[i], t.edge_a[i]) << "slot " << slot;
        ASSERT_EQ(g.edge_b[i], t.edge_b[i]) << "slot " << slot;
        ASSERT_EQ(g.edge_c[i], t.edge_c[i]) << "slot " << slot;
      }
      ASSERT_EQ(g.bbox_min_x, t.bbox_min_x);
      ASSERT_EQ(g.bbox_min_y, t.bbox_min_y);
      ASSERT_EQ(g.bbox_max_x, t.bbox_max_x);
      ASSERT_EQ(g.bbox_max_y, t.bbox_max_y);
      ASSERT_EQ(g.face, t.face);
      EXPECT_EQ(g.ref_x, t.ref_x);
      EXPECT_EQ(g.ref_y, t.ref_y);
      expect_plane_near(g.inv_w, t.inv_w, "inv_w", slot);
      expect_plane_near(g.u_over_w, t.u_over_w, "u_over_w", slot);
      expect_plane_near(g.v_over_w, t.v_over_w, "v_over_w", slot);
    }
    EXPECT_EQ(result.stats.visible_triangles, non_empty);
    EXPECT_GT(non_empty, 0u);

    // Binning, from the GPU's setups: same counts, offsets the exclusive scan, same sets, each in
    // input order (binning.cl's chunks keep it: paper's 4,948 triangles make five).
    const auto twin_bins = bin_triangles_reference(gpu_setups, frame);
    const std::vector<uint32_t> counts = renderer.read_tile_counts();
    const std::vector<uint32_t> offsets = renderer.read_tile_offsets();
    const std::vector<uint32_t> lists = renderer.read_tile_lists();
    ASSERT_EQ(counts.size(), twin_bins.size());
    uint32_t running = 0;
    for (size_t tile = 0; tile < twin_bins.size(); ++tile) {
      ASSERT_EQ(counts[tile], twin_bins[tile].size()) << "tile " << tile;
      ASSERT_EQ(offsets[tile], running) << "tile " << tile;
      const std::vector<uint32_t> gpu_list(lists.begin() + offsets[tile], lists.begin() + offsets[tile] + counts[tile]);
      ASSERT_EQ(gpu_list, twin_bins[tile]) << "tile " << tile;
      running += counts[tile];
    }
    EXPECT_EQ(result.stats.bin_entries, running);
    // Each entry's rows and columns: its slot's box clipped to the tile, tile-relative.
    const std::vector<uint16_t> rows = renderer.read_tile_entry_rows();
    ASSERT_EQ(rows.size(), lists.size());
    for (size_t tile = 0; tile < counts.size(); ++tile) {
      const int x0 = static_cast<int>(tile % frame.tiles_x) * SEAMCL_TILE_SIZE;
      const int y0 = static_cast<int>(tile / frame.tiles_x) * SEAMCL_TILE_SIZE;
      for (uint32_t entry = offsets[tile]; entry < offsets[tile] + counts[tile]; ++entry) {
        const TriangleSetup& s = gpu_setups.at(lists[entry]);
        const int expected = std::max(s.bbox_min_y - y0, 0) | std::min(s.bbox_max_y - y0, SEAMCL_TILE_SIZE - 1) << 4 |
                             std::max(s.bbox_min_x - x0, 0) << 8 | std::min(s.bbox_max_x - x0, SEAMCL_TILE_SIZE - 1) << 12;
        ASSERT_EQ(rows[entry], expected) << "tile " << tile << " entry " << entry;
      }
    }

    // Raster, from the GPU's setups: the same winner for every sample.
    const std::vector<uint32_t> gpu_winners = renderer.read_sample_triangles();
    const std::vector<uint32_t> twin_winners = raster_reference(gpu_setups, frame);
    ASSERT_EQ(gpu_winners.size(), twin_winners.size());
    size_t mismatches = 0, covered = 0;
    for (size_t i = 0; i < gpu_winners.size(); ++i) {
      mismatches += gpu_winners[i] != twin_winners[i];
      covered += twin_winners[i] != SEAMCL_NO_TRIANGLE;
    }
    EXPECT_EQ(mismatches, 0u);
    EXPECT_GT(covered, 0u);

    // Shade and resolve, from the GPU's setups and winners.
    const ResolveReference twin_image = shade_resolve_reference(packed, frame, gpu_setups, gpu_winners);
    EXPECT_EQ(result.stats.fragments, twin_image.fragments);
    float worst = 0.0f;
    for (size_t p = 0; p < twin_image.pixels.size(); ++p) {
      for (int ch = 0; ch < 4; ++ch) {
        ASSERT_TRUE(std::isfinite(result.pixels[p][ch])) << "pixel " << p;
        worst = std::max(worst, std::fabs(result.pixels[p][ch] - twin_image.pixels[p][ch]));
      }
    }
    EXPECT_LE(worst, 2e-5f);
  }
}

TEST(SamplePattern, HostAndKernelTablesAreTheD3D11StandardPatterns) {
  // D3D11_STANDARD_MULTISAMPLE_PATTERN, in 1/16 pixel from the centre (D3D11.3 spec 3.5.6.1),
  // written out here independently of host/pipeline/stages/sample_pattern.cpp.
  const std::vector<std::vector<std::pair<int, int>>> standard = {
      {{0, 0}},
      {{4, 4}, {-4, -4}},
      {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}},
      {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}},
      {{1, 1}, {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5}, {5, 3}, {3, -5},
       {-2, 6}, {0, -7}, {-4, -6}, {-6, 4}, {-8, 0}, {7, -4}, {6, 7}, {-7, -8}}};
  cl::Kernel kernel(shared_runtime().program(KernelProgram::Geometry), "sample_pattern");
  cl::Buffer out(shared_runtime().context(), CL_MEM_WRITE_ONLY, sizeof(cl_int) * 2 * SEAMCL_MAX_SAMPLES);
  for (size_t row = 0; row < standard.size(); ++row) {
    const int count = 1 << row;
    const auto& host = sample_pattern(count);
    ASSERT_EQ(host.size(), standard[row].size());
    kernel.setArg(0, static_cast<cl_int>(count));
    kernel.setArg(1, out);
    shared_runtime().queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(1));
    std::vector<cl_int> device(2 * static_cast<size_t>(count));
    shared_runtime().queue().enqueueReadBuffer(out, CL_TRUE, 0, sizeof(cl_int) * device.size(), device.data());
    for (int s = 0; s < count; ++s) {
      EXPECT_EQ(host[s].x, standard[row][s].first) << count << "x sample " << s;
      EXPECT_EQ(host[s].y, standard[row][s].second) << count << "x sample " << s;
      EXPECT_EQ(device[2 * s], standard[row][s].first) << count << "x sample " << s;
      EXPECT_EQ(device[2 * s + 1], standard[row][s].second) << count << "x sample " << s;
    }
  }
  EXPECT_THROW(sample_pattern(3), std::invalid_argument);
}

TEST(KernelVsTwin, SetupCullsOnlyTrianglesThatCoverNoSample) {
  // The paper scene subdivided to about a triangle per pixel (most triangles miss every sample
  // centre at 1x) and a random scene (slivers, clipped quads), at every sample count: each
  // triangle setup culls for holding no sample in its box must cover no sample, and the winners
  // must be those of the raster twin over the setups without that cull.
  GeneratorOptions dense_options;
  dense_options.faces = 20000;
  std::vector<std::pair<std::string, Scene>> scenes;
  scenes.emplace_back("dense paper", generate_scene("paper", dense_options));
  scenes.emplace_back("random3", random_scene(3, 40));
  Renderer renderer(shared_runtime());
  for (const auto& [name, scene] : scenes) {
    renderer.load_scene(scene);
    for (int msaa : {1, 2, 4, 8, 16}) {
      SCOPED_TRACE(name + " msaa " + std::to_string(msaa));
      RenderOptions options;
      options.width = 96;
      options.height = 80;
      options.msaa = msaa;
      renderer.render(scene.camera, options);
      const FrameParams frame = renderer.last_frame_params();
      const std::vector<TriangleSetup> gpu = renderer.read_setups();
      const std::vector<TriangleSetup> culled = setup_triangles_reference(renderer.packed_scene(), frame, true);
      const std::vector<TriangleSetup> kept = setup_triangles_reference(renderer.packed_scene(), frame, false);
      ASSERT_EQ(gpu.size(), kept.size());
      ASSERT_EQ(culled.size(), kept.size());
      const std::vector<SampleOffset>& pattern = sample_pattern(msaa);
      size_t culls = 0, kept_visible = 0;
      for (size_t slot = 0; slot < kept.size(); ++slot) {
        kept_visible += !setup_is_empty(kept[slot]);
        ASSERT_EQ(setup_is_empty(gpu[slot]), setup_is_empty(culled[slot])) << "slot " << slot;
        // A box emptied by the image's edges reads as empty either way (the cull only makes it
        // the plain empty record).
        if (setup_is_empty(kept[slot])) {
          ASSERT_TRUE(setup_is_empty(culled[slot])) << "slot " << slot;
          continue;
        }
        if (std::memcmp(&culled[slot], &kept[slot], sizeof(TriangleSetup)) == 0) continue;
        ++culls;
        ASSERT_TRUE(setup_is_empty(culled[slot])) << "slot " << slot;
        const TriangleSetup& t = kept[slot];
        size_t covered = 0;
        for (int y = t.bbox_min_y; y <= t.bbox_max_y; ++y) {
          for (int x = t.bbox_min_x; x <= t.bbox_max_x; ++x) {
            for (const SampleOffset& o : pattern) covered += setup_covers(t, sample_fixed_x(x, o), sample_fixed_y(y, o));
          }
        }
        EXPECT_EQ(covered, 0u) << "culled slot " << slot << " covers samples";
      }
      EXPECT_EQ(renderer.read_sample_triangles(), raster_reference(kept, frame));
      if (name == "dense paper" && msaa == 1) {
        // The cull must actually happen where it matters: a good share of the visible triangles.
        EXPECT_GT(culls * 10, kept_visible) << culls << " culled of " << kept_visible;
      }
    }
  }
}

TEST(KernelVsTwin, EarlyCullKeepsEveryTriangleTheFullSetupKeeps) {
  // triangle_setup.cl culls back faces, zero-area triangles, boxes past an image side and
  // triangles wholly outside one clip plane before the full setup (its early cull), and
  // writes only a clipped triangle's fan, which the twin does not: every slot must still be the
  // twin's. Scenes where it matters: the paper scene subdivided (half its triangles face away),
  // zoomed in so that the image sides cut through its triangles inside the guard band (boxes just
  // past a side, and just inside it) and the guard band clips others; and many small random quads
  // around a narrow view. Every sample count (the image-side test must hold for every pattern).
  GeneratorOptions dense_options;
  dense_options.faces = 20000;
  std::vector<std::pair<std::string, Scene>> scenes;
  scenes.emplace_back("dense paper", generate_scene("paper", dense_options));
  scenes.emplace_back("dense paper zoomed", generate_scene("paper", dense_options));
  scenes.back().second.camera.fov_y_degrees *= 0.3f;
  scenes.emplace_back("small random quads", random_scene(11, 600));
  scenes.back().second.camera.fov_y_degrees = 20.0f;
  Renderer renderer(shared_runtime());
  for (const auto& [name, scene] : scenes) {
    renderer.load_scene(scene);
    for (int msaa : {1, 2, 4, 8, 16}) {
      SCOPED_TRACE(name + " msaa " + std::to_string(msaa));
      RenderOptions options;
      options.width = 83;
      options.height = 61;
      options.msaa = msaa;
      const RenderResult result = renderer.render(scene.camera, options);
      const FrameParams frame = renderer.last_frame_params();
      const std::vector<TriangleSetup> gpu = renderer.read_setups();
      const std::vector<TriangleSetup> twin = setup_triangles_reference(renderer.packed_scene(), frame);
      ASSERT_EQ(gpu.size(), twin.size());
      uint32_t visible = 0, empty_first_slots = 0;
      for (size_t slot = 0; slot < gpu.size(); ++slot) {
        ASSERT_EQ(setup_is_empty(gpu[slot]), setup_is_empty(twin[slot])) << "slot " << slot;
        if (setup_is_empty(twin[slot])) {
          empty_first_slots += slot % SEAMCL_CLIP_SLOTS == 0;
          continue;
        }
        ++visible;
        for (int i = 0; i < 3; ++i) {
          ASSERT_EQ(gpu[slot].edge_c[i], twin[slot].edge_c[i]) << "slot " << slot;
          ASSERT_EQ(gpu[slot].edge_a[i], twin[slot].edge_a[i]) << "slot " << slot;
          ASSERT_EQ(gpu[slot].edge_b[i], twin[slot].edge_b[i]) << "slot " << slot;
        }
        ASSERT_EQ(gpu[slot].bbox_min_x, twin[slot].bbox_min_x) << "slot " << slot;
        ASSERT_EQ(gpu[slot].bbox_max_y, twin[slot].bbox_max_y) << "slot " << slot;
      }
      EXPECT_EQ(result.stats.visible_triangles, visible);
      // Both kinds must be there in numbers: culled triangles and kept ones (the narrow view of
      // the random quads keeps 53 slots, the paper scenes thousands).
      EXPECT_GT(visible, 40u);
      EXPECT_GT(empty_first_slots, 100u);
      // The early cull must fire, on exactly the triangles its rule names (the twin counts them
      // from its own snapped vertices): else the checks above would pass with it switched off.
      const EarlyCullCounts counts = early_culled_reference(renderer.packed_scene(), frame);
      const size_t early_culled = counts.total();
      EXPECT_EQ(result.stats.early_culled, early_culled);
      // The zoomed paper and the random quads around a narrow view reach past the guard band:
      // triangles wholly outside one plane are culled early too.
      if (name != "dense paper") EXPECT_GT(counts.outside_a_plane, 20u) << name;
      EXPECT_LE(early_culled, size_t{empty_first_slots});  // it stops only triangles setup empties
      if (name != "small random quads") {
        // Half the paper's triangles face away, and the cull stops those that need no clipping.
        EXPECT_GT(early_culled * 3, static_cast<size_t>(frame.input_triangles)) << early_culled;
      } else {
        EXPECT_GT(early_culled, 100u);
      }
    }
  }
}
