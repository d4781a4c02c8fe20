// Where the seam methods fail, measured on scenes built to provoke each failure (docs/methods.md "Where
// methods fail", docs/results/failures/README.md): zero coverage (helper pixels, the paper's
// Figure 8), magnification at the texture edge (Figure 6), grazing angles beyond 16x anisotropy,
// guard bands too thin for wide footprints, and frame-to-frame change near seams over an orbit.
//
// Every test prints its numbers ("[failure] ..." lines) and, with SEAMCL_FAILURES_OUT=DIR set,
// writes its figures' data there (PNG crops and one JSON per test; examples/failures.py draws
// the charts from the JSON). Without it nothing is written.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/io/image_io.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include "test_support.h"
#include "pipeline/stages/raster_twin.h"
#include "pipeline/stages/shade_resolve_twin.h"
#include "pipeline/stages/texture_sample_twin.h"

using namespace seamcl;
using nlohmann::json;
using seamcl_tests::shared_runtime;

namespace {

namespace fs = std::filesystem;

std::optional<fs::path> out_dir() {
  const char* dir = std::getenv("SEAMCL_FAILURES_OUT");
  if (dir == nullptr || *dir == '\0') return std::nullopt;
  fs::create_directories(dir);
  return fs::path(dir);
}

void write_json(const std::string& name, const json& data) {
  if (const auto dir = out_dir()) std::ofstream(*dir / name) << data.dump(1) << "\n";
}

bool finite_rgb(const glm::vec4& p) { return std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b); }

size_t count_non_finite(const std::vector<glm::vec4>& pixels) {
  return static_cast<size_t>(std::count_if(pixels.begin(), pixels.end(), [](const glm::vec4& p) {
    return !(finite_rgb(p) && std::isfinite(p.a));
  }));
}

// A crop of an image, enlarged `scale` times (nearest), non-finite pixels magenta.
std::vector<glm::vec4> crop(const std::vector<glm::vec4>& pixels, int width, int x0, int y0, int w, int h,
                            int scale) {
  std::vector<glm::vec4> out(static_cast<size_t>(w * scale) * static_cast<size_t>(h * scale));
  for (int y = 0; y < h * scale; ++y) {
    for (int x = 0; x < w * scale; ++x) {
      const glm::vec4 p = pixels[static_cast<size_t>(y0 + y / scale) * static_cast<size_t>(width) +
                                 static_cast<size_t>(x0 + x / scale)];
      out[static_cast<size_t>(y) * static_cast<size_t>(w * scale) + static_cast<size_t>(x)] =
          finite_rgb(p) ? glm::vec4(glm::vec3(p), 1.0f) : glm::vec4(1, 0, 1, 1);
    }
  }
  return out;
}

// Several crops of the same region side by side, 4 pixels of white between them.
void write_strip(const std::string& name, const std::vector<const std::vector<glm::vec4>*>& images, int width,
                 int x0, int y0, int w, int h, int scale) {
  const auto dir = out_dir();
  if (!dir) return;
  const int gap = 4;
  const int cw = w * scale, ch = h * scale;
  const int total = static_cast<int>(images.size()) * (cw + gap) - gap;
  std::vector<glm::vec4> strip(static_cast<size_t>(total) * static_cast<size_t>(ch), glm::vec4(1.0f));
  for (size_t i = 0; i < images.size(); ++i) {
    const std::vector<glm::vec4> c = crop(*images[i], width, x0, y0, w, h, scale);
    const int left = static_cast<int>(i) * (cw + gap);
    for (int y = 0; y < ch; ++y)
      for (int x = 0; x < cw; ++x)
        strip[static_cast<size_t>(y) * static_cast<size_t>(total) + static_cast<size_t>(left + x)] =
            c[static_cast<size_t>(y) * static_cast<size_t>(cw) + static_cast<size_t>(x)];
  }
  write_image((*dir / name).string(), total, ch, strip);
}

std::vector<glm::vec4> heat(const std::vector<glm::vec4>& test, const std::vector<glm::vec4>& reference) {
  return error_heatmap(pixel_distances(test, reference));
}

