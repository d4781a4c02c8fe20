// The pixel inspector: the debug variant of shading (kernels/shade_inspect.cl) held to its twin
// (host/pipeline/stages/shade_inspect_twin.cpp), its records held to the frame they describe
// (resolved, they give the rendered pixel), and the inspect job's JSON to the records.
// Tolerances as tests/test_kernels.cpp: integers exact, floats within a few ulps.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <optional>

#include <glm/gtc/matrix_transform.hpp>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/cube_metrics.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/jobs/inspect_job.h>
#include <seamcl/jobs/overlay_job.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "displacement_test_scenes.h"
#include "pipeline/stages/shade_inspect_launcher.h"
#include "pipeline/stages/shade_inspect_twin.h"
#include "pipeline/tessellation_factors.h"
#include "test_support.h"

using namespace seamcl;
using nlohmann::json;
using seamcl_tests::shared_runtime;

namespace {

// An overlay answer's pixels: its base64 decoded, width * height bytes.
std::vector<uint8_t> overlay_flags(const json& answer) {
  const std::string text = answer.at("pixels").get<std::string>();
  const size_t size = answer.at("width").get<size_t>() * answer.at("height").get<size_t>();
  EXPECT_EQ(text.size(), (size + 2) / 3 * 4);
  auto digit = [](char c) -> uint32_t {
    return c >= 'A' && c <= 'Z' ? c - 'A' : c >= 'a' && c <= 'z' ? c - 'a' + 26 : c >= '0' && c <= '9' ? c - '0' + 52 : c == '+' ? 62 : 63;
  };
  std::vector<uint8_t> flags;
  for (size_t i = 0; i + 3 < text.size(); i += 4) {
    const uint32_t n = digit(text[i]) << 18 | digit(text[i + 1]) << 12 | (text[i + 2] == '=' ? 0 : digit(text[i + 2]) << 6) |
                       (text[i + 3] == '=' ? 0 : digit(text[i + 3]));
    for (int k = 0; k < 3 && flags.size() < size; ++k) flags.push_back(static_cast<uint8_t>(n >> (16 - 8 * k)));
  }
  return flags;
}

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
  // Displaced, lit by the displaced surface's normals as the render lights it.
  RenderOptions displaced = options(96, 72, 4, ShadingMode::Pixel, Method::Discard, Filter::Aniso);
  displaced.displacement = DisplacementMethod::Ownership;
  displaced.tessellation = 4;
  displaced.displacement_normals = DisplacementNormals::Displaced;
  return {
      {"paper traverse aniso 4x pixel", "paper", options(120, 135, 4, ShadingMode::Pixel, Method::Traverse, Filter::Aniso)},
      {"displaced ownership T4 discard aniso 4x pixel", "displaced", displaced},
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
    std::optional<seamcl_tests::DeviceSurface> surface;
    DisplacedShadingReference lit;
    if (c.options.displacement) {
      surface = seamcl_tests::device_surface(
          pack_displacement(scene, displacement_settings(scene, c.options, scene.camera)));
      lit = surface->shading(c.options.displacement_normals);
      ASSERT_GT(lit.params.tessellation, 0);
    }
    const std::vector<InspectSample> twin =
        shade_inspect_reference(renderer.packed_scene(), params, renderer.read_setups(), renderer.read_sample_triangles(),
                                window.x, window.y, window.width, window.height, nullptr, surface ? &lit : nullptr);
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
  const json answer = job.run(shared_runtime(), renderer, scene, JobControl{});
  ASSERT_EQ(answer.at("width"), 64);
  ASSERT_EQ(answer.at("height"), 48);
  // The same frame's seam mask and winners, read here.
  const RenderResult frame = renderer.render(scene.camera, job.options(), true);
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  const std::vector<uint8_t> flags = overlay_flags(answer);
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
  // The layers that do not apply to quad2 (no displacement, no environment) are there, empty.
  EXPECT_EQ(answer.at("layers"), json({{"seam", 1}, {"boundary", 2}, {"face_edge", 4}, {"crack", 8}, {"cube_edge", 16}}));
  EXPECT_EQ(answer.at("counts").at("crack"), 0);
  EXPECT_EQ(answer.at("counts").at("cube_edge"), 0);
  for (uint8_t f : flags) ASSERT_EQ(f & (kOverlayCrack | kOverlayCubeEdge), 0);
  EXPECT_THROW(OverlayJob(json{{"method", "guardband"}}), InputError);
}

// The crack layer marks the pixels the displacement metrics count for the same frame: some for
// naive on a frame where it cracks, none for a watertight method.
TEST(OverlayJob, CrackPixelsAreThoseTheDisplacementMetricsCount) {
  const int frames = 60;
  json request = {{"scene", "displaced"}, {"size", "96x96"}, {"msaa", 1}, {"tessellation", 8}, {"frame", 0}, {"frames", frames}};
  const Scene scene = generate_scene("displaced", OverlayJob(request).render_job().generator_options());
  ASSERT_TRUE(is_closed_mesh(scene));
  // The first orbit frame on which naive cracks, by the metrics.
  int frame = -1;
  size_t expected = 0;
  for (int f = 0; f < frames && frame < 0; f += 3) {
    request["frame"] = f;
    request["displacement_method"] = "naive";
    const OverlayJob job(request);
    const DisplacementReport report =
        measure_displacement(shared_runtime(), scene, job.render_job().camera(scene), job.options(), 0, 0);
    ASSERT_TRUE(report.crack_pixels.has_value());
    if (*report.crack_pixels > 0) frame = f, expected = *report.crack_pixels;
  }
  ASSERT_GE(frame, 0) << "naive shows no crack on any frame of the orbit";
  request["frame"] = frame;
  for (const std::string method : {"naive", "zipper"}) {
    request["displacement_method"] = method;
    const OverlayJob job(request);
    EXPECT_TRUE(job.crack_pixels_apply(scene));
    Renderer renderer(shared_runtime());
    renderer.load_scene(scene);
    const json answer = job.run(shared_runtime(), renderer, scene, JobControl{});
    const std::vector<uint8_t> flags = overlay_flags(answer);
    const size_t marked = static_cast<size_t>(std::count_if(flags.begin(), flags.end(), [](uint8_t f) { return (f & kOverlayCrack) != 0; }));
    EXPECT_EQ(answer.at("counts").at("crack"), marked) << method;
    const DisplacementReport report =
        measure_displacement(shared_runtime(), scene, job.render_job().camera(scene), job.options(), 0, 0);
    EXPECT_EQ(marked, *report.crack_pixels) << method << " frame " << frame;
    if (method == "naive") EXPECT_EQ(marked, expected);
    if (method == "zipper") EXPECT_EQ(marked, 0u);
    // The plan holds the crack render beside the frame's.
    EXPECT_GT(job.plan(scene).device.total(), job.render_job().plan(scene).device.total());
  }
  // Without a displacement method the frame is not displaced: the layer does not apply.
  request.erase("displacement_method");
  EXPECT_FALSE(OverlayJob(request).crack_pixels_apply(scene));
}

// The lookup directions of an environment frame's sky are the camera's rays through the pixel
// centres, computed here from the view and projection matrices; the cube-edge layer is
// cube_edge_pixels of the frame's lookup directions and is not empty on envmap.
TEST(OverlayJob, CubeEdgesAreWhereTheLookupDirectionsCubeFaceChanges) {
  const json request = {{"scene", "envmap"}, {"size", "64x48"}, {"msaa", 4}};
  const OverlayJob job(request);
  const Scene scene = generate_scene("envmap", job.render_job().generator_options());
  ASSERT_TRUE(OverlayJob::cube_edges_apply(scene));
  EXPECT_FALSE(job.crack_pixels_apply(scene));
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const json answer = job.run(shared_runtime(), renderer, scene, JobControl{});
  const std::vector<uint8_t> flags = overlay_flags(answer);
  ASSERT_EQ(flags.size(), 64u * 48u);
  const Camera camera = job.render_job().camera(scene);
  const std::vector<glm::vec3> directions = lookup_directions(renderer, camera, job.options());
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();  // the directions' frame: 1 sample
  const std::vector<uint8_t> expected = cube_edge_pixels(directions, 64, 48);
  const glm::mat4 inverse = glm::inverse(glm::perspective(glm::radians(camera.fov_y_degrees), 64.0f / 48.0f, 0.1f, 100.0f) *
                                         glm::lookAt(camera.eye, camera.target, camera.up));
  size_t sky = 0, marked = 0;
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      const size_t p = static_cast<size_t>(y) * 64 + x;
      EXPECT_EQ((flags[p] & kOverlayCubeEdge) != 0, expected[p] != 0) << x << "," << y;
      marked += (flags[p] & kOverlayCubeEdge) != 0;
      if (winners[p] != SEAMCL_NO_TRIANGLE) continue;
      const float nx = (x + 0.5f) / 64.0f * 2.0f - 1.0f, ny = 1.0f - (y + 0.5f) / 48.0f * 2.0f;
      const glm::vec4 near = inverse * glm::vec4(nx, ny, -1.0f, 1.0f), far = inverse * glm::vec4(nx, ny, 1.0f, 1.0f);
      const glm::vec3 ray = glm::normalize(glm::vec3(far) / far.w - glm::vec3(near) / near.w);
      EXPECT_GT(glm::dot(ray, directions[p]), 1.0f - 1e-5f) << x << "," << y;
      ++sky;
    }
  }
  EXPECT_GT(sky, 100u);
  EXPECT_EQ(answer.at("counts").at("cube_edge"), marked);
  EXPECT_GT(marked, 10u);
  EXPECT_EQ(answer.at("counts").at("crack"), 0);
}

