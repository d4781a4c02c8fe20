// Crack pixels on closed meshes that are not star-shaped: the Ptex cube (72 quads with tunnels)
// and a torus made here. Every watertight method must show none over an orbit, and naive, whose
// gap is not 0, must show some, so the counter is seen to fail as well as to pass.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/displacement_packing.h"
#include "scene/displaced_scene.h"
#include "scene/displacement_map.h"
#include "displacement_test_scenes.h"
#include "test_support.h"

namespace {

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::kWatertightMethods;

using seamcl_tests::cube_obj;
using seamcl_tests::kPtexAssets;
using seamcl_tests::make_torus;
const std::string& kAssets = kPtexAssets;

RenderOptions crack_options(DisplacementMethod method, int t, int width, int height, int msaa) {
  RenderOptions o;
  o.width = width;
  o.height = height;
  o.msaa = msaa;
  o.displacement = method;
  o.tessellation = t;
  return o;
}


// The counts each method shows on both meshes, for docs/displacement.md (not run by ctest:
// `seamcl_tests --gtest_also_run_disabled_tests --gtest_filter='*CrackPixelsReport*'`).
TEST(CrackPixelsReport, DISABLED_PrintsEveryMethod) {
  for (const Scene& scene : {cube_obj(), make_torus(16, 8)}) {
    ASSERT_TRUE(is_closed_mesh(scene));
    for (int t : {4, 16}) {
      for (DisplacementMethod m : {DisplacementMethod::Naive, DisplacementMethod::Zipper, DisplacementMethod::Ownership,
                                   DisplacementMethod::Fixed, DisplacementMethod::PtexFilter}) {
        const DisplacementReport r = measure_displacement(shared_runtime(), scene, scene.camera, crack_options(m, t, 480, 540, 4), 8, 0);
        std::printf("%s T=%d %s max_gap %g crack_pixels %zu\n", scene.name.c_str(), t, to_string(m).c_str(), r.gap.max_gap,
                    r.crack_pixels.value_or(0));
      }
    }
  }
}

// Every watertight method shows no crack over an 8-frame orbit, and naive, whose gap is not 0,
// shows some: the counter can fail.
void expect_cracks_only_where_the_gap_is_open(const Scene& scene, int width, int height) {
  ASSERT_TRUE(is_closed_mesh(scene));
  for (int t : {4, 9}) {
    for (DisplacementMethod m : kWatertightMethods) {
      const DisplacementReport r =
          measure_displacement(shared_runtime(), scene, scene.camera, crack_options(m, t, width, height, 4), 8, 0);
      ASSERT_EQ(r.gap.max_gap, 0.0) << scene.name << " " << to_string(m) << " T=" << t;
      ASSERT_TRUE(r.crack_pixels.has_value());
      EXPECT_EQ(r.crack_frames, 8);
      EXPECT_EQ(*r.crack_pixels, 0u) << scene.name << " " << to_string(m) << " T=" << t;
    }
    const DisplacementReport naive = measure_displacement(
        shared_runtime(), scene, scene.camera, crack_options(DisplacementMethod::Naive, t, width, height, 4), 8, 0);
    ASSERT_GT(naive.gap.max_gap, 0.0);
    ASSERT_TRUE(naive.crack_pixels.has_value());
    EXPECT_GT(*naive.crack_pixels, 0u) << scene.name << " naive T=" << t;
  }
}

TEST(CrackPixels, PtexCubeWithTunnelsCracksOnlyWhereTheGapIsOpen) {
  expect_cracks_only_where_the_gap_is_open(cube_obj(), 240, 270);
}

// Issue 39's command (480x540, 4x MSAA, 8 frames, T = 4 and 16), where the half-size shell
// charged the watertight methods with cracks. At T = 16 a fold of the text's steps lets a back
// face win a sample with no crack under it (docs/displacement.md): the coverage balance must not
// count it.
TEST(CrackPixels, TheIssuesCubeCommandCountsNoneForTheWatertightMethods) {
  const Scene scene = cube_obj();
  for (int t : {4, 16}) {
    for (DisplacementMethod m : kWatertightMethods) {
      const DisplacementReport r =
          measure_displacement(shared_runtime(), scene, scene.camera, crack_options(m, t, 480, 540, 4), 8, 0);
      EXPECT_EQ(r.crack_pixels.value_or(1), 0u) << to_string(m) << " T=" << t;
    }
  }
}

TEST(CrackPixels, TorusCracksOnlyWhereTheGapIsOpen) {
  const Scene torus = make_torus(16, 8);
  EXPECT_EQ(torus.faces.size(), 128u);
  expect_cracks_only_where_the_gap_is_open(torus, 240, 270);
}

// The displaced surface's normals (the device's displaced_normals, which measure_displacement
// reports and shading interpolates), computed by each patch at its own copy of a boundary point:
// bit for bit the same on both sides of every edge and at every mesh vertex for the watertight
// methods, different for naive, whose positions differ.
TEST(DisplacedNormals, AgreeBitForBitAcrossEveryEdgeForTheWatertightMethods) {
  Scene plane = load_scene_source(kAssets + "plane.obj");
  attach_ptex_displacement(plane, kAssets + "rand_lo.ptx");
  for (const Scene& scene : {generate_scene("displaced", {}), cube_obj(), make_torus(16, 8), plane}) {
    for (int t : {3, 8}) {
      for (DisplacementMethod m : kWatertightMethods) {
        const DisplacementReport r =
            measure_displacement(shared_runtime(), scene, scene.camera, crack_options(m, t, 32, 32, 1), 0, 0);
        EXPECT_EQ(r.gap.max_normal_gap, 0.0) << scene.name << " " << to_string(m) << " T=" << t;
        EXPECT_EQ(r.gap.differing_normals, 0u) << scene.name << " " << to_string(m) << " T=" << t;
      }
      const DisplacementReport naive = measure_displacement(shared_runtime(), scene, scene.camera,
                                                            crack_options(DisplacementMethod::Naive, t, 32, 32, 1), 0, 0);
      EXPECT_GT(naive.gap.max_normal_gap, 0.0) << scene.name << " T=" << t;
      EXPECT_GT(naive.gap.differing_normals, 0u) << scene.name << " T=" << t;
      EXPECT_LE(naive.gap.max_normal_gap, 2.0) << "unit normals differ by at most 2 a coordinate";
    }
  }
}

TEST(DisplacedNormals, PointOutOfTheUndisplacedSphereEverywhere) {
  // With no displacement the `displaced` scene is a closed polyhedron around the origin: every
  // normal, inside a patch, on its edges and at its corners, points away from the origin.
  Scene scene = generate_scene("displaced", {});
  auto flat = std::make_shared<Displacement>(*scene.displacement);
  flat->scale = 0.0f;
  scene.displacement = flat;
  const RenderOptions options = crack_options(DisplacementMethod::Fixed, 4, 32, 32, 1);
  const PackedDisplacement packed = pack_displacement(scene, {DisplacementMethod::Fixed, 4, 0});
  const std::vector<TessVertex> vertices = tessellate_displacement(shared_runtime(), scene, options);
  for (int p = 0; p < static_cast<int>(scene.faces.size()); ++p) {
    for (int j = 0; j <= 4; ++j) {
      for (int i = 0; i <= 4; ++i) {
        const std::array<float, 3> n = displaced_normal(packed, vertices, p, i, j);
        const float* at = vertices[(static_cast<size_t>(p) * 5 + j) * 5 + i].position;
        EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0f, 1e-5f);
        EXPECT_GT(n[0] * at[0] + n[1] * at[1] + n[2] * at[2], 0.5f) << "patch " << p << " (" << i << ", " << j << ")";
      }
    }
  }
}

}  // namespace