ReferenceImage uncached_reference(Renderer& renderer, const Camera& camera, const RenderOptions& frame) {
  ReferenceSettings settings;
  settings.use_cache = false;
  return reference_image(renderer, camera, frame, settings);
}

// Mean over the masked pixels of the 2-norm of the rgb difference (both finite).
double masked_mean_distance(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b,
                            const std::vector<uint8_t>& mask) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (!mask[i] || !finite_rgb(a[i]) || !finite_rgb(b[i])) continue;
    sum += static_cast<double>(glm::length(glm::vec3(a[i]) - glm::vec3(b[i])));
    ++n;
  }
  return n ? sum / static_cast<double>(n) : 0.0;
}

size_t mask_count(const std::vector<uint8_t>& mask) {
  return static_cast<size_t>(std::count(mask.begin(), mask.end(), uint8_t{1}));
}

// The footprint of the fragment at each pixel's centre (1 sample per pixel render): the lengths
// of the two screen-axis derivatives in level-0 texels of the face, as the aniso filter sees them.
struct Footprint {
  bool covered = false;
  float major = 0, minor = 0;  // texels per pixel
  int probes = 0;              // min(ceil(major/minor), max_aniso)
  float lod = 0;               // log2(major / probes), the probes' level
};

std::vector<Footprint> pixel_footprints(Renderer& renderer, int max_aniso) {
  const Scene& scene = renderer.scene();
  const FrameParams frame = renderer.last_frame_params();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  std::vector<Footprint> out(static_cast<size_t>(frame.width) * static_cast<size_t>(frame.height));
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const size_t pixel = static_cast<size_t>(y) * static_cast<size_t>(frame.width) + static_cast<size_t>(x);
      const uint32_t slot = winners[pixel * static_cast<size_t>(frame.sample_count)];
      if (slot == SEAMCL_NO_TRIANGLE) continue;
      const TriangleSetup& t = setups[slot];
      const MipChain& texture = scene.faces[t.face].texture;
      const SurfaceUv uv = interpolate_uv(t, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
      const auto tw = static_cast<float>(texture.width()), th = static_cast<float>(texture.height());
      const float lx = std::hypot(uv.dudx * tw, uv.dvdx * th);
      const float ly = std::hypot(uv.dudy * tw, uv.dvdy * th);
      Footprint& f = out[pixel];
      f.covered = true;
      f.major = std::max(lx, ly);
      f.minor = std::max(std::min(lx, ly), 1e-12f);
      f.probes = std::clamp(static_cast<int>(std::ceil(f.major / f.minor)), 1, max_aniso);
      f.lod = std::log2(std::max(f.major / static_cast<float>(f.probes), 1e-12f));
    }
  }
  return out;
}