// cube_edge_pixels on the rays of a camera looking at the +X/+Z cube edge, computed here: a pixel
// is marked where its ray's largest component (a face chosen here, by its own comparisons) differs
// from its right or lower neighbour's; no lookup and a jump wider than 0.25 radians mark nothing.
TEST(OverlayCubeEdges, MarkWhereTheViewRaysCubeFaceChanges) {
  const int w = 40, h = 30;
  const glm::mat4 inverse = glm::inverse(glm::perspective(glm::radians(60.0f), float(w) / h, 0.1f, 100.0f) *
                                         glm::lookAt(glm::vec3(0.0f), glm::vec3(1.0f, 0.6f, 1.0f), glm::vec3(0, 1, 0)));
  std::vector<glm::vec3> rays;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const glm::vec4 far = inverse * glm::vec4((x + 0.5f) / w * 2.0f - 1.0f, 1.0f - (y + 0.5f) / h * 2.0f, 1.0f, 1.0f);
      rays.push_back(glm::normalize(glm::vec3(far) / far.w));
    }
  }
  auto face_of = [](glm::vec3 d) {
    const glm::vec3 a = glm::abs(d);
    if (a.x >= a.y && a.x >= a.z) return d.x >= 0 ? 0 : 1;
    if (a.y >= a.z) return d.y >= 0 ? 2 : 3;
    return d.z >= 0 ? 4 : 5;
  };
  const std::vector<uint8_t> marked = cube_edge_pixels(rays, w, h);
  size_t count = 0;
  std::vector<int> faces_seen(6, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      const int f = face_of(rays[p]);
      ++faces_seen[static_cast<size_t>(f)];
      const bool expected = (x + 1 < w && face_of(rays[p + 1]) != f) || (y + 1 < h && face_of(rays[p + w]) != f);
      EXPECT_EQ(marked[p] != 0, expected) << x << "," << y;
      count += marked[p];
    }
  }
  // The view holds the +X/+Z edge and the top face's edges: three faces, a line of pixels or more.
  EXPECT_GT(faces_seen[0], 0);
  EXPECT_GT(faces_seen[2], 0);
  EXPECT_GT(faces_seen[4], 0);
  EXPECT_GE(count, static_cast<size_t>(h));
  // A pixel that looks nothing up marks nothing, nor does its neighbour on its account.
  std::vector<glm::vec3> holes = rays;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t p = static_cast<size_t>(y) * w + x;
      if (marked[p] && x + 1 < w && face_of(rays[p + 1]) != face_of(rays[p])) holes[p + 1] = glm::vec3(0.0f);
    }
  }
  const std::vector<uint8_t> around = cube_edge_pixels(holes, w, h);
  for (size_t p = 0; p < holes.size(); ++p)
    if (holes[p] == glm::vec3(0.0f)) EXPECT_EQ(around[p], 0) << p;
  // Two faces' directions far apart (a silhouette) are no cube edge.
  const std::vector<glm::vec3> jump = {glm::vec3(1, 0, 0.2f), glm::vec3(0.2f, 0, -1)};
  EXPECT_EQ(cube_edge_pixels(jump, 2, 1), (std::vector<uint8_t>{0, 0}));
  const std::vector<glm::vec3> close = {glm::normalize(glm::vec3(1, 0, 0.99f)), glm::normalize(glm::vec3(0.99f, 0, 1))};
  EXPECT_EQ(cube_edge_pixels(close, 2, 1), (std::vector<uint8_t>{1, 0}));
}
