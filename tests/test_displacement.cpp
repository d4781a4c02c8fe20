// The tessellation stage and the displacement seam methods (docs/displacement.md): the kernel
// against its twin, the exact gap between patches, and hostile displacement input.
#include <algorithm>
#include <cstring>
#include <map>
#include <set>
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
#include "pipeline/stages/tessellate_launcher.h"
#include "scene/displaced_scene.h"
#include "scene/displacement_map.h"
#include "test_support.h"
#include "pipeline/stages/tessellate_twin.h"
#include "pipeline/stages/triangle_setup_twin.h"

namespace {

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::kAllDisplacementMethods;
using seamcl_tests::kWatertightMethods;


const Scene& displaced() {
  static const Scene scene = generate_scene("displaced", {});
  return scene;
}

std::vector<TessVertex> device_tessellation(const Scene& scene, const DisplacementSettings& settings, PackedDisplacement* packed_out = nullptr) {
  TessellateLauncher stage(shared_runtime());
  stage.load(pack_displacement(scene, settings));
  std::vector<TessVertex> out = stage.tessellate();
  if (packed_out) *packed_out = stage.packed();
  return out;
}

std::string input_error_field(const std::function<void()>& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const InputError& e) {
    if (message) *message = e.what();
    return e.field();
  }
  return "(no InputError)";
}

TEST(Displacement, SceneIsClosedWithMixedResolutionsAndRotations) {
  const Scene& scene = displaced();
  ASSERT_TRUE(scene.displacement);
  EXPECT_TRUE(is_closed_mesh(scene));
  EXPECT_EQ(scene.faces.size(), 24u);
  std::set<int> sides;
  for (const DisplacementMap& m : scene.displacement->maps) {
    sides.insert(m.columns);
    sides.insert(m.rows);
  }
  EXPECT_GE(sides.size(), 5u) << "neighbours of several resolutions";
  EXPECT_TRUE(sides.count(2)) << "a 1-interval side next to finer ones";
  // Neighbours meet rotated: some shared edge is edge k of one face and edge m != k+2 of the other.
  const PackedDisplacement packed = pack_displacement(scene, {DisplacementMethod::Naive, 1, 0});
  std::set<int> turns;
  for (const DisplacementPatch& p : packed.patches)
    for (int e = 0; e < 4; ++e)
      if (p.neighbor[e] >= 0) turns.insert((p.neighbor_edge[e] - e + 4) % 4);
  EXPECT_EQ(turns, (std::set<int>{0, 1, 2, 3})) << "every rotation of a neighbour occurs";
}

TEST(Displacement, KernelMatchesTwinBitForBit) {
  for (DisplacementMethod method : kAllDisplacementMethods) {
    for (int t : {1, 3, 16}) {
      PackedDisplacement packed;
      const std::vector<TessVertex> device = device_tessellation(displaced(), {method, t, 0}, &packed);
      const std::vector<TessVertex> twin = tessellate_reference(packed);
      ASSERT_EQ(device.size(), twin.size());
      size_t differing = 0;
      for (size_t k = 0; k < device.size(); ++k) {
        if (std::memcmp(&device[k], &twin[k], sizeof(TessVertex)) != 0) {
          if (differing++ < 3) {
            ADD_FAILURE() << to_string(method) << " T=" << t << " vertex " << k << ": device (" << device[k].position[0]
                          << ", " << device[k].position[1] << ", " << device[k].position[2] << ") twin ("
                          << twin[k].position[0] << ", " << twin[k].position[1] << ", " << twin[k].position[2] << ")";
          }
        }
      }
      EXPECT_EQ(differing, 0u) << to_string(method) << " T=" << t;
    }
  }
}