// The plane scene, generated once for the tests that use it (baking takes a while).
const Scene& plane_scene() {
  static const Scene scene = generate_scene("plane", {});
  return scene;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// 1. Zero coverage. Thin slivers (0.15 pixel wide, slightly tilted) at 4x/8x MSAA with shading at
// the pixel centre: a sliver covering a sample but not the centre is shaded at a point well
// outside its face in uv, and the whole filter footprint can miss the face. Discard with
// zero_coverage=nan divides 0 by 0 there; the default (clamped lookup) never does.
namespace {

Scene sliver_scene(int image_side) {
  Scene scene;
  scene.name = "slivers";
  scene.camera.eye = glm::vec3(0, 0, 5);
  scene.camera.target = glm::vec3(0, 0, 0);
  const float pixel = 2.0f * 5.0f * std::tan(glm::radians(22.5f)) / static_cast<float>(image_side);
  constexpr int kCell = 8;  // one sliver per 8x8 pixel cell
  const float length = 7.0f * pixel, width = 0.15f * pixel;
  std::mt19937 rng(7);
  const int cells = image_side / kCell;
  for (int cy = 0; cy < cells; ++cy) {
    for (int cx = 0; cx < cells; ++cx) {
      // Every direction (37 degrees apart from one cell to the next) and a random sub-pixel offset.
      const float angle = glm::radians(static_cast<float>((cy * cells + cx) * 37 % 180));
      const glm::vec3 d(std::cos(angle), std::sin(angle), 0.0f), n(-d.y, d.x, 0.0f);
      const glm::vec3 c((static_cast<float>(cx * kCell + kCell / 2) + seamcl_tests::uniform(rng, -0.5f, 0.5f) -
                         0.5f * static_cast<float>(image_side)) * pixel,
                        (static_cast<float>(cy * kCell + kCell / 2) + seamcl_tests::uniform(rng, -0.5f, 0.5f) -
                         0.5f * static_cast<float>(image_side)) * pixel,
                        0.0f);
      const auto base = static_cast<uint32_t>(scene.positions.size());
      // u across the sliver (0.15 pixel), v along it (7 pixels); counter-clockwise from +z.
      scene.positions.push_back(c + n * (width / 2) - d * (length / 2));
      scene.positions.push_back(c - n * (width / 2) - d * (length / 2));
      scene.positions.push_back(c - n * (width / 2) + d * (length / 2));
      scene.positions.push_back(c + n * (width / 2) + d * (length / 2));
      Face face;
      face.vertices = {base, base + 1, base + 2, base + 3};
      scene.faces.push_back(std::move(face));
    }
  }
  for (Face& face : scene.faces)
    face.texture = build_mip_chain(bake_face_texture(scene.corners(face), 8, 8, surface_pattern));
  return scene;
}

struct NanCheck {
  size_t nan_pixels = 0;
  size_t uncovered_pixels = 0;  // pixels with a fragment whose taps all fall outside
  size_t mismatches = 0;        // NaN != uncovered
};

// As in Methods.ZeroCoverageNanOnlyOnFragmentsWithNoTapInsideAndNeverByDefault: per pixel, the
// scalar twin of the lookup of every fragment; NaN exactly where one has zero tap weight.
NanCheck check_nan_pixels(Renderer& renderer, const RenderResult& raw) {
  const FrameParams frame = renderer.last_frame_params();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const PackedScene& packed = renderer.packed_scene();
  const int msaa = frame.sample_count;
  NanCheck check;
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const size_t pixel = static_cast<size_t>(y) * static_cast<size_t>(frame.width) + static_cast<size_t>(x);
      const uint32_t* ids = &winners[pixel * static_cast<size_t>(msaa)];
      const bool uncovered_fragment = pixel_has_uncovered_fragment(packed, frame, setups, ids, x, y);
      const bool is_nan = std::isnan(raw.pixels[pixel].r);
      check.nan_pixels += is_nan;
      check.uncovered_pixels += uncovered_fragment;
      check.mismatches += is_nan != uncovered_fragment;
    }
  }
  return check;
}

}  // namespace

