// The pixel inspector: the debug variant of shading (kernels/shade_inspect.cl) held to its twin
// (host/pipeline/stages/shade_inspect_twin.cpp), its records held to the frame they describe
// (resolved, they give the rendered pixel), and the inspect job's JSON to the records.
// Tolerances as tests/test_kernels.cpp: integers exact, floats within a few ulps.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>

#include <seamcl/core/input_error.h>
#include <seamcl/jobs/inspect_job.h>
#include <seamcl/jobs/overlay_job.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/stages/shade_inspect_launcher.h"
#include "pipeline/stages/shade_inspect_twin.h"
#include "test_support.h"

using namespace seamcl;
using nlohmann::json;
using seamcl_tests::shared_runtime;

namespace {

struct Case {
  std::string name;
  std::string scene;
  RenderOptions options;
};

std::vector<Case> cases() {
  auto options = [](int w, int h, int msaa, ShadingMode shading, Method method, Filter filter) {
    RenderOptions o;
    o.width = w;
    o.height = h;
    o.msaa = msaa;
    o.shading = shading;
    o.method = method;
    o.filter = filter;
    return o;
  };
  return {
      {"paper traverse aniso 4x pixel", "paper", options(120, 135, 4, ShadingMode::Pixel, Method::Traverse, Filter::Aniso)},
      {"quad2 traverse-edges trilinear 8x centroid", "quad2",
       options(67, 45, 8, ShadingMode::Centroid, Method::TraverseEdges, Filter::Trilinear)},
      {"cube discard ewa 2x sample", "cube", options(50, 50, 2, ShadingMode::Sample, Method::Discard, Filter::Ewa)},
      {"plane clamp bilinear 1x", "plane", options(96, 64, 1, ShadingMode::Pixel, Method::Clamp, Filter::Bilinear)},
  };
}

void expect_near(float kernel, float twin, const char* what, size_t record) {
  const float scale = std::max({std::fabs(kernel), std::fabs(twin), 1.0f});
  EXPECT_LE(std::fabs(kernel - twin), 4e-6f * scale) << what << " of record " << record << ": " << kernel << " vs " << twin;
}

// The window around the first seam pixel of the frame (the mask's), else the image's centre.
PixelWindow seam_window(const RenderResult& frame, int side) {
  int x = frame.width / 2, y = frame.height / 2;
  for (size_t p = 0; p < frame.seam_mask.size(); ++p) {
    if (frame.seam_mask[p] != SEAMCL_MASK_SEAM) continue;
    x = static_cast<int>(p % frame.width);
    y = static_cast<int>(p / frame.width);
    break;
  }
  x = std::clamp(x - side / 2, 0, frame.width - side);
  y = std::clamp(y - side / 2, 0, frame.height - side);
  return {x, y, side, side};
}

}  // namespace