TEST(Displacement, VerticesLieOnTheDisplacedSurface) {
  // Corners sit at their mesh vertex moved along its normal by scale * h, h in [0, 1].
  PackedDisplacement packed;
  const int t = 4;
  const std::vector<TessVertex> v = device_tessellation(displaced(), {DisplacementMethod::Ownership, t, 0}, &packed);
  const float scale = packed.params.scale;
  for (size_t p = 0; p < packed.patches.size(); ++p) {
    const TessVertex& corner = v[p * (t + 1) * (t + 1)];
    const cl_float4& base = packed.positions[packed.patches[p].vertex[0]];
    const glm::vec3 moved(corner.position[0] - base.s[0], corner.position[1] - base.s[1], corner.position[2] - base.s[2]);
    EXPECT_GE(corner.displacement, 0.0f);
    EXPECT_LE(corner.displacement, 1.0f);
    EXPECT_NEAR(glm::length(moved), scale * corner.displacement, 1e-5f) << "patch " << p;
    EXPECT_EQ(corner.u, 0.0f);
    EXPECT_EQ(corner.v, 0.0f);
  }
}

TEST(Displacement, WatertightMethodsHaveExactlyZeroGapAtEveryLevel) {
  for (DisplacementMethod method : kWatertightMethods) {
    for (int t : {1, 2, 3, 7, 16, 64}) {
      PackedDisplacement packed;
      const std::vector<TessVertex> v = device_tessellation(displaced(), {method, t, 0}, &packed);
      const DisplacementGap gap = measure_gap(packed, v);
      EXPECT_GT(gap.compared_pairs, 0u);
      EXPECT_EQ(gap.max_gap, 0.0) << to_string(method) << " T=" << t;
      EXPECT_EQ(gap.differing_pairs, 0u) << to_string(method) << " T=" << t;
    }
  }
}

TEST(Displacement, NaiveCracksOnTheMixedResolutionMesh) {
  for (int t : {2, 3, 7, 16, 64}) {
    PackedDisplacement packed;
    const std::vector<TessVertex> v = device_tessellation(displaced(), {DisplacementMethod::Naive, t, 0}, &packed);
    const DisplacementGap gap = measure_gap(packed, v);
    EXPECT_GT(gap.max_gap, 0.0) << "T=" << t;
    EXPECT_GT(gap.differing_pairs, 0u) << "T=" << t;
  }
}

TEST(Displacement, EdgeDomainPointsAgreeFromEitherSide) {
  // The Khronos invariance check: the domain point of step k on a shared edge, seen from the other
  // patch at step T - k (u -> 1 - u), is the same point, for every level.
  for (int t = 1; t <= 64; ++t) {
    const PackedDisplacement packed = pack_displacement(displaced(), {DisplacementMethod::Fixed, t, 0});
    // Scale 0 leaves only the domain points and the base surface.
    PackedDisplacement flat = packed;
    flat.params.scale = 0.0f;
    const std::vector<TessVertex> v = tessellate_reference(flat);
    const DisplacementGap gap = measure_gap(flat, v);
    ASSERT_EQ(gap.differing_pairs, 0u) << "T=" << t;
  }
}

TEST(Displacement, TessellatedSetupAtT1EqualsTriangleSetup) {
  // At T = 1 without displacement the micro-triangles are the quads' own triangles: the
  // tessellated setup must produce the same records as triangle_setup, bit for bit, and lit with
  // the face normals (displacement_normals=face) the same image; lit with the displaced surface's
  // normals (the default), whose corners average the patches around them, a different one.
  Scene scene = displaced();
  auto flat = std::make_shared<Displacement>(*scene.displacement);
  flat->scale = 0.0f;
  scene.displacement = flat;
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  RenderOptions options;
  options.width = 96;
  options.height = 80;
  options.msaa = 4;
  const RenderResult plain = renderer.render(scene.camera, options);
  const std::vector<TriangleSetup> plain_setups = renderer.read_setups();
  options.displacement = DisplacementMethod::Fixed;
  options.tessellation = 1;
  options.displacement_normals = DisplacementNormals::Face;
  const RenderResult tessellated = renderer.render(scene.camera, options);
  const std::vector<TriangleSetup> tess_setups = renderer.read_setups();
  ASSERT_EQ(plain_setups.size(), tess_setups.size());
  EXPECT_EQ(std::memcmp(plain_setups.data(), tess_setups.data(), plain_setups.size() * sizeof(TriangleSetup)), 0);
  const std::vector<TriangleSetup> twin = setup_triangles_reference(renderer.packed_scene(), renderer.last_frame_params());
  ASSERT_EQ(twin.size(), tess_setups.size());
  EXPECT_EQ(std::memcmp(twin.data(), tess_setups.data(), twin.size() * sizeof(TriangleSetup)), 0);
  ASSERT_EQ(plain.pixels.size(), tessellated.pixels.size());
  EXPECT_EQ(std::memcmp(plain.pixels.data(), tessellated.pixels.data(), plain.pixels.size() * sizeof(glm::vec4)), 0);
  EXPECT_GT(tessellated.stats.fragments, 0u);
  options.displacement_normals = DisplacementNormals::Displaced;
  const RenderResult smooth = renderer.render(scene.camera, options);
  EXPECT_EQ(smooth.stats.fragments, tessellated.stats.fragments);
  EXPECT_NE(std::memcmp(plain.pixels.data(), smooth.pixels.data(), plain.pixels.size() * sizeof(glm::vec4)), 0);
}