TEST(Failure, ZeroCoverageHelperPixelsGiveNanOnlyWithZeroCoverageNan) {
  constexpr int kSide = 96;
  const Scene scene = sliver_scene(kSide);
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  json report = json::array();
  size_t nan_at_8x_trilinear = 0;
  for (int msaa : {1, 4, 8}) {
    for (Filter filter : {Filter::Aniso, Filter::Trilinear}) {
      SCOPED_TRACE(testing::Message() << "msaa " << msaa << " " << to_string(filter));
      RenderOptions options;
      options.width = kSide;
      options.height = kSide;
      options.msaa = msaa;
      options.filter = filter;
      options.method = Method::Discard;
      const RenderResult fixed = renderer.render(scene.camera, options);
      const size_t default_nan = count_non_finite(fixed.pixels);
      EXPECT_EQ(default_nan, 0u) << "the default zero_coverage=clamp must never give NaN";

      options.zero_coverage = ZeroCoverage::Nan;
      const RenderResult raw = renderer.render(scene.camera, options);
      const NanCheck check = check_nan_pixels(renderer, raw);
      EXPECT_EQ(check.mismatches, 0u) << "NaN exactly where a fragment has no tap inside its face";
      options.shading = ShadingMode::Centroid;
      const size_t centroid_nan = count_non_finite(renderer.render(scene.camera, options).pixels);
      if (filter == Filter::Trilinear) {
        // The helper-pixel case: at 1 sample the centre is covered, so some tap lands inside; with
        // MSAA the centre can lie far outside the sliver. Centroid shading moves the shading point
        // into the covered samples and cures it.
        if (msaa == 1) {
          EXPECT_EQ(check.nan_pixels, 0u) << "1 sample: shaded at a covered centre";
        } else {
          EXPECT_GT(check.nan_pixels, 100u) << "thin slivers at MSAA must provoke zero coverage";
        }
        EXPECT_EQ(centroid_nan, 0u);
      } else {
        // Aniso: the probes are spread along the footprint's longer screen axis, which for a
        // sliver 0.15 pixel wide spans several sliver widths in u, at a level as coarse as 1x1:
        // every probe can straddle the face even from a covered centre, at any rate and with
        // centroid shading too.
        EXPECT_GT(check.nan_pixels, 20u);
        EXPECT_GT(centroid_nan, 20u);
      }
      if (msaa == 8 && filter == Filter::Trilinear) nan_at_8x_trilinear = check.nan_pixels;

      const size_t covered = static_cast<size_t>(std::count_if(
          fixed.pixels.begin(), fixed.pixels.end(),
          [&](const glm::vec4& p) { return glm::length(glm::vec3(p) - scene.background) > 1e-6f; }));
      std::printf("[failure] zero coverage: msaa %d %s: %zu NaN pixels with zero_coverage=nan (of %zu pixels "
                  "showing a sliver); default: %zu; centroid shading: %zu\n",
                  msaa, to_string(filter).c_str(), check.nan_pixels, covered, default_nan, centroid_nan);
      report.push_back({{"msaa", msaa},
                        {"filter", to_string(filter)},
                        {"nan_pixels", check.nan_pixels},
                        {"covered_pixels", covered},
                        {"default_nan_pixels", default_nan},
                        {"centroid_nan_pixels", centroid_nan}});
      if (msaa == 8 && filter == Filter::Trilinear && out_dir()) {
        write_strip("zero_coverage_8x.png", {&raw.pixels, &fixed.pixels}, kSide, 16, 16, 32, 32, 6);
      }
    }
  }
  RecordProperty("nan_pixels_8x_trilinear", static_cast<int>(nan_at_8x_trilinear));
  write_json("zero_coverage.json", {{"size", kSide}, {"results", report}});
}