TEST(KernelVsTwin, InspectRecordsEqualTheTwinsAndResolveToTheFrame) {
  Renderer renderer(shared_runtime());
  size_t across_taps = 0, partial_pixels = 0;
  for (const Case& c : cases()) {
    SCOPED_TRACE(c.name);
    const Scene scene = generate_scene(c.scene, {});
    renderer.load_scene(scene);
    const RenderResult frame = renderer.render(scene.camera, c.options, true);
    const PixelWindow window = seam_window(frame, 8);
    const std::vector<InspectSample> gpu = renderer.inspect_last_frame(window.x, window.y, window.width, window.height);
    const FrameParams params = renderer.last_frame_params();
    const std::vector<InspectSample> twin =
        shade_inspect_reference(renderer.packed_scene(), params, renderer.read_setups(), renderer.read_sample_triangles(),
                                window.x, window.y, window.width, window.height);
    ASSERT_EQ(gpu.size(), twin.size());
    ASSERT_EQ(gpu.size(), static_cast<size_t>(window.width * window.height * params.sample_count));
    for (size_t i = 0; i < gpu.size(); ++i) {
      const InspectSample& g = gpu[i];
      const InspectSample& t = twin[i];
      ASSERT_EQ(g.triangle, t.triangle) << "record " << i;
      ASSERT_EQ(g.face, t.face) << "record " << i;
      ASSERT_EQ(g.coverage, t.coverage) << "record " << i;
      EXPECT_EQ(g.probes, t.probes) << "record " << i;
      EXPECT_EQ(g.level0, t.level0) << "record " << i;
      EXPECT_EQ(g.level1, t.level1) << "record " << i;
      EXPECT_EQ(g.reflective, t.reflective) << "record " << i;
      EXPECT_EQ(g.x, t.x) << "record " << i;
      EXPECT_EQ(g.y, t.y) << "record " << i;
      for (int k = 0; k < 4; ++k) {
        EXPECT_EQ(g.edge_face[k], t.edge_face[k]) << "record " << i << " edge " << k;
        EXPECT_EQ(g.corner_face[k], t.corner_face[k]) << "record " << i << " corner " << k;
        expect_near(g.edge_weight[k], t.edge_weight[k], "edge_weight", i);
        expect_near(g.corner_weight[k], t.corner_weight[k], "corner_weight", i);
        across_taps += g.edge_weight[k] > 0.0f || g.corner_weight[k] > 0.0f;
      }
      expect_near(g.u, t.u, "u", i);
      expect_near(g.v, t.v, "v", i);
      expect_near(g.dudx, t.dudx, "dudx", i);
      expect_near(g.dvdy, t.dvdy, "dvdy", i);
      expect_near(g.axis_x, t.axis_x, "axis_x", i);
      expect_near(g.axis_y, t.axis_y, "axis_y", i);
      expect_near(g.lod, t.lod, "lod", i);
      expect_near(g.own_weight, t.own_weight, "own_weight", i);
      for (int ch = 0; ch < 4; ++ch) expect_near(g.color[ch], t.color[ch], "color", i);
    }
    // The records describe the frame: each pixel's samples, each counted at its fragment's
    // colour, resolve to the rendered pixel, and a triangle's samples name it.
    const std::vector<TriangleSetup> setups = renderer.read_setups();
    const int samples = params.sample_count;
    for (int wy = 0; wy < window.height; ++wy) {
      for (int wx = 0; wx < window.width; ++wx) {
        const InspectSample* r = &gpu[(static_cast<size_t>(wy) * window.width + wx) * samples];
        glm::vec3 sum(0.0f);
        for (int s = 0; s < samples; ++s) {
          sum += glm::vec3(r[s].color[0], r[s].color[1], r[s].color[2]);
          EXPECT_TRUE((r[s].coverage >> s) & 1u);
          if (r[s].triangle == SEAMCL_NO_TRIANGLE) continue;
          EXPECT_EQ(static_cast<uint32_t>(r[s].face), setups.at(r[s].triangle).face);
          EXPECT_GE(r[s].level0, 0);
          EXPECT_LE(r[s].level0, r[s].level1);
        }
        partial_pixels += std::popcount(r[0].coverage) < samples;
        const glm::vec4 pixel = frame.pixels.at(static_cast<size_t>(window.y + wy) * frame.width + window.x + wx);
        for (int ch = 0; ch < 3; ++ch) {
          EXPECT_NEAR(sum[ch] / static_cast<float>(samples), pixel[ch], 2e-5f) << "pixel " << window.x + wx << ", " << window.y + wy;
        }
      }
    }
  }
  // The windows hold what the records are for: taps read from other faces, and pixels that
  // triangles share.
  EXPECT_GT(across_taps, 0u);
  EXPECT_GT(partial_pixels, 0u);
}

TEST(InspectJob, AnswersTheRecordsOfThePixelAsJson) {
  const json request = {{"scene", "quad2"}, {"size", "64x48"}, {"msaa", 4}, {"method", "traverse"}, {"x", 31}, {"y", 20},
                        {"window", 2}};
  const InspectJob job(request);
  const Scene scene = generate_scene("quad2", job.render_job().generator_options());
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const json answer = job.run(renderer, scene, JobControl{});
  EXPECT_EQ(answer.at("width"), 2);
  EXPECT_EQ(answer.at("height"), 2);
  EXPECT_EQ(answer.at("samples"), 4);
  EXPECT_EQ(answer.at("method"), "traverse");
  EXPECT_TRUE(answer.at("renormalize").get<bool>());
  const std::vector<InspectSample> records = renderer.inspect_last_frame(31, 20, 2, 2);
  const json& pixels = answer.at("pixels");
  ASSERT_EQ(pixels.size(), 4u);
  for (size_t p = 0; p < pixels.size(); ++p) {
    EXPECT_EQ(pixels[p].at("x"), 31 + static_cast<int>(p % 2));
    EXPECT_EQ(pixels[p].at("y"), 20 + static_cast<int>(p / 2));
    const json& items = pixels[p].at("samples");
    ASSERT_EQ(items.size(), 4u);
    for (size_t s = 0; s < items.size(); ++s) {
      const InspectSample& r = records[p * 4 + s];
      ASSERT_NE(r.triangle, SEAMCL_NO_TRIANGLE) << "quad2 fills the middle of the frame";
      EXPECT_EQ(items[s].at("face"), r.face);
      EXPECT_EQ(items[s].at("uv").at(0).get<float>(), r.u);
      EXPECT_EQ(items[s].at("uv").at(1).get<float>(), r.v);
      // The taps: the own face first; with renormalisation the shares add up to 1.
      const json& taps = items[s].at("taps");
      ASSERT_FALSE(taps.empty());
      EXPECT_EQ(taps.at(0).at("from"), "own");
      EXPECT_EQ(taps.at(0).at("face"), r.face);
      double shares = 0;
      for (const json& tap : taps) shares += tap.at("share").get<double>();
      EXPECT_NEAR(shares, 1.0, 1e-5);
    }
  }
  // quad2's two faces share an edge: the faces around the pixel name the other one.
  bool names_neighbor = false;
  for (const json& tap : pixels[0].at("samples")[0].at("taps")) names_neighbor |= tap.at("from") == "edge";
  EXPECT_TRUE(names_neighbor);
}

