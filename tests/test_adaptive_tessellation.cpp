// Tessellation factors per patch edge (docs/displacement.md, "Factors per edge"): screen-space
// factors shared by both patches of an edge, the slot grid's transitions tiling every patch, the
// kernel against its twin, and every watertight method keeping gap 0, normals equal and no crack
// pixel with mixed factors on `displaced`, the Ptex cube and a torus, while naive still cracks.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene_generators.h>
#include "displacement_test_scenes.h"
#include "pipeline/displacement_packing.h"
#include "pipeline/frame_params.h"
#include "pipeline/stages/tessellate_launcher.h"
#include "pipeline/stages/tessellate_twin.h"
#include "pipeline/tessellation_factors.h"
#include "test_support.h"

namespace {

using namespace seamcl;
using seamcl_tests::cube_obj;
using seamcl_tests::make_torus;
using seamcl_tests::shared_runtime;
using seamcl_tests::kAllDisplacementMethods;
using seamcl_tests::kWatertightMethods;


// A factor per edge from its two vertices alone (so both faces agree), spread over 1..max.
std::vector<std::array<int, 4>> hashed_factors(const Scene& scene, int max_factor) {
  std::vector<std::array<int, 4>> out(scene.faces.size());
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const uint32_t a = scene.faces[f].vertices[k], b = scene.faces[f].vertices[(k + 1) % 4];
      const uint32_t lo = std::min(a, b), hi = std::max(a, b);
      out[f][static_cast<size_t>(k)] = 1 + static_cast<int>((lo * 7919u + hi * 104729u) % static_cast<uint32_t>(max_factor));
    }
  }
  return out;
}

std::vector<TessVertex> device_tessellation(const PackedDisplacement& packed) {
  TessellateLauncher stage(shared_runtime());
  stage.load(packed);
  return stage.tessellate();
}

RenderOptions adaptive_options(DisplacementMethod method, int t, float pixels, int width, int height, int msaa) {
  RenderOptions o;
  o.width = width;
  o.height = height;
  o.msaa = msaa;
  o.displacement = method;
  o.tessellation = t;
  o.tessellation_pixels = pixels;
  return o;
}

std::string input_error_field(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.field();
  }
  return "(no InputError)";
}

TEST(AdaptiveFactors, ScreenSpaceFactorsAreTheEdgesOwnSharedByBothFaces) {
  const Scene scene = generate_scene("displaced", {});
  const glm::mat4 vp = view_projection(scene.camera, 480, 540);
  const auto near = screen_space_edge_factors(scene, vp, 480, 540, 4.0f, 64);
  const auto coarse = screen_space_edge_factors(scene, vp, 480, 540, 40.0f, 64);
  std::map<std::pair<uint32_t, uint32_t>, int> seen;
  std::set<int> values;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const int factor = near[f][static_cast<size_t>(k)];
      ASSERT_GE(factor, 1);
      ASSERT_LE(factor, 64);
      EXPECT_LE(coarse[f][static_cast<size_t>(k)], factor) << "more pixels a segment, no more segments";
      values.insert(factor);
      const uint32_t a = scene.faces[f].vertices[k], b = scene.faces[f].vertices[(k + 1) % 4];
      const auto [it, inserted] = seen.emplace(std::make_pair(std::min(a, b), std::max(a, b)), factor);
      if (!inserted) EXPECT_EQ(it->second, factor) << "face " << f << " edge " << k;
    }
  }
  EXPECT_GE(values.size(), 3u) << "the sphere's edges project to different lengths";
  // One edge by hand: its length in pixels over 4, rounded up.
  const glm::vec4 a = vp * glm::vec4(scene.positions[scene.faces[0].vertices[0]], 1.0f);
  const glm::vec4 b = vp * glm::vec4(scene.positions[scene.faces[0].vertices[1]], 1.0f);
  const float dx = (a.x / a.w - b.x / b.w) * 240.0f, dy = (a.y / a.w - b.y / b.w) * 270.0f;
  EXPECT_NEAR(static_cast<float>(near[0][0]), std::clamp(std::ceil(std::sqrt(dx * dx + dy * dy) / 4.0f), 1.0f, 64.0f), 1.0f);
  // Clamped to the largest factor, and never below 1.
  for (const auto& face : screen_space_edge_factors(scene, vp, 480, 540, 0.25f, 3))
    for (int factor : face) EXPECT_EQ(factor, 3);
  for (const auto& face : screen_space_edge_factors(scene, vp, 480, 540, 4096.0f, 64))
    for (int factor : face) EXPECT_EQ(factor, 1);
}