// ---------------------------------------------------------------------------------------------
// 2. Magnification (Figure 6): two unit quads sharing an edge, 8x8 textures baked from
// surface_pattern, seen so close that one texel covers 16 pixels. Clamp and discard have no data
// in the outermost half-texel band and extend the edge texel across it; traverse interpolates
// with the neighbour's texels.
TEST(Failure, MagnificationHalfTexelBandAtTheSeamTraverseDoesNotShowIt) {
  Scene scene;
  scene.name = "magnify";
  for (int j = 0; j <= 1; ++j)
    for (int i = 0; i <= 2; ++i)
      scene.positions.emplace_back(static_cast<float>(i) - 1.0f, static_cast<float>(j) - 0.5f, 0.0f);
  for (uint32_t i = 0; i < 2; ++i) {
    Face face;
    face.vertices = {i, i + 1, i + 4, i + 3};
    scene.faces.push_back(std::move(face));
  }
  for (Face& face : scene.faces)
    face.texture = build_mip_chain(bake_face_texture(scene.corners(face), 8, 8, surface_pattern));
  scene.camera.eye = glm::vec3(0.0f, 0.0f, 0.6f);  // 0.5 units of the plane across the view
  scene.camera.target = glm::vec3(0.0f);

  constexpr int kSide = 64;  // one texel = 16 pixels; the half-texel band is 8 pixels wide
  constexpr int kBand = 8;
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  RenderOptions frame;
  frame.width = kSide;
  frame.height = kSide;
  const std::vector<uint8_t> mask = seam_mask(render_face_map(renderer, scene.camera, frame), kBand);
  const size_t band_pixels = mask_count(mask);
  ASSERT_GT(band_pixels, static_cast<size_t>(kSide * 2 * kBand));
  const ReferenceImage reference = uncached_reference(renderer, scene.camera, frame);

  json report = json::array();
  std::vector<std::vector<glm::vec4>> images;
  double seam_error[5] = {};
  const Method methods[] = {Method::Clamp, Method::Black, Method::Discard, Method::Traverse, Method::Guardband};
  // One sample per pixel: the plane is flat and shaded at the pixel centre, so MSAA changes nothing
  // but the pixels on the seam line itself.
  for (int mi = 0; mi < 5; ++mi) {
    {
      RenderOptions options = frame;
      options.method = methods[mi];
      const RenderResult result = renderer.render(scene.camera, options);
      const ImageErrors errors = compare_images(result.pixels, reference.pixels, &mask);
      EXPECT_EQ(errors.nan_pixels, 0u);
      seam_error[mi] = errors.seam.mean;
      std::printf("[failure] magnification: %-9s msaa %d: seam-band mean %.5f p99 %.5f max %.4f; whole frame mean "
                  "%.5f\n",
                  to_string(methods[mi]).c_str(), options.msaa, errors.seam.mean, errors.seam.p99, errors.seam.max,
                  errors.all.mean);
      report.push_back({{"method", to_string(methods[mi])},
                        {"msaa", options.msaa},
                        {"seam_mean", errors.seam.mean},
                        {"seam_p99", errors.seam.p99},
                        {"seam_max", errors.seam.max},
                        {"mean", errors.all.mean}});
      images.push_back(result.pixels);
    }
  }
  const double traverse = seam_error[3], discard = seam_error[2], clamp = seam_error[0];
  // Measured: discard 0.0172, traverse 0.00004 (430x; docs/results/failures/README.md). Held
  // with a wide margin: 50x.
  EXPECT_GT(discard, 50.0 * traverse) << "discard " << discard << " traverse " << traverse;
  EXPECT_GT(clamp, 50.0 * traverse) << "clamp " << clamp << " traverse " << traverse;
  EXPECT_GT(discard, 0.005) << "the half-texel band must show";
  // Guardband (g = 4, filled at build time from the neighbour) has the band's data too.
  EXPECT_LT(seam_error[4], discard / 50.0);
  if (out_dir()) {
    const int x0 = kSide / 2 - 12, y0 = kSide / 2 - 8;
    write_strip("magnification.png", {&images[2], &images[0], &images[3], &reference.pixels}, kSide, x0, y0, 24, 16,
                8);
    const std::vector<glm::vec4> hd = heat(images[2], reference.pixels), ht = heat(images[3], reference.pixels);
    write_strip("magnification_error.png", {&hd, &ht}, kSide, x0, y0, 24, 16, 8);
  }
  write_json("magnification.json", {{"size", kSide}, {"band_radius", kBand}, {"band_pixels", band_pixels},
                                    {"results", report}});
}

