// The displaced surface's normals on the device (kernels/tessellate.cl, displaced_normals) against
// their twin (displaced_normal), the same bits on both sides of every edge for the watertight
// methods, and the shading they light (kernels/shade_resolve.cl): against its twin, and without
// the jump along patch edges that lighting with the patches' face normals shows.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "displacement_test_scenes.h"
#include "pipeline/displacement_packing.h"
#include "pipeline/stages/shade_resolve_twin.h"
#include "pipeline/stages/tessellate_launcher.h"
#include "pipeline/tessellation_factors.h"
#include "scene/displacement_map.h"
#include "test_support.h"

namespace {

using namespace seamcl;
using seamcl_tests::cube_obj;
using seamcl_tests::device_surface;
using seamcl_tests::DeviceSurface;
using seamcl_tests::make_torus;
using seamcl_tests::shared_runtime;
using seamcl_tests::kAllDisplacementMethods;


// Mixed edge factors 1..t, each shared edge's the same from both faces (a hash of its vertices).
std::vector<std::array<int, 4>> mixed_factors(const Scene& scene, int t) {
  std::vector<std::array<int, 4>> out(scene.faces.size());
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const uint32_t a = scene.faces[f].vertices[static_cast<size_t>(k)], b = scene.faces[f].vertices[static_cast<size_t>((k + 1) % 4)];
      const uint32_t h = std::min(a, b) * 2654435761u ^ std::max(a, b) * 40503u;
      out[f][static_cast<size_t>(k)] = 1 + static_cast<int>((h >> 7) % static_cast<uint32_t>(t));
    }
  }
  return out;
}

// Units in the last place between two floats of the same sign (the count of floats between).
int64_t ulps(float a, float b) {
  if (a == b) return 0;
  int32_t ia = 0, ib = 0;
  std::memcpy(&ia, &a, sizeof(float));
  std::memcpy(&ib, &b, sizeof(float));
  if ((ia < 0) != (ib < 0)) return INT64_MAX;
  return std::llabs(static_cast<int64_t>(ia) - static_cast<int64_t>(ib));
}

// The kernel sums the cross products exactly as the twin does (no contraction, the same order);
// its sqrt and division are correctly rounded on PoCL, where it must match bit for bit. OpenCL 1.2
// lets other devices round sqrt within 3 ulp and division within 2.5, which through n / |n|
// moves a coordinate by at most about 6 ulp.
int64_t allowed_normal_ulps() {
  return shared_runtime().device_description().find("Portable Computing Language") != std::string::npos ? 0 : 8;
}

TEST(DisplacedNormals, KernelEqualsTwinAtEveryVertex) {
  const int64_t allowed = allowed_normal_ulps();
  for (const Scene& scene : {generate_scene("displaced", {}), make_torus(16, 8), cube_obj()}) {
    for (int t : {1, 3, 8}) {
      for (bool adaptive : {false, true}) {
        if (adaptive && t == 1) continue;
        for (DisplacementMethod m : kAllDisplacementMethods) {
          const DeviceSurface s = device_surface(
              pack_displacement(scene, {m, t, 0, adaptive ? mixed_factors(scene, t) : std::vector<std::array<int, 4>>{}}));
          ASSERT_EQ(s.normals.size(), s.vertices.size());
          const int side = s.packed.params.tessellation + 1;
          int64_t worst = 0;
          size_t zero = 0;
          for (size_t k = 0; k < s.normals.size(); ++k) {
            const int p = static_cast<int>(k / static_cast<size_t>(side * side));
            const int i = static_cast<int>(k % static_cast<size_t>(side)), j = static_cast<int>((k / static_cast<size_t>(side)) % static_cast<size_t>(side));
            const std::array<float, 3> twin = displaced_normal(s.packed, s.vertices, p, i, j);
            for (int c = 0; c < 3; ++c) worst = std::max(worst, ulps(s.normals[k].s[c], twin[static_cast<size_t>(c)]));
            EXPECT_EQ(s.normals[k].s[3], 0.0f);
            zero += twin[0] == 0.0f && twin[1] == 0.0f && twin[2] == 0.0f;
          }
          EXPECT_LE(worst, allowed) << scene.name << " " << to_string(m) << " T=" << t << (adaptive ? " adaptive" : "");
          if (!adaptive) EXPECT_EQ(zero, 0u) << "a uniform grid has area around every vertex";
        }
      }
    }
  }
}