TEST(InspectJob, RefusesAMissingOrOutsidePixelNamingTheField) {
  auto field_of = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("(none)");
  };
  EXPECT_EQ(field_of([] { InspectJob({{"scene", "quad2"}, {"y", 1}}); }), "x");
  EXPECT_EQ(field_of([] { InspectJob({{"scene", "quad2"}, {"x", 1}}); }), "y");
  EXPECT_EQ(field_of([] { InspectJob({{"x", 1}, {"y", 1}, {"window", 9}}); }), "window");
  EXPECT_EQ(field_of([] { InspectJob({{"x", -1}, {"y", 1}}); }), "x");
  EXPECT_EQ(field_of([] { InspectJob({{"x", 1}, {"y", 1}, {"repeat", 2}}); }), "repeat");
  const InspectJob outside({{"scene", "quad2"}, {"size", "32x32"}, {"x", 32}, {"y", 0}});
  const Scene scene = generate_scene("quad2", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  EXPECT_EQ(field_of([&] { outside.run(renderer, scene, JobControl{}); }), "x");
  // The window is cut at the image's edges.
  const json corner = InspectJob({{"scene", "quad2"}, {"size", "32x32"}, {"x", 30}, {"y", 31}, {"window", 4}})
                          .run(renderer, scene, JobControl{});
  EXPECT_EQ(corner.at("width"), 2);
  EXPECT_EQ(corner.at("height"), 1);
}

TEST(OverlayJob, LayersAreTheSeamMaskAndTheFaceEdgesOfTheFrame) {
  const json request = {{"scene", "quad2"}, {"size", "64x48"}, {"msaa", 4}, {"method", "clamp"}};
  const OverlayJob job(request);
  const Scene scene = generate_scene("quad2", job.render_job().generator_options());
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const json answer = job.run(renderer, scene, JobControl{});
  ASSERT_EQ(answer.at("width"), 64);
  ASSERT_EQ(answer.at("height"), 48);
  // The same frame's seam mask and winners, read here.
  const RenderResult frame = renderer.render(scene.camera, job.options(), true);
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  const std::string text = answer.at("pixels").get<std::string>();
  ASSERT_EQ(text.size(), (64u * 48u + 2) / 3 * 4);
  auto digit = [](char c) -> uint32_t {
    return c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52 : c == '+' ? 62 : 63;
  };
  std::vector<uint8_t> flags;
  for (size_t i = 0; i < text.size(); i += 4) {
    const uint32_t n = digit(text[i]) << 18 | digit(text[i + 1]) << 12 | (text[i + 2] == '=' ? 0 : digit(text[i + 2]) << 6) |
                       (text[i + 3] == '=' ? 0 : digit(text[i + 3]));
    for (int k = 0; k < 3 && flags.size() < 64u * 48u; ++k) flags.push_back(static_cast<uint8_t>(n >> (16 - 8 * k)));
  }
  ASSERT_EQ(flags.size(), 64u * 48u);
  size_t seam = 0, edges = 0;
  const int samples = 4;
  for (size_t p = 0; p < flags.size(); ++p) {
    EXPECT_EQ((flags[p] & kOverlaySeam) != 0, frame.seam_mask[p] == SEAMCL_MASK_SEAM) << "pixel " << p;
    EXPECT_EQ((flags[p] & kOverlayBoundary) != 0, frame.seam_mask[p] == SEAMCL_MASK_BOUNDARY) << "pixel " << p;
    seam += (flags[p] & kOverlaySeam) != 0;
    // A pixel whose own samples lie on two faces is a face edge.
    uint32_t first_face = UINT32_MAX;
    bool two_faces = false;
    for (int s = 0; s < samples; ++s) {
      const uint32_t slot = winners[p * samples + s];
      if (slot == SEAMCL_NO_TRIANGLE) continue;
      if (first_face == UINT32_MAX) first_face = setups[slot].face;
      two_faces = two_faces || setups[slot].face != first_face;
    }
    if (two_faces) EXPECT_TRUE(flags[p] & kOverlayFaceEdge) << "pixel " << p;
    edges += (flags[p] & kOverlayFaceEdge) != 0;
  }
  EXPECT_EQ(answer.at("counts").at("seam"), seam);
  EXPECT_EQ(answer.at("counts").at("face_edge"), edges);
  // quad2's shared edge runs down the frame: a line of face-edge pixels, and seam pixels along it.
  EXPECT_GE(edges, 20u);
  EXPECT_GT(seam, 0u);
  EXPECT_THROW(OverlayJob(json{{"method", "guardband"}}), InputError);
}