// ---------------------------------------------------------------------------------------------
// 3. Grazing angles beyond 16x anisotropy: the plane scene from lower and lower eye heights.
// More and more of the frame needs more than 16 probes; errors grow, nothing breaks.
TEST(Failure, GrazingAnglesBeyond16xErrorsGrowButStayFinite) {
  const Scene& scene = plane_scene();
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  constexpr int kW = 96, kH = 64;
  const Method methods[] = {Method::Clamp, Method::Black, Method::Discard, Method::Traverse, Method::Guardband};
  const float heights[] = {1.0f, 0.3f, 0.1f};
  json report = json::array();
  double covered_mean[3][5] = {}, beyond16[3] = {}, seam_mean[3][5] = {}, over_mean[3][5] = {},
         under_mean[3][5] = {};
  for (int hi = 0; hi < 3; ++hi) {
    Camera camera = scene.camera;
    camera.eye = glm::vec3(0.0f, heights[hi], 8.0f);
    camera.target = glm::vec3(0.0f, 0.0f, 0.0f);
    RenderOptions frame;
    frame.width = kW;
    frame.height = kH;
    const FaceMap faces = render_face_map(renderer, camera, frame);
    const std::vector<uint8_t> mask = seam_mask(faces);
    const std::vector<Footprint> footprints = pixel_footprints(renderer, 16);
    // Covered pixels, and among them those whose footprint is longer than 16:1 or not.
    std::vector<uint8_t> covered(footprints.size()), over(footprints.size()), under(footprints.size());
    for (size_t i = 0; i < footprints.size(); ++i) {
      covered[i] = footprints[i].covered;
      over[i] = footprints[i].covered && footprints[i].major / footprints[i].minor > 16.0f;
      under[i] = footprints[i].covered && !over[i];
    }
    beyond16[hi] = static_cast<double>(mask_count(over)) / static_cast<double>(mask_count(covered));
    const ReferenceImage reference = uncached_reference(renderer, camera, frame);
    EXPECT_EQ(count_non_finite(reference.pixels), 0u);
    json row = {{"height", heights[hi]},
                {"covered_pixels", mask_count(covered)},
                {"beyond_16x", beyond16[hi]}};
    for (int mi = 0; mi < 5; ++mi) {
      RenderOptions options = frame;
      options.method = methods[mi];
      const RenderResult result = renderer.render(camera, options);
      EXPECT_EQ(count_non_finite(result.pixels), 0u) << to_string(methods[mi]) << " height " << heights[hi];
      const ImageErrors errors = compare_images(result.pixels, reference.pixels, &mask);
      covered_mean[hi][mi] = masked_mean_distance(result.pixels, reference.pixels, covered);
      over_mean[hi][mi] = masked_mean_distance(result.pixels, reference.pixels, over);
      under_mean[hi][mi] = masked_mean_distance(result.pixels, reference.pixels, under);
      seam_mean[hi][mi] = errors.seam.mean;
      std::printf("[failure] grazing: height %.1f (%.0f%% of %zu covered px beyond 16:1) %-9s covered mean %.5f "
                  "(beyond 16:1 %.5f, within %.5f) seam mean %.5f\n",
                  static_cast<double>(heights[hi]), 100.0 * beyond16[hi], mask_count(covered),
                  to_string(methods[mi]).c_str(), covered_mean[hi][mi], over_mean[hi][mi], under_mean[hi][mi],
                  errors.seam.mean);
      row[to_string(methods[mi])] = {{"covered_mean", covered_mean[hi][mi]},
                                     {"beyond_16x_mean", over_mean[hi][mi]},
                                     {"within_16x_mean", under_mean[hi][mi]},
                                     {"seam_mean", errors.seam.mean}};
    }
    report.push_back(row);
    // The other filters and MSAA stay finite at these angles too.
    for (Filter filter : {Filter::Trilinear, Filter::Ewa}) {
      for (Method method : {Method::Discard, Method::Traverse}) {
        RenderOptions options = frame;
        options.filter = filter;
        options.method = method;
        options.msaa = 4;
        EXPECT_EQ(count_non_finite(renderer.render(camera, options).pixels), 0u) << to_string(filter);
      }
    }
  }
  // Measured (docs/results/failures/README.md): the share of the frame beyond the 16x cap grows
  // as the view flattens; the error sits in those pixels (2.5-18x the error of the pixels within
  // 16:1, every method, every height); the seam error grows from height 1 to 0.1 (by 17-31%).
  // The mean over all covered pixels does not grow: the far plane fills more of the frame and,
  // filtered down to its coarsest levels in image and reference alike, agrees.
  EXPECT_LT(beyond16[0], beyond16[1]);
  EXPECT_LT(beyond16[1], beyond16[2]);
  for (int mi = 0; mi < 5; ++mi) {
    SCOPED_TRACE(to_string(methods[mi]));
    for (int hi = 0; hi < 3; ++hi) EXPECT_GT(over_mean[hi][mi], 2.0 * under_mean[hi][mi]) << "height " << hi;
    EXPECT_GT(seam_mean[2][mi], 1.1 * seam_mean[0][mi]);
  }
  write_json("grazing.json", {{"size", std::to_string(kW) + "x" + std::to_string(kH)}, {"results", report}});
}