// With mixed factors (the uniform case: DisplacedNormals.AgreeBitForBit... through
// measure_displacement, which reports the device's normals): the copies of every shared point get
// the same bits from the device for the watertight methods, and different ones for naive.
TEST(DisplacedNormals, DeviceNormalsAgreeBitForBitAcrossEdgesWithMixedFactors) {
  for (const Scene& scene : {generate_scene("displaced", {}), make_torus(16, 8)}) {
    for (int t : {4, 8}) {
      for (DisplacementMethod m : kAllDisplacementMethods) {
        if (m == DisplacementMethod::PtexFilter) continue;  // not watertight, and not always open either
        const DeviceSurface s = device_surface(pack_displacement(scene, {m, t, 0, mixed_factors(scene, t)}));
        const DisplacementGap gap = measure_gap(s.packed, s.vertices, &s.normals);
        if (m == DisplacementMethod::Naive) {
          EXPECT_GT(gap.max_normal_gap, 0.0) << scene.name << " T=" << t;
          EXPECT_GT(gap.differing_normals, 0u) << scene.name << " T=" << t;
        } else {
          EXPECT_EQ(gap.max_normal_gap, 0.0) << scene.name << " " << to_string(m) << " T=" << t;
          EXPECT_EQ(gap.differing_normals, 0u) << scene.name << " " << to_string(m) << " T=" << t;
        }
      }
    }
  }
}

RenderOptions torus_options(DisplacementNormals normals) {
  RenderOptions o;
  o.width = 240;
  o.height = 270;
  o.msaa = 1;
  o.method = Method::Clamp;
  o.displacement = DisplacementMethod::Fixed;
  o.tessellation = 4;
  o.displacement_normals = normals;
  return o;
}

// A smooth torus (no displacement) in one flat grey: a pixel's luminance is its lighting.
Scene smooth_torus() {
  Scene scene = make_torus(16, 8);
  auto flat = std::make_shared<Displacement>(*scene.displacement);
  flat->scale = 0.0f;
  scene.displacement = flat;
  return scene;
}

// Luminance steps between neighbouring pixels, on a surface seen without depth edges. Along a
// row or a column, pixels p and q = p + 1 with their outer neighbours o = p - 1 and r = q + 1, all
// four covered and each next one's view depth (w at the pixel centre, from its triangle's 1/w
// plane) within 0.5% (a part of the torus in front of another is a depth edge, not a neighbourhood
// on the surface; so is a run seen at a grazing angle, more than about 60 degrees here). The step's excess over its neighbours' is |L(q) - L(p)| - max(|L(p) - L(o)|,
// |L(r) - L(q)|): a continuous shading changes no faster between p and q than around them (up to its
// curvature), a discontinuity jumps there alone. p and q on patches that differ but meet (share a
// mesh vertex) are across a border; on one patch, inside it.
struct Steps {
  float border_excess = 0.0f, inside_excess = 0.0f;  // largest excess
  float border_step = 0.0f, inside_step = 0.0f;      // largest |L(q) - L(p)|
  size_t border_pairs = 0, inside_pairs = 0;
};