TEST(Displacement, DefaultRendersAreUnchangedByTheScenesMaps) {
  // Displacement is off unless asked for: the scene's maps change nothing in a plain render.
  Scene with_maps = displaced();
  Scene without = with_maps;
  without.displacement.reset();
  RenderOptions options;
  options.width = 64;
  options.height = 64;
  Renderer a(shared_runtime()), b(shared_runtime());
  a.load_scene(with_maps);
  b.load_scene(without);
  const RenderResult ra = a.render(with_maps.camera, options), rb = b.render(without.camera, options);
  EXPECT_EQ(std::memcmp(ra.pixels.data(), rb.pixels.data(), ra.pixels.size() * sizeof(glm::vec4)), 0);
}

// Face f's vertex list started one corner later, its map turned to match (the same surface,
// the same samples): new (u, v) is old (1 - v, u).
void rotate_face(Scene& scene, Displacement& d, size_t f) {
  auto& v = scene.faces[f].vertices;
  std::rotate(v.begin(), v.begin() + 1, v.end());
  const DisplacementMap old = d.maps[f];
  DisplacementMap turned;
  turned.columns = old.rows;
  turned.rows = old.columns;
  turned.samples.resize(old.samples.size());
  for (int j = 0; j < turned.rows; ++j)
    for (int i = 0; i < turned.columns; ++i) turned.at(i, j) = old.at(old.columns - 1 - j, i);
  d.maps[f] = turned;
}

TEST(Displacement, ZeroGapForEveryRotationOfANeighbour) {
  // Turn two neighbouring faces through all 16 combinations of their rotations.
  for (int ra = 0; ra < 4; ++ra) {
    for (int rb = 0; rb < 4; ++rb) {
      Scene scene = displaced();
      auto d = std::make_shared<Displacement>(*scene.displacement);
      const PackedDisplacement before = pack_displacement(scene, {DisplacementMethod::Naive, 1, 0});
      const size_t a = 5, b = static_cast<size_t>(before.patches[a].neighbor[0]);
      for (int k = 0; k < ra; ++k) rotate_face(scene, *d, a);
      for (int k = 0; k < rb; ++k) rotate_face(scene, *d, b);
      scene.displacement = d;
      for (DisplacementMethod method : kWatertightMethods) {
        for (int t : {3, 8}) {
          PackedDisplacement packed;
          const std::vector<TessVertex> v = device_tessellation(scene, {method, t, 0}, &packed);
          const DisplacementGap gap = measure_gap(packed, v);
          EXPECT_EQ(gap.differing_pairs, 0u) << to_string(method) << " T=" << t << " rotations " << ra << ", " << rb;
        }
      }
    }
  }
}

TEST(Displacement, CoarserLevelsStayWatertight) {
  for (int level : {1, 2, 5}) {
    for (DisplacementMethod method : kWatertightMethods) {
      PackedDisplacement packed;
      const std::vector<TessVertex> v = device_tessellation(displaced(), {method, 16, level}, &packed);
      const DisplacementGap gap = measure_gap(packed, v);
      EXPECT_EQ(gap.differing_pairs, 0u) << to_string(method) << " level " << level;
    }
  }
  // Level 5 leaves every map at 2 samples a side: the maps shrink as asked.
  const PackedDisplacement packed = pack_displacement(displaced(), {DisplacementMethod::Naive, 4, 5});
  for (const DisplacementPatch& p : packed.patches) {
    EXPECT_EQ(p.columns, 2);
    EXPECT_EQ(p.rows, 2);
  }
}