// ---------------------------------------------------------------------------------------------
// 4. Guard bands too thin for wide footprints: guardband with g = 1, 2, 4, 8 against traverse on
// the plane scene (16x aniso): the aniso probes spread along the footprint's long axis, up to
// +-N/2 texels of the probes' level, so a thin band clamps where N is large.
TEST(Failure, GuardBandTooThinForWideFootprints) {
  const Scene& scene = plane_scene();
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  RenderOptions frame;
  frame.width = 96;
  frame.height = 64;
  const Camera camera = scene.camera;
  const std::vector<uint8_t> mask = seam_mask(render_face_map(renderer, camera, frame));
  const std::vector<Footprint> footprints = pixel_footprints(renderer, frame.aniso);
  RenderOptions options = frame;
  options.method = Method::Traverse;
  const RenderResult traverse = renderer.render(camera, options);

  // Buckets of the probe count N at the pixel centre.
  const int bucket_top[] = {1, 2, 4, 8, 16};
  auto bucket_of = [&](int probes) {
    int b = 0;
    while (probes > bucket_top[b]) ++b;
    return b;
  };
  const int gs[] = {1, 2, 4, 8};
  double seam_mean[4] = {};
  json report = json::array();
  std::vector<glm::vec4> g1_pixels;
  for (int gi = 0; gi < 4; ++gi) {
    options.method = Method::Guardband;
    options.guard_band = gs[gi];
    const RenderResult result = renderer.render(camera, options);
    ASSERT_EQ(count_non_finite(result.pixels), 0u);
    if (gi == 0) g1_pixels = result.pixels;
    seam_mean[gi] = masked_mean_distance(result.pixels, traverse.pixels, mask);
    double bucket_sum[5] = {};
    size_t bucket_n[5] = {};
    for (size_t i = 0; i < mask.size(); ++i) {
      if (!mask[i] || !footprints[i].covered) continue;
      const int b = bucket_of(footprints[i].probes);
      bucket_sum[b] += static_cast<double>(glm::length(glm::vec3(result.pixels[i]) - glm::vec3(traverse.pixels[i])));
      ++bucket_n[b];
    }
    json buckets = json::array();
    std::string text;
    for (int b = 0; b < 5; ++b) {
      const double mean = bucket_n[b] ? bucket_sum[b] / static_cast<double>(bucket_n[b]) : 0.0;
      buckets.push_back({{"probes_up_to", bucket_top[b]}, {"pixels", bucket_n[b]}, {"mean", mean}});
      char cell[64];
      std::snprintf(cell, sizeof cell, " N<=%d: %.5f (%zu px)", bucket_top[b], mean, bucket_n[b]);
      text += cell;
    }
    std::printf("[failure] guard band g=%d: seam mean |guardband - traverse| %.5f;%s\n", gs[gi], seam_mean[gi],
                text.c_str());
    report.push_back({{"g", gs[gi]}, {"seam_mean_vs_traverse", seam_mean[gi]}, {"by_probes", buckets}});
  }
  for (int gi = 1; gi < 4; ++gi) EXPECT_LE(seam_mean[gi], seam_mean[gi - 1] * 1.02 + 1e-5) << "g=" << gs[gi];
  EXPECT_GT(seam_mean[0], 2.0 * seam_mean[3]) << "g=1 should be clearly worse than g=8";
  if (out_dir()) {
    const std::vector<glm::vec4> h1 = heat(g1_pixels, traverse.pixels);
    write_strip("guardband_g1_vs_traverse.png", {&g1_pixels, &traverse.pixels, &h1}, frame.width, 0, 0, frame.width,
                frame.height, 3);
  }
  write_json("guardband.json", {{"size", "96x64"}, {"scene", "plane"}, {"results", report}});
}