Steps luminance_steps(const Scene& scene, const RenderResult& r, const std::vector<uint32_t>& winners,
                      const std::vector<TriangleSetup>& setups, int t) {
  Steps out;
  const int w = r.width, h = r.height;
  auto covered = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < w && y < h && winners[static_cast<size_t>(y) * w + x] != SEAMCL_NO_TRIANGLE;
  };
  auto patch_at = [&](int x, int y) {
    return static_cast<int>(winners[static_cast<size_t>(y) * w + x] / SEAMCL_CLIP_SLOTS / static_cast<uint32_t>(2 * t * t));
  };
  auto depth_at = [&](int x, int y) {
    const TriangleSetup& s = setups.at(winners[static_cast<size_t>(y) * w + x]);
    const float dx = static_cast<float>(x) + 0.5f - s.ref_x, dy = static_cast<float>(y) + 0.5f - s.ref_y;
    return 1.0f / (s.inv_w[0] + s.inv_w[1] * dx + s.inv_w[2] * dy);
  };
  auto luminance = [&](int x, int y) {
    const glm::vec4& c = r.pixels[static_cast<size_t>(y) * w + x];
    return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b;
  };
  auto meet = [&](int a, int b) {
    for (uint32_t va : scene.faces[static_cast<size_t>(a)].vertices)
      for (uint32_t vb : scene.faces[static_cast<size_t>(b)].vertices)
        if (va == vb) return true;
    return false;
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (const auto [dx, dy] : {std::pair{1, 0}, std::pair{0, 1}}) {
        const int xs[4] = {x - dx, x, x + dx, x + 2 * dx}, ys[4] = {y - dy, y, y + dy, y + 2 * dy};
        bool smooth_run = true;
        for (int k = 0; k < 4 && smooth_run; ++k) smooth_run = covered(xs[k], ys[k]);
        for (int k = 0; k < 3 && smooth_run; ++k) {
          const float da = depth_at(xs[k], ys[k]), db = depth_at(xs[k + 1], ys[k + 1]);
          smooth_run = std::fabs(da - db) <= 0.005f * std::min(da, db);
        }
        if (!smooth_run) continue;
        float l[4];
        for (int k = 0; k < 4; ++k) l[k] = luminance(xs[k], ys[k]);
        const float step = std::fabs(l[2] - l[1]);
        const float excess = step - std::max(std::fabs(l[1] - l[0]), std::fabs(l[3] - l[2]));
        const int a = patch_at(xs[1], ys[1]), b = patch_at(xs[2], ys[2]);
        if (a == b) {
          out.inside_excess = std::max(out.inside_excess, excess);
          out.inside_step = std::max(out.inside_step, step);
          ++out.inside_pairs;
        } else if (meet(a, b)) {
          out.border_excess = std::max(out.border_excess, excess);
          out.border_step = std::max(out.border_step, step);
          ++out.border_pairs;
        }
      }
    }
  }
  return out;
}

// The face-normal render is flat on each patch and steps at every border; lit with the displaced
// surface's normals a border step is no larger than the steps beside it, as inside a patch.
TEST(DisplacedNormals, ShadingHasNoStepAlongPatchBordersThatFaceNormalsShow) {
  const Scene scene = smooth_torus();
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const RenderResult face = renderer.render(scene.camera, torus_options(DisplacementNormals::Face));
  const Steps face_steps = luminance_steps(scene, face, renderer.read_sample_triangles(), renderer.read_setups(), 4);
  const RenderResult smooth = renderer.render(scene.camera, torus_options(DisplacementNormals::Displaced));
  const Steps smooth_steps =
      luminance_steps(scene, smooth, renderer.read_sample_triangles(), renderer.read_setups(), 4);
  for (const auto& [name, s] : {std::pair{"face", face_steps}, std::pair{"displaced", smooth_steps}}) {
    RecordProperty(std::string(name) + "_border_excess", std::to_string(s.border_excess));
    RecordProperty(std::string(name) + "_inside_excess", std::to_string(s.inside_excess));
    RecordProperty(std::string(name) + "_border_step", std::to_string(s.border_step));
    RecordProperty(std::string(name) + "_inside_step", std::to_string(s.inside_step));
    RecordProperty(std::string(name) + "_pairs", std::to_string(s.border_pairs) + " border, " +
                                                      std::to_string(s.inside_pairs) + " inside");
  }
  ASSERT_GT(face_steps.border_pairs, 500u);
  ASSERT_GT(face_steps.inside_pairs, 5000u);
  EXPECT_LE(face_steps.inside_step, 1e-6f) << "a flat grey patch lit by one normal is one colour";
  EXPECT_GT(face_steps.border_excess, 0.1f) << "16 x 8 quads: neighbouring face normals 22.5 and 45 degrees apart";
  EXPECT_GT(smooth_steps.inside_step, 0.0f);
  EXPECT_LE(smooth_steps.border_excess, std::max(smooth_steps.inside_excess, 0.0f) + 0.01f)
      << "border " << smooth_steps.border_excess << " inside " << smooth_steps.inside_excess;
  EXPECT_LT(smooth_steps.border_excess, face_steps.border_excess / 10.0f)
      << "displaced " << smooth_steps.border_excess << " face " << face_steps.border_excess;
}