TEST(Displacement, FixedNeedsMatchedMapsAndSaysWhatMatchingChanged) {
  // The post: fixed point alone is not enough; the maps' edge samples must match. Fixed reports
  // how many samples its matching changed, and the same maps unmatched crack.
  PackedDisplacement packed = pack_displacement(displaced(), {DisplacementMethod::Fixed, 16, 0});
  EXPECT_GT(packed.matched_samples, 0u);
  EXPECT_EQ(packed.unmatched_edges, 0u);
  const PackedDisplacement raw = pack_displacement(displaced(), {DisplacementMethod::Naive, 16, 0});
  packed.samples = raw.samples;  // the unmatched maps, same layout
  const DisplacementGap gap = measure_gap(packed, tessellate_reference(packed));
  EXPECT_GT(gap.differing_pairs, 0u);
}

TEST(Displacement, CostsFollowTheMethod) {
  const int t = 8;
  std::map<DisplacementMethod, size_t> samples, bytes;
  for (DisplacementMethod method : kAllDisplacementMethods) {
    const PackedDisplacement packed = pack_displacement(displaced(), {method, t, 0});
    size_t taken = 0;
    for (const TessVertex& v : tessellate_reference(packed)) taken += v.samples;
    samples[method] = taken;
    bytes[method] = packed.method_bytes();
  }
  const size_t vertices = displaced().faces.size() * (t + 1) * (t + 1);
  EXPECT_EQ(samples[DisplacementMethod::Naive], vertices);
  EXPECT_EQ(samples[DisplacementMethod::Ownership], vertices) << "one sample per vertex";
  EXPECT_EQ(samples[DisplacementMethod::Fixed], vertices);
  // Zipper: two on each edge's T-1 inner vertices (both patches), none at corners.
  const size_t patches = displaced().faces.size();
  EXPECT_EQ(samples[DisplacementMethod::Zipper], vertices + patches * 4 * (t - 1) - patches * 4);
  EXPECT_EQ(bytes[DisplacementMethod::Ownership], patches * 16 * sizeof(DisplacementTexcoord));
  EXPECT_EQ(bytes[DisplacementMethod::Naive], 0u);
  // ptex-filter: up to 9 taps a vertex, fewer where taps past corners and boundaries drop out.
  EXPECT_GT(samples[DisplacementMethod::PtexFilter], 8 * vertices);
  EXPECT_LE(samples[DisplacementMethod::PtexFilter], 9 * vertices);
}

TEST(Displacement, PtexFilterCracksWhereFilterWidthsDiffer) {
  // Measured, not assumed: filtering across an edge with each side's own width leaves a gap
  // inside the edges of the mixed-resolution mesh; with one resolution everywhere the widths
  // agree and so do the edges (to float rounding), but corners still crack: each patch there
  // reads a different set of neighbours (the post: averaging does not work at corners).
  auto gap_of = [](const Scene& scene) {
    PackedDisplacement packed;
    const std::vector<TessVertex> v = device_tessellation(scene, {DisplacementMethod::PtexFilter, 8, 0}, &packed);
    return measure_gap(packed, v);
  };
  const DisplacementGap mixed = gap_of(displaced());
  Scene uniform = displaced();
  auto d = std::make_shared<Displacement>(*uniform.displacement);
  for (size_t f = 0; f < uniform.faces.size(); ++f)
    d->maps[f] = bake_displacement_map(uniform.corners(uniform.faces[f]), 9, 9, displacement_pattern);
  uniform.displacement = d;
  const DisplacementGap same = gap_of(uniform);
  EXPECT_GT(mixed.max_edge_gap, 0.0);
  EXPECT_GT(mixed.max_edge_gap, 100.0 * same.max_edge_gap) << "mixed " << mixed.max_edge_gap << ", uniform " << same.max_edge_gap;
  EXPECT_GT(same.max_corner_gap, 100.0 * same.max_edge_gap) << "corners " << same.max_corner_gap;
}