// ---------------------------------------------------------------------------------------------
// 5. Temporal stability: 8 consecutive frames of a 720-frame orbit of the paper scene (0.5
// degrees a frame). Per method, the mean change of the error against each frame's reference
// from one frame to the next, over the pixels near seams in both frames ("flicker": the motion
// of the content itself cancels), and the raw frame-to-frame change.
TEST(Failure, TemporalChangeNearSeamsOverAnOrbit) {
  const Scene paper = generate_scene("paper", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(paper);
  constexpr int kFrames = 720, kUsed = 8;
  RenderOptions frame;
  frame.width = 96;
  frame.height = 108;
  struct Entry {
    Method method;
    int msaa;
  };
  const std::vector<Entry> entries = {{Method::Clamp, 1},    {Method::Black, 1},    {Method::Discard, 1},
                                      {Method::Discard, 8},  {Method::Traverse, 1}, {Method::Traverse, 8},
                                      {Method::Guardband, 1}};
  std::vector<std::vector<std::vector<glm::vec4>>> images(entries.size());
  std::vector<std::vector<glm::vec4>> references;
  std::vector<std::vector<uint8_t>> masks;
  for (int k = 0; k < kUsed; ++k) {
    const Camera camera = orbit_camera(paper, k, kFrames);
    masks.push_back(seam_mask(render_face_map(renderer, camera, frame)));
    references.push_back(uncached_reference(renderer, camera, frame).pixels);
    for (size_t e = 0; e < entries.size(); ++e) {
      RenderOptions options = frame;
      options.method = entries[e].method;
      options.msaa = entries[e].msaa;
      images[e].push_back(renderer.render(camera, options).pixels);
    }
  }
  auto flicker = [&](const std::vector<std::vector<glm::vec4>>& frames, bool against_reference) {
    double sum = 0;
    size_t n = 0;
    for (int k = 0; k + 1 < kUsed; ++k) {
      const auto& a = frames[static_cast<size_t>(k)];
      const auto& b = frames[static_cast<size_t>(k + 1)];
      const auto& ra = references[static_cast<size_t>(k)];
      const auto& rb = references[static_cast<size_t>(k + 1)];
      for (size_t i = 0; i < a.size(); ++i) {
        if (!masks[static_cast<size_t>(k)][i] || !masks[static_cast<size_t>(k + 1)][i]) continue;
        glm::vec3 d = glm::vec3(b[i]) - glm::vec3(a[i]);
        if (against_reference) d -= glm::vec3(rb[i]) - glm::vec3(ra[i]);
        sum += static_cast<double>(glm::length(d));
        ++n;
      }
    }
    return n ? sum / static_cast<double>(n) : 0.0;
  };
  const double reference_change = flicker(references, false);
  std::printf("[failure] temporal: reference frame-to-frame change near seams %.5f\n", reference_change);
  json report = json::array();
  std::vector<double> error_flicker(entries.size()), change(entries.size());
  for (size_t e = 0; e < entries.size(); ++e) {
    error_flicker[e] = flicker(images[e], true);
    change[e] = flicker(images[e], false);
    std::printf("[failure] temporal: %-9s msaa %d: change %.5f, change of the error (flicker) %.5f\n",
                to_string(entries[e].method).c_str(), entries[e].msaa, change[e], error_flicker[e]);
    report.push_back({{"method", to_string(entries[e].method)},
                      {"msaa", entries[e].msaa},
                      {"change", change[e]},
                      {"error_change", error_flicker[e]}});
  }
  // Measured first (see docs/results/failures/README.md); only the robust orderings are held.
  EXPECT_GT(error_flicker[1], 1.2 * error_flicker[2]) << "black flickers more than discard at seams";
  EXPECT_LT(error_flicker[3], error_flicker[2] / 1.2) << "discard at 8x is steadier than at 1x";
  write_json("temporal.json", {{"scene", "paper"},
                               {"size", "96x108"},
                               {"frames", kFrames},
                               {"used", kUsed},
                               {"reference_change", reference_change},
                               {"results", report}});
}