// The shading stage against its twin on a displaced render lit by the displaced normals, from the
// device's setups, winners, vertices and normals; and with face normals the twin without them.
TEST(DisplacedNormals, ShadeKernelMatchesTwinWithDisplacedNormals) {
  for (const Scene& scene : {make_torus(16, 8), generate_scene("displaced", {})}) {
    for (DisplacementNormals normals : {DisplacementNormals::Displaced, DisplacementNormals::Face}) {
      for (bool adaptive : {false, true}) {
        RenderOptions options = torus_options(normals);
        options.width = 120;
        options.height = 96;
        options.msaa = 4;
        options.tessellation = 6;
        if (adaptive) options.tessellation_pixels = 6.0f;
        Renderer renderer(shared_runtime());
        renderer.load_scene(scene);
        const RenderResult result = renderer.render(scene.camera, options);
        const FrameParams frame = renderer.last_frame_params();
        const std::vector<TriangleSetup> setups = renderer.read_setups();
        const std::vector<uint32_t> winners = renderer.read_sample_triangles();
        const DeviceSurface s = device_surface(pack_displacement(scene, displacement_settings(scene, options, scene.camera)));
        EXPECT_EQ(s.packed.adaptive(), adaptive);
        const DisplacedShadingReference displaced = s.shading(normals);
        const ResolveReference twin = shade_resolve_reference(renderer.packed_scene(), frame, setups, winners, nullptr,
                                                              nullptr, &displaced);
        EXPECT_EQ(result.stats.fragments, twin.fragments);
        float worst = 0.0f;
        for (size_t p = 0; p < twin.pixels.size(); ++p)
          for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(result.pixels[p][c] - twin.pixels[p][c]));
        EXPECT_LE(worst, 2e-5f) << scene.name << " " << to_string(normals) << (adaptive ? " adaptive" : "");
      }
    }
  }
}

TEST(DisplacedNormals, OptionDefaultsToDisplacedAndIsWrittenWithAMethodOnly) {
  const RenderOptions defaults = parse_render_options(nlohmann::json::object());
  EXPECT_EQ(defaults.displacement_normals, DisplacementNormals::Displaced);
  EXPECT_FALSE(to_json(defaults).contains("displacement_normals"));
  const RenderOptions face =
      parse_render_options({{"displacement_method", "fixed"}, {"displacement_normals", "face"}});
  EXPECT_EQ(face.displacement_normals, DisplacementNormals::Face);
  EXPECT_EQ(to_json(face).at("displacement_normals"), "face");
  try {
    parse_render_options({{"displacement_method", "fixed"}, {"displacement_normals", "vertex"}});
    ADD_FAILURE() << "an unknown value was taken";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "displacement_normals");
  }
}

}  // namespace