TEST(Displacement, RejectsHostileSettingsNamingTheField) {
  std::string message;
  EXPECT_EQ(input_error_field([] { parse_render_options({{"displacement_method", "wobbly"}}); }, &message),
            "displacement_method");
  EXPECT_NE(message.find("naive, zipper, ownership, fixed, ptex-filter"), std::string::npos) << message;
  EXPECT_EQ(input_error_field([] { parse_render_options({{"displacement_method", 3}}); }), "displacement_method");
  EXPECT_EQ(input_error_field([] { parse_render_options({{"tessellation", 0}}); }), "tessellation");
  EXPECT_EQ(input_error_field([] { parse_render_options({{"tessellation", 65}}); }), "tessellation");
  EXPECT_EQ(input_error_field([] { parse_render_options({{"tessellation", 2.5}}); }), "tessellation");
  EXPECT_EQ(input_error_field([] { parse_render_options({{"displacement_level", -1}}); }), "displacement_level");
  EXPECT_EQ(input_error_field([] { pack_displacement(displaced(), {DisplacementMethod::Zipper, 0, 0}); }), "tessellation");
  EXPECT_EQ(input_error_field([] { pack_displacement(displaced(), {DisplacementMethod::Zipper, 65, 0}); }), "tessellation");
  EXPECT_EQ(input_error_field([] { pack_displacement(generate_scene("cube", {}), {DisplacementMethod::Zipper, 4, 0}); }),
            "displacement");
  // Maps that do not fit the scene: too few, wrong sample counts, absurd sizes, bad scale.
  auto broken = [](auto&& edit) {
    Scene scene = displaced();
    auto d = std::make_shared<Displacement>(*scene.displacement);
    edit(*d);
    scene.displacement = d;
    return input_error_field([&] { pack_displacement(scene, {DisplacementMethod::Fixed, 4, 0}); });
  };
  EXPECT_EQ(broken([](Displacement& d) { d.maps.pop_back(); }), "displacement");
  EXPECT_EQ(broken([](Displacement& d) { d.maps[3].samples.pop_back(); }), "displacement");
  EXPECT_EQ(broken([](Displacement& d) { d.maps[3].columns = -2; }), "displacement");
  EXPECT_EQ(broken([](Displacement& d) { d.maps[3].columns = 100000; }), "displacement");
  EXPECT_EQ(broken([](Displacement& d) { d.scale = std::nanf(""); }), "displacement");
  // Through the renderer, the same errors, and the renderer still works afterwards.
  Renderer renderer(shared_runtime());
  renderer.load_scene(generate_scene("quad2", {}));
  RenderOptions options;
  options.width = options.height = 16;
  options.displacement = DisplacementMethod::Naive;
  EXPECT_EQ(input_error_field([&] { renderer.render(renderer.scene().camera, options); }), "displacement");
  options.displacement.reset();
  EXPECT_NO_THROW(renderer.render(renderer.scene().camera, options));
}

TEST(Displacement, OptionsRoundTripThroughJson) {
  const RenderOptions o = parse_render_options({{"displacement_method", "ownership"}, {"tessellation", 7}, {"displacement_level", 1}});
  ASSERT_TRUE(o.displacement);
  EXPECT_EQ(*o.displacement, DisplacementMethod::Ownership);
  EXPECT_EQ(o.tessellation, 7);
  const nlohmann::json j = to_json(o);
  EXPECT_EQ(j.at("displacement_method"), "ownership");
  EXPECT_EQ(j.at("tessellation"), 7);
  EXPECT_FALSE(to_json(RenderOptions{}).contains("displacement_method")) << "default renders say nothing of it";
  for (const std::string& name : displacement_method_names()) {
    ASSERT_TRUE(parse_displacement_method(name)) << name;
    EXPECT_EQ(to_string(*parse_displacement_method(name)), name);
  }
}

}  // namespace