TEST(AdaptiveFactors, FactorTablesAreCheckedNamingTheField) {
  const Scene scene = generate_scene("displaced", {});
  DisplacementSettings settings{DisplacementMethod::Fixed, 8, 0, hashed_factors(scene, 8)};
  EXPECT_NO_THROW(pack_displacement(scene, settings));
  DisplacementSettings short_table = settings;
  short_table.edge_factors.pop_back();
  EXPECT_EQ(input_error_field([&] { pack_displacement(scene, short_table); }), "tessellation_factors");
  DisplacementSettings too_large = settings;
  too_large.edge_factors[3][1] = 9;
  EXPECT_EQ(input_error_field([&] { pack_displacement(scene, too_large); }), "tessellation_factors");
  DisplacementSettings zero = settings;
  zero.edge_factors[0][0] = 0;
  EXPECT_EQ(input_error_field([&] { pack_displacement(scene, zero); }), "tessellation_factors");
  // One side of a shared edge changed: the two patches would disagree.
  DisplacementSettings one_sided = settings;
  one_sided.edge_factors[5][2] = one_sided.edge_factors[5][2] == 1 ? 2 : 1;
  EXPECT_EQ(input_error_field([&] { pack_displacement(scene, one_sided); }), "tessellation_factors");
  EXPECT_EQ(input_error_field([&] { parse_render_options({{"displacement_method", "fixed"}, {"tessellation_pixels", 0}}); }),
            "tessellation_pixels");
  EXPECT_EQ(input_error_field([&] { parse_render_options({{"displacement_method", "fixed"}, {"tessellation_pixels", "x"}}); }),
            "tessellation_pixels");
  const RenderOptions parsed = parse_render_options({{"displacement_method", "fixed"}, {"tessellation_pixels", 6.5}});
  ASSERT_TRUE(parsed.tessellation_pixels.has_value());
  EXPECT_EQ(*parsed.tessellation_pixels, 6.5f);
}

// The slot grid with mixed factors tiles every patch: in the domain, every micro-triangle that is
// not degenerate turns the same way, and their areas sum to the patch's exactly; the edge slots
// make exactly the edge's factor of segments and the inside its factor's grid.
TEST(AdaptiveFactors, SlotGridTilesEveryPatchWithoutFoldsAtEveryFactorMix) {
  const Scene scene = generate_scene("displaced", {});
  for (int t : {2, 3, 7, 16}) {
    PackedDisplacement packed = pack_displacement(scene, {DisplacementMethod::Fixed, t, 0, hashed_factors(scene, t)});
    ASSERT_TRUE(packed.adaptive());
    const int n = packed.params.tessellation;
    const std::vector<TessVertex> v = tessellate_reference(packed);
    size_t surface = 0;
    for (int p = 0; p < static_cast<int>(packed.patches.size()); ++p) {
      auto at = [&](int i, int j) { return v[(static_cast<size_t>(p) * (n + 1) + j) * (n + 1) + i]; };
      double area = 0.0;
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const bool flip = (i == n - 1 && j == 0) || (i == 0 && j == n - 1);
          const TessVertex a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
          const std::array<std::array<TessVertex, 3>, 2> tris =
              flip ? std::array<std::array<TessVertex, 3>, 2>{{{a, b, d}, {b, c, d}}}
                   : std::array<std::array<TessVertex, 3>, 2>{{{a, b, c}, {a, c, d}}};
          for (const auto& tri : tris) {
            const double cross = (static_cast<double>(tri[1].u) - tri[0].u) * (static_cast<double>(tri[2].v) - tri[0].v) -
                                 (static_cast<double>(tri[1].v) - tri[0].v) * (static_cast<double>(tri[2].u) - tri[0].u);
            EXPECT_GE(cross, 0.0) << "T=" << t << " patch " << p << " cell (" << i << ", " << j << ")";
            area += cross / 2.0;
            surface += cross > 0.0;
          }
        }
      }
      EXPECT_NEAR(area, 1.0, 1e-9) << "T=" << t << " patch " << p;
      // Edge e's slots make exactly its factor's distinct points (corners included).
      const DisplacementPatch& patch = packed.patches[static_cast<size_t>(p)];
      for (int e = 0; e < 4; ++e) {
        std::set<std::pair<float, float>> points;
        for (int k = 0; k <= n; ++k) {
          const int i = e == 0 ? k : e == 1 ? n : e == 2 ? n - k : 0, j = e == 0 ? 0 : e == 1 ? k : e == 2 ? n : n - k;
          points.insert({at(i, j).u, at(i, j).v});
        }
        EXPECT_EQ(static_cast<int>(points.size()), patch.edge_factor[e] + 1) << "T=" << t << " patch " << p << " edge " << e;
      }
      EXPECT_EQ(patch.inner_factor, std::max({2, patch.edge_factor[0], patch.edge_factor[1], patch.edge_factor[2],
                                              patch.edge_factor[3]}));
    }
    EXPECT_EQ(surface, packed.surface_triangle_count()) << "T=" << t;
    EXPECT_LT(packed.surface_triangle_count(), packed.triangle_count());
  }
}

TEST(AdaptiveTessellation, KernelEqualsTwinBitForBitWithMixedFactors) {
  const Scene scene = generate_scene("displaced", {});
  for (int t : {1, 3, 16}) {
    for (DisplacementMethod m : kAllDisplacementMethods) {
      const PackedDisplacement packed = pack_displacement(scene, {m, t, 0, hashed_factors(scene, t)});
      const std::vector<TessVertex> device = device_tessellation(packed);
      const std::vector<TessVertex> twin = tessellate_reference(packed);
      ASSERT_EQ(device.size(), twin.size());
      for (size_t k = 0; k < device.size(); ++k) {
        ASSERT_EQ(std::memcmp(&device[k], &twin[k], sizeof(TessVertex)), 0)
            << to_string(m) << " T=" << t << " vertex " << k;
      }
    }
  }
}

// Mixed factors from a table on every mesh: the watertight methods' positions and normals agree
// bit for bit across every edge and at every corner, naive's do not.
TEST(AdaptiveTessellation, WatertightMethodsKeepGapAndNormalGapZeroWithMixedFactors) {
  for (const Scene& scene : {generate_scene("displaced", {}), cube_obj(), make_torus(16, 8)}) {
    for (int t : {3, 8}) {
      for (DisplacementMethod m : kAllDisplacementMethods) {
        const PackedDisplacement packed = pack_displacement(scene, {m, t, 0, hashed_factors(scene, t)});
        const DisplacementGap gap = measure_gap(packed, device_tessellation(packed));
        EXPECT_GT(gap.compared_pairs, 0u);
        if (m == DisplacementMethod::Naive) {
          EXPECT_GT(gap.max_gap, 0.0) << scene.name << " T=" << t;
          EXPECT_GT(gap.max_normal_gap, 0.0) << scene.name << " T=" << t;
        } else if (m != DisplacementMethod::PtexFilter) {
          EXPECT_EQ(gap.max_gap, 0.0) << scene.name << " " << to_string(m) << " T=" << t;
          EXPECT_EQ(gap.differing_pairs, 0u) << scene.name << " " << to_string(m) << " T=" << t;
          EXPECT_EQ(gap.max_normal_gap, 0.0) << scene.name << " " << to_string(m) << " T=" << t;
          EXPECT_EQ(gap.differing_normals, 0u) << scene.name << " " << to_string(m) << " T=" << t;
        }
      }
    }
  }
}

// Screen-space factors (mixed: checked) over an 8-frame orbit, the tessellation of the scene's
// camera kept for every frame: no crack pixel for the watertight methods, some for naive.
TEST(AdaptiveTessellation, ScreenSpaceFactorsShowNoCrackPixelForTheWatertightMethods) {
  for (const Scene& scene : {generate_scene("displaced", {}), cube_obj(), make_torus(16, 8)}) {
    ASSERT_TRUE(is_closed_mesh(scene));
    const int t = 12;
    const float pixels = 6.0f;
    std::set<int> factors;
    for (const auto& face : screen_space_edge_factors(scene, view_projection(scene.camera, 240, 270), 240, 270, pixels, t))
      factors.insert(face.begin(), face.end());
    EXPECT_GE(factors.size(), 3u) << scene.name << ": the factors must be mixed";
    for (DisplacementMethod m : kWatertightMethods) {
      const DisplacementReport r =
          measure_displacement(shared_runtime(), scene, scene.camera, adaptive_options(m, t, pixels, 240, 270, 4), 8, 0);
      EXPECT_EQ(r.gap.max_gap, 0.0) << scene.name << " " << to_string(m);
      EXPECT_EQ(r.gap.max_normal_gap, 0.0) << scene.name << " " << to_string(m);
      EXPECT_LT(r.surface_triangles, r.triangles) << scene.name;
      ASSERT_TRUE(r.crack_pixels.has_value());
      EXPECT_EQ(*r.crack_pixels, 0u) << scene.name << " " << to_string(m);
    }
    const DisplacementReport naive = measure_displacement(
        shared_runtime(), scene, scene.camera, adaptive_options(DisplacementMethod::Naive, t, pixels, 240, 270, 4), 8, 0);
    EXPECT_GT(naive.gap.max_gap, 0.0) << scene.name;
    EXPECT_GT(naive.crack_pixels.value_or(0), 0u) << scene.name;
  }
}

}  // namespace
