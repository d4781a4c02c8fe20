// The scene model, the built-in generators and the JSON scene format.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <set>

#include <seamcl/assets/scene_source.h>
#include <seamcl/core/input_error.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>

namespace seamcl {
namespace {

using nlohmann::json;

constexpr size_t kPaperTorusFaces = 50 * 29;
constexpr size_t kPaperGroundFaces = 32 * 32;
constexpr glm::vec2 kCornerUv[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};

// The paper scene takes a noticeable fraction of a second to bake; build it once.
const Scene& paper_scene() {
  static const Scene scene = generate_scene("paper", {});
  return scene;
}

std::string examples_dir() { return SEAMCL_EXAMPLES_DIR; }

// The uv coordinate of the centre of texel i of n.
float texel_centre(int i, int n) { return (static_cast<float>(i) + 0.5f) / static_cast<float>(n); }

// Runs `action`, expecting an InputError for `field`; returns its message for further checks.
std::string expect_input_error(const std::function<void()>& action, const std::string& field) {
  try {
    action();
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), field) << error.what();
    return error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected InputError for " << field << ", got: " << error.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError for " << field << ", nothing thrown";
  return {};
}

TextureLevel level_from(int width, int height, std::function<float(int, int)> value) {
  TextureLevel level{width, height, {}};
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) level.texels.emplace_back(value(i, j), 0.0f, 1.0f, 1.0f);
  return level;
}

std::vector<std::pair<int, int>> level_sizes(const MipChain& chain) {
  std::vector<std::pair<int, int>> sizes;
  for (const TextureLevel& level : chain.levels) sizes.emplace_back(level.width, level.height);
  return sizes;
}

// Each directed edge (a, b) of faces [first, last) with the face and edge number it belongs to.
std::map<std::pair<uint32_t, uint32_t>, std::vector<std::pair<size_t, int>>> directed_edges(
    const Scene& scene, size_t first, size_t last) {
  std::map<std::pair<uint32_t, uint32_t>, std::vector<std::pair<size_t, int>>> edges;
  for (size_t f = first; f < last; ++f)
    for (int k = 0; k < 4; ++k)
      edges[{scene.faces[f].vertices[k], scene.faces[f].vertices[(k + 1) % 4]}].emplace_back(f, k);
  return edges;
}

// Every edge used exactly once in each direction: a closed, consistently oriented mesh.
void expect_closed(const Scene& scene, size_t first, size_t last) {
  const auto edges = directed_edges(scene, first, last);
  size_t bad = 0;
  for (const auto& [edge, users] : edges) {
    const auto reverse = edges.find({edge.second, edge.first});
    if (users.size() != 1 || reverse == edges.end() || reverse->second.size() != 1) ++bad;
  }
  EXPECT_EQ(bad, 0u) << "of " << edges.size() << " directed edges";
  EXPECT_EQ(edges.size(), 4 * (last - first));
}

// An upper bound on |grad| of every channel of surface_pattern (estimated, with a safety margin).
float pattern_lipschitz_bound() {
  std::mt19937 random(7);
  auto coordinate = [&random] { return static_cast<float>(random() % 20000) / 1000.0f - 10.0f; };
  constexpr float h = 1e-3f;
  float bound = 0.0f;
  for (int n = 0; n < 20000; ++n) {
    const glm::vec3 p(coordinate(), coordinate(), coordinate());
    glm::vec3 gradient[3];
    for (int axis = 0; axis < 3; ++axis) {
      glm::vec3 step(0.0f);
      step[axis] = h;
      const glm::vec4 slope = (surface_pattern(p + step) - surface_pattern(p - step)) / (2 * h);
      for (int c = 0; c < 3; ++c) gradient[c][axis] = slope[c];
    }
    for (const glm::vec3& g : gradient) bound = std::max(bound, glm::length(g));
  }
  return 1.5f * bound;
}

// ---------------------------------------------------------------------------------------------
// Scene model

TEST(Scene, MipChainSizesGoDownToOneByOne) {
  auto sizes_for = [](int width, int height) {
    return level_sizes(build_mip_chain(level_from(width, height, [](int, int) { return 0.0f; })));
  };
  using Sizes = std::vector<std::pair<int, int>>;
  EXPECT_EQ(sizes_for(8, 2), (Sizes{{8, 2}, {4, 1}, {2, 1}, {1, 1}}));
  EXPECT_EQ(sizes_for(1, 4), (Sizes{{1, 4}, {1, 2}, {1, 1}}));
  EXPECT_EQ(sizes_for(16, 16).size(), 5u);
  EXPECT_EQ(sizes_for(1, 1), (Sizes{{1, 1}}));
}

TEST(Scene, MipChainIsABoxFilterPerLevel) {
  // 4x2: value i + 10 j.
  const MipChain wide =
      build_mip_chain(level_from(4, 2, [](int i, int j) { return float(i + 10 * j); }));
  ASSERT_EQ(wide.levels.size(), 3u);
  EXPECT_FLOAT_EQ(wide.levels[1].at(0, 0).x, (0 + 1 + 10 + 11) / 4.0f);
  EXPECT_FLOAT_EQ(wide.levels[1].at(1, 0).x, (2 + 3 + 12 + 13) / 4.0f);
  EXPECT_FLOAT_EQ(wide.levels[2].at(0, 0).x, (5.5f + 7.5f) / 2.0f);  // 2x1 -> 1x1
  EXPECT_FLOAT_EQ(wide.levels[2].at(0, 0).w, 1.0f);

  // 1x4: the 1-wide side is not halved, so each level averages vertical pairs.
  const MipChain tall = build_mip_chain(level_from(1, 4, [](int, int j) { return float(j * j); }));
  ASSERT_EQ(tall.levels.size(), 3u);
  EXPECT_FLOAT_EQ(tall.levels[1].at(0, 0).x, 0.5f);
  EXPECT_FLOAT_EQ(tall.levels[1].at(0, 1).x, 6.5f);
  EXPECT_FLOAT_EQ(tall.levels[2].at(0, 0).x, 3.5f);
}

TEST(Scene, MipChainRejectsBadLevel0) {
  expect_input_error([] { build_mip_chain(level_from(3, 4, [](int, int) { return 0.0f; })); },
                     "texture");
  expect_input_error([] { build_mip_chain(TextureLevel{0, 0, {}}); }, "texture");
  TextureLevel short_level = level_from(4, 4, [](int, int) { return 0.0f; });
  short_level.texels.pop_back();
  expect_input_error([&] { build_mip_chain(short_level); }, "texture");
}

TEST(Scene, FacePointInterpolatesEachTriangle) {
  // Non-planar on purpose: the two triangles differ from a bilinear patch.
  const std::array<glm::vec3, 4> c = {glm::vec3(0, 0, 0), glm::vec3(2, 0, 0.5f),
                                      glm::vec3(2, 1, -0.3f), glm::vec3(0, 1.5f, 0.2f)};
  for (int k = 0; k < 4; ++k) {
    const glm::vec3 p = face_point(c, kCornerUv[k].x, kCornerUv[k].y);
    EXPECT_LT(glm::distance(p, c[k]), 1e-6f) << "corner " << k;
  }
  EXPECT_LT(glm::distance(face_point(c, 0.5f, 0.5f), 0.5f * (c[0] + c[2])), 1e-6f);
  // (0.75, 0.25) is in triangle (v0, v1, v2), (0.25, 0.75) in (v0, v2, v3): each on its plane.
  const glm::vec3 lower = face_point(c, 0.75f, 0.25f);
  EXPECT_NEAR(glm::dot(lower - c[0], glm::cross(c[1] - c[0], c[2] - c[0])), 0.0f, 1e-5f);
  const glm::vec3 upper = face_point(c, 0.25f, 0.75f);
  EXPECT_NEAR(glm::dot(upper - c[0], glm::cross(c[2] - c[0], c[3] - c[0])), 0.0f, 1e-5f);
  EXPECT_LT(glm::distance(lower, 0.25f * c[0] + 0.5f * c[1] + 0.25f * c[2]), 1e-6f);
}

TEST(Scene, FacePointAgreesAlongSharedEdges) {
  const glm::vec3 a0(0, 0, 0), a1(1, 0, 0.3f), a2(1.1f, 1, -0.2f), a3(0, 0.9f, 0.4f);
  const glm::vec3 right1(2, 0.1f, 0.0f), right2(2.2f, 1.2f, 0.5f);
  const glm::vec3 top2(1.3f, 2.0f, 0.1f), top3(0.1f, 1.8f, -0.3f);
  const std::array<glm::vec3, 4> face{a0, a1, a2, a3};
  const std::array<glm::vec3, 4> right{a1, right1, right2, a2};  // shares a1-a2 as its u = 0 edge
  const std::array<glm::vec3, 4> above{a3, a2, top2, top3};      // shares a3-a2 as its v = 0 edge
  for (int s = 0; s <= 32; ++s) {
    const float t = static_cast<float>(s) / 32.0f;
    EXPECT_LT(glm::distance(face_point(face, 1.0f, t), face_point(right, 0.0f, t)), 1e-6f) << t;
    EXPECT_LT(glm::distance(face_point(face, t, 1.0f), face_point(above, t, 0.0f)), 1e-6f) << t;
  }
}

TEST(Scene, BakeSamplesTexelCentres) {
  const std::array<glm::vec3, 4> c = {glm::vec3(0, 0, 0), glm::vec3(4, 0, 0), glm::vec3(4, 2, 1),
                                      glm::vec3(0, 2, 0)};
  const TextureLevel level =
      bake_face_texture(c, 8, 4, [](glm::vec3 p) { return glm::vec4(p, 1.0f); });
  ASSERT_EQ(level.width, 8);
  ASSERT_EQ(level.height, 4);
  ASSERT_EQ(level.texels.size(), 32u);
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 8; ++i) {
      const glm::vec3 expected = face_point(c, texel_centre(i, 8), texel_centre(j, 4));
      EXPECT_LT(glm::distance(glm::vec3(level.at(i, j)), expected), 1e-6f) << i << "," << j;
    }
}

TEST(Scene, FaceNormalCornersAndTexelCount) {
  Scene scene;
  scene.positions = {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}};
  scene.faces.push_back(
      {{0, 1, 2, 3}, build_mip_chain(level_from(4, 2, [](int, int) { return 0.0f; }))});
  EXPECT_EQ(scene.corners(scene.faces[0])[2], glm::vec3(2, 1, 0));
  EXPECT_LT(glm::distance(scene.face_normal(scene.faces[0]), glm::vec3(0, 0, 1)), 1e-6f);
  EXPECT_EQ(scene.texel_count(), 8u + 2u + 1u);
  EXPECT_EQ(scene.triangle_count(), 2u);
  std::swap(scene.faces[0].vertices[1], scene.faces[0].vertices[3]);  // clockwise: faces away
  EXPECT_LT(glm::distance(scene.face_normal(scene.faces[0]), glm::vec3(0, 0, -1)), 1e-6f);
}

TEST(Scene, SetConstantTexturesKeepsSizesAndFullChains) {
  Scene scene = generate_scene("quad2", {});
  const glm::vec4 color(0.2f, 0.4f, 0.6f, 1.0f);
  set_constant_textures(scene, color);
  EXPECT_EQ(level_sizes(scene.faces[1].texture),
            (std::vector<std::pair<int, int>>{{32, 16}, {16, 8}, {8, 4}, {4, 2}, {2, 1}, {1, 1}}));
  EXPECT_EQ(scene.faces[0].texture.levels.size(), 7u);
  for (const Face& face : scene.faces)
    for (const TextureLevel& level : face.texture.levels)
      for (const glm::vec4& texel : level.texels) ASSERT_EQ(texel, color);
  validate_scene(scene);
}

TEST(Scene, SurfacePatternIsBoundedColourfulAndDetailed) {
  std::mt19937 random(11);
  auto coordinate = [&random] { return static_cast<float>(random() % 16000) / 1000.0f - 8.0f; };
  double mean_range_over_half_unit = 0.0;
  double mean_chroma = 0.0;
  constexpr int kSegments = 2000;
  for (int n = 0; n < kSegments; ++n) {
    const glm::vec3 start(coordinate(), coordinate(), coordinate());
    const glm::vec3 direction =
        glm::normalize(glm::vec3(coordinate(), coordinate(), coordinate()) + 1e-3f);
    glm::vec3 low(1.0f), high(0.0f);
    for (int s = 0; s <= 50; ++s) {
      const glm::vec4 c =
          surface_pattern(start + direction * (0.5f * static_cast<float>(s) / 50.0f));
      ASSERT_EQ(c.w, 1.0f);
      for (int k = 0; k < 3; ++k) {
        ASSERT_GE(c[k], 0.05f);
        ASSERT_LE(c[k], 0.95f);
      }
      low = glm::min(low, glm::vec3(c));
      high = glm::max(high, glm::vec3(c));
      if (s == 0) mean_chroma += std::max({c.r, c.g, c.b}) - std::min({c.r, c.g, c.b});
    }
    mean_range_over_half_unit += std::max({high.r - low.r, high.g - low.g, high.b - low.b});
  }
  // Over any half unit the colour changes a lot (features of 0.2-0.5 units), and it is not grey.
  EXPECT_GT(mean_range_over_half_unit / kSegments, 0.3);
  EXPECT_GT(mean_chroma / kSegments, 0.15);
  // Smooth: bounded slope (a stripe of 0.15 units at full contrast would be ~6 per unit).
  EXPECT_LT(pattern_lipschitz_bound(), 40.0f);
}

TEST(Scene, SurfacePatternsEqualSurfacePatternAtEveryPoint) {
  // The batched pattern (the bakes') against the one-point pattern (the analytic reference's):
  // equal to the bit, for counts that fill its lanes and counts that leave some empty.
  std::mt19937 random(5);
  std::uniform_real_distribution<float> coordinate(-40.0f, 40.0f);
  for (size_t count : {size_t{1}, size_t{7}, size_t{8}, size_t{9}, size_t{1000}}) {
    std::vector<glm::vec3> points(count);
    for (glm::vec3& p : points) p = {coordinate(random), coordinate(random), coordinate(random)};
    std::vector<glm::vec4> colors(count, glm::vec4(-1.0f));
    surface_patterns(points.data(), count, colors.data());
    for (size_t i = 0; i < count; ++i) {
      const glm::vec4 one = surface_pattern(points[i]);
      for (int c = 0; c < 4; ++c)
        ASSERT_EQ(std::bit_cast<uint32_t>(colors[i][c]), std::bit_cast<uint32_t>(one[c]))
            << "point " << i << " of " << count << ", channel " << c << ": " << colors[i][c] << " vs " << one[c];
    }
  }
  // A bake through the batch equals a bake a point at a time.
  const std::array<glm::vec3, 4> corners = {glm::vec3(0.1f, 0.0f, 0.3f), glm::vec3(1.3f, 0.2f, 0.1f),
                                            glm::vec3(1.1f, 1.4f, 0.0f), glm::vec3(-0.2f, 1.0f, 0.4f)};
  const TextureLevel batched = bake_face_texture(corners, 37, 5, surface_patterns);
  const TextureLevel single = bake_face_texture(corners, 37, 5, [](glm::vec3 p) { return surface_pattern(p); });
  ASSERT_EQ(batched.texels.size(), single.texels.size());
  for (size_t t = 0; t < batched.texels.size(); ++t) ASSERT_EQ(batched.texels[t], single.texels[t]) << "texel " << t;
}

TEST(Scene, OrbitCameraMath) {
  Scene scene = generate_scene("cube", {});
  scene.orbit = Orbit{glm::vec3(1, 2, 3), 4.0f, 0.5f, 0.0f};
  scene.camera.fov_y_degrees = 30.0f;
  const glm::vec3 expected_eyes[4] = {{1, 2.5f, 7}, {5, 2.5f, 3}, {1, 2.5f, -1}, {-3, 2.5f, 3}};
  for (int frame = 0; frame < 4; ++frame) {
    const Camera camera = orbit_camera(scene, frame, 4);
    EXPECT_LT(glm::distance(camera.eye, expected_eyes[frame]), 1e-5f) << frame;
    EXPECT_EQ(camera.target, glm::vec3(1, 2, 3));
    EXPECT_EQ(camera.up, glm::vec3(0, 1, 0));
    EXPECT_EQ(camera.fov_y_degrees, 30.0f);
  }
  scene.orbit->start_degrees = 90.0f;
  EXPECT_LT(glm::distance(orbit_camera(scene, 0, 1).eye, expected_eyes[1]), 1e-5f);
  EXPECT_LT(glm::distance(orbit_camera(scene, 3, 4).eye, expected_eyes[0]), 1e-5f);
}

TEST(Scene, OrbitCameraErrors) {
  Scene scene = generate_scene("cube", {});
  expect_input_error([&] { orbit_camera(scene, 0, 0); }, "frames");
  expect_input_error([&] { orbit_camera(scene, -1, 4); }, "frame");
  expect_input_error([&] { orbit_camera(scene, 4, 4); }, "frame");
  // An orbit whose eye sits (next to) on the vertical through the centre looks along world up:
  // refused like such a static camera, not rendered blank.
  const Orbit kept = *scene.orbit;
  scene.orbit->radius = 1e-30f;
  scene.orbit->height = 5.0f;
  EXPECT_NE(expect_input_error([&] { orbit_camera(scene, 0, 4); }, "orbit.radius").find("straight along the vertical"),
            std::string::npos);
  scene.orbit->height = 0.0f;  // the eye on the centre
  EXPECT_NE(expect_input_error([&] { orbit_camera(scene, 1, 4); }, "orbit.radius").find("frame 1's eye on the centre"),
            std::string::npos);
  *scene.orbit = kept;
  EXPECT_NO_THROW(orbit_camera(scene, 3, 4));
  scene.orbit.reset();
  const std::string message = expect_input_error([&] { orbit_camera(scene, 0, 4); }, "frame");
  EXPECT_NE(message.find("no orbit"), std::string::npos) << message;
}

TEST(Scene, ValidateNamesTheFieldAtFault) {
  const Scene valid = generate_scene("quad2", {});
  ASSERT_NO_THROW(validate_scene(valid));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<std::pair<std::string, std::function<void(Scene&)>>> cases = {
      {"faces", [](Scene& s) { s.faces.clear(); }},
      {"positions[4]", [&](Scene& s) { s.positions[4].y = nan; }},
      {"faces[1].vertices[2]", [](Scene& s) { s.faces[1].vertices[2] = 6; }},
      {"faces[0].vertices",
       [](Scene& s) {
         s.faces[0].vertices = {0, 1, 1, 0};
       }},
      {"faces[0].texture", [](Scene& s) { s.faces[0].texture.levels.pop_back(); }},
      {"faces[1].texture", [&](Scene& s) { s.faces[1].texture.levels[2].texels[5].x = nan; }},
      {"faces[0].texture",
       [](Scene& s) {
         s.faces[0].texture = build_mip_chain(level_from(8192, 1, [](int, int) { return 0.f; }));
       }},
      {"faces[1].texture", [](Scene& s) { s.faces[1].texture.levels.clear(); }},
      {"camera.fov_y_degrees", [](Scene& s) { s.camera.fov_y_degrees = 0.0f; }},
      {"camera.fov_y_degrees", [](Scene& s) { s.camera.fov_y_degrees = 180.0f; }},
      {"camera.eye", [](Scene& s) { s.camera.eye = s.camera.target; }},
      {"camera.eye", [&](Scene& s) { s.camera.eye.x = nan; }},
      {"camera.up", [](Scene& s) { s.camera.up = s.camera.target - s.camera.eye; }},
      {"camera.up", [](Scene& s) { s.camera.up = glm::vec3(0.0f); }},
      {"light.to_light", [](Scene& s) { s.light.to_light = glm::vec3(0.0f); }},
      {"light.ambient", [](Scene& s) { s.light.ambient = 1.5f; }},
      {"orbit.radius", [](Scene& s) { s.orbit->radius = 0.0f; }},
      {"background", [](Scene& s) { s.background.z = -1.0f; }},
  };
  for (const auto& [field, mutate] : cases) {
    SCOPED_TRACE(field);
    Scene scene = valid;
    mutate(scene);
    expect_input_error([&] { validate_scene(scene); }, field);
  }
}

// ---------------------------------------------------------------------------------------------
// Generators

TEST(Generators, ListsTheScenesWithPaperFirst) {
  std::vector<std::string> names;
  for (const GeneratorInfo& info : scene_generators()) {
    names.push_back(info.name);
    EXPECT_FALSE(info.description.empty()) << info.name;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"paper", "quad2", "plane", "cube", "closeup-seam", "closeup-corner",
                                             "mixed", "envmap", "displaced"}));
  const std::string message = expect_input_error([] { generate_scene("teapot", {}); }, "scene");
  EXPECT_NE(message.find("unknown scene 'teapot' (known: paper, quad2, plane, cube, closeup-seam, closeup-corner, mixed, envmap, displaced)"),
            std::string::npos)
      << message;
}

TEST(Generators, PaperHasTheFigureOneCountsAndMixedTextureSizes) {
  const Scene& scene = paper_scene();
  ASSERT_EQ(scene.faces.size(), kPaperTorusFaces + kPaperGroundFaces);
  const std::set<int> allowed = {16, 32, 64, 128};
  std::set<int> widths, heights;
  std::set<std::pair<int, int>> sizes;
  size_t non_square = 0;
  for (const Face& face : scene.faces) {
    ASSERT_TRUE(allowed.count(face.texture.width())) << face.texture.width();
    ASSERT_TRUE(allowed.count(face.texture.height())) << face.texture.height();
    widths.insert(face.texture.width());
    heights.insert(face.texture.height());
    sizes.emplace(face.texture.width(), face.texture.height());
    non_square += face.texture.width() != face.texture.height();
  }
  EXPECT_EQ(widths, allowed);
  EXPECT_EQ(heights, allowed);
  EXPECT_EQ(sizes.size(), 16u);
  EXPECT_GT(non_square, scene.faces.size() / 2);
  EXPECT_LT(non_square, scene.faces.size());
  EXPECT_TRUE(scene.orbit.has_value());
  EXPECT_EQ(scene.camera.fov_y_degrees, 45.0f);
}

TEST(Generators, PaperTorusStandsOnTheGroundFacingOutwards) {
  const Scene& scene = paper_scene();
  float lowest = std::numeric_limits<float>::max();
  glm::vec3 torus_min(std::numeric_limits<float>::max()),
      torus_max(-std::numeric_limits<float>::max());
  for (size_t f = 0; f < kPaperTorusFaces; ++f)
    for (const glm::vec3& p : scene.corners(scene.faces[f])) {
      lowest = std::min(lowest, p.y);
      torus_min = glm::min(torus_min, p);
      torus_max = glm::max(torus_max, p);
    }
  EXPECT_GE(lowest, 0.0f);
  EXPECT_LT(lowest, 0.05f);
  const glm::vec3 extent = torus_max - torus_min;
  EXPECT_GT(extent.y, 2.0f * extent.z) << "upright: the axis is horizontal";
  EXPECT_NEAR(extent.x, extent.y, 0.05f);
  // Outward: away from the tube's centre circle (axis z through the torus centre).
  const glm::vec3 centre = 0.5f * (torus_min + torus_max);
  for (size_t f = 0; f < kPaperTorusFaces; ++f) {
    const auto c = scene.corners(scene.faces[f]);
    const glm::vec3 face_centre = 0.25f * (c[0] + c[1] + c[2] + c[3]);
    const glm::vec2 radial = glm::normalize(glm::vec2(face_centre - centre));
    const glm::vec3 tube_centre = centre + glm::vec3(2.0f * radial, 0.0f);
    ASSERT_GT(
        glm::dot(scene.face_normal(scene.faces[f]), glm::normalize(face_centre - tube_centre)),
        0.9f)
        << "face " << f;
  }
  for (size_t f = kPaperTorusFaces; f < scene.faces.size(); ++f)
    ASSERT_GT(scene.face_normal(scene.faces[f]).y, 0.999f) << "ground face " << f;
}

TEST(Generators, GroundAndPlaneFacesPointUp) {
  const Scene plane = generate_scene("plane", {});
  EXPECT_EQ(plane.faces.size(), 64u * 64u);
  for (const Face& face : plane.faces) ASSERT_GT(plane.face_normal(face).y, 0.999f);
  EXPECT_LT(plane.camera.eye.y, 1.5f) << "grazing view";
  const auto edges = directed_edges(plane, 0, plane.faces.size());
  size_t shared = 0;
  for (const auto& [edge, users] : edges) shared += edges.count({edge.second, edge.first});
  EXPECT_EQ(shared, 2u * (2u * 64u * 63u)) << "every interior edge in both directions";
}

TEST(Generators, CubeAndPaperTorusAreClosed) {
  const Scene cube = generate_scene("cube", {});
  ASSERT_EQ(cube.faces.size(), 6u);
  expect_closed(cube, 0, cube.faces.size());
  expect_closed(paper_scene(), 0, kPaperTorusFaces);
  for (const Face& face : cube.faces) {
    const auto c = cube.corners(face);
    const glm::vec3 centre = 0.25f * (c[0] + c[1] + c[2] + c[3]);
    EXPECT_GT(glm::dot(cube.face_normal(face), centre), 0.99f) << "outward";
    EXPECT_EQ(face.texture.width(), 64);
    EXPECT_EQ(face.texture.height(), 64);
  }
}

TEST(Generators, DefaultCamerasSeeTheirSubject) {
  for (const GeneratorInfo& info : scene_generators()) {
    SCOPED_TRACE(info.name);
    const Scene scene = info.name == "paper" ? paper_scene() : generate_scene(info.name, {});
    ASSERT_TRUE(scene.orbit.has_value());
    const Camera frame0 = orbit_camera(scene, 0, 1);
    EXPECT_LT(glm::distance(frame0.eye, scene.camera.eye), 1e-4f)
        << "the default camera is frame 0";
    EXPECT_LT(glm::distance(frame0.target, scene.camera.target), 1e-4f);
    // The subject's centre is well inside the view cone, and front faces face the camera.
    glm::vec3 low(std::numeric_limits<float>::max()), high(-std::numeric_limits<float>::max());
    size_t facing = 0;
    for (const Face& face : scene.faces) {
      const auto c = scene.corners(face);
      for (const glm::vec3& p : c) low = glm::min(low, p), high = glm::max(high, p);
      facing += glm::dot(scene.face_normal(face), scene.camera.eye - c[0]) > 0.0f;
    }
    const glm::vec3 view = glm::normalize(scene.camera.target - scene.camera.eye);
    const glm::vec3 to_subject = glm::normalize(0.5f * (low + high) - scene.camera.eye);
    EXPECT_GT(glm::dot(view, to_subject), std::cos(glm::radians(scene.camera.fov_y_degrees / 4)));
    EXPECT_GT(facing, scene.faces.size() / 3);
    if (info.name == "cube") {
      EXPECT_EQ(facing, 3u) << "oblique: three faces show";
    }
    if (info.name == "quad2") {
      EXPECT_EQ(facing, 2u);
    }
    EXPECT_GT(
        glm::dot(scene.light.to_light, glm::normalize(scene.camera.eye - scene.camera.target)),
        0.0f)
        << "lit from the camera's side";
  }
}

TEST(Generators, QuadTwoSharesOneEdgeBetweenDifferentSizes) {
  const Scene scene = generate_scene("quad2", {});
  ASSERT_EQ(scene.faces.size(), 2u);
  EXPECT_EQ(level_sizes(scene.faces[0].texture).front(), std::make_pair(64, 64));
  EXPECT_EQ(level_sizes(scene.faces[1].texture).front(), std::make_pair(32, 16));
  const auto edges = directed_edges(scene, 0, 2);
  size_t shared = 0;
  for (const auto& [edge, users] : edges) shared += edges.count({edge.second, edge.first});
  EXPECT_EQ(shared, 2u);
}

// Textures are baked from one continuous function, so across every shared edge of the torus the
// texels nearest the edge on both sides differ by no more than the function can change over the
// distance between their centres (about half a texel on each side).
TEST(Generators, AdjacentPaperTexturesAgreeAtSharedEdges) {
  const Scene& scene = paper_scene();
  const float lipschitz = pattern_lipschitz_bound();
  const auto edges = directed_edges(scene, 0, kPaperTorusFaces);
  size_t compared = 0, differing_sizes = 0;
  float worst_ratio = 0.0f;
  auto nearest_texel = [](const TextureLevel& level, glm::vec2 uv) {
    return glm::ivec2(
        std::clamp(static_cast<int>(uv.x * static_cast<float>(level.width)), 0, level.width - 1),
        std::clamp(static_cast<int>(uv.y * static_cast<float>(level.height)), 0, level.height - 1));
  };
  for (const auto& [edge, users] : edges) {
    const auto reverse = edges.find({edge.second, edge.first});
    ASSERT_NE(reverse, edges.end());
    const auto [face_a, edge_a] = users.front();
    const auto [face_b, edge_b] = reverse->second.front();
    const Face& a = scene.faces[face_a];
    const Face& b = scene.faces[face_b];
    const TextureLevel& level_a = a.texture.levels.front();
    const TextureLevel& level_b = b.texture.levels.front();
    differing_sizes += level_a.width != level_b.width || level_a.height != level_b.height;
    for (int s = 0; s < 32; ++s) {
      const float t = texel_centre(s, 32);
      // The same point of the edge, in each face's uv (b runs along it the other way).
      const glm::vec2 uv_a = glm::mix(kCornerUv[edge_a], kCornerUv[(edge_a + 1) % 4], t);
      const glm::vec2 uv_b = glm::mix(kCornerUv[edge_b], kCornerUv[(edge_b + 1) % 4], 1.0f - t);
      ASSERT_LT(glm::distance(face_point(scene.corners(a), uv_a.x, uv_a.y),
                              face_point(scene.corners(b), uv_b.x, uv_b.y)),
                1e-5f);
      const glm::ivec2 texel_a = nearest_texel(level_a, uv_a);
      const glm::ivec2 texel_b = nearest_texel(level_b, uv_b);
      const glm::vec3 centre_a =
          face_point(scene.corners(a), texel_centre(texel_a.x, level_a.width),
                     texel_centre(texel_a.y, level_a.height));
      const glm::vec3 centre_b =
          face_point(scene.corners(b), texel_centre(texel_b.x, level_b.width),
                     texel_centre(texel_b.y, level_b.height));
      const glm::vec4 difference =
          glm::abs(level_a.at(texel_a.x, texel_a.y) - level_b.at(texel_b.x, texel_b.y));
      const float largest = std::max({difference.r, difference.g, difference.b});
      const float tolerance = lipschitz * glm::distance(centre_a, centre_b) + 1e-4f;
      ASSERT_LE(largest, tolerance) << "faces " << face_a << " and " << face_b << " at t " << t;
      worst_ratio = std::max(worst_ratio, largest / tolerance);
      ++compared;
    }
  }
  EXPECT_EQ(compared, 32u * 4u * kPaperTorusFaces) << "each edge from both sides";
  EXPECT_GT(differing_sizes, edges.size() / 2);
  EXPECT_GT(worst_ratio, 0.01f) << "the comparison is not vacuous";
}

TEST(Generators, AreDeterministic) {
  const Scene again = generate_scene("paper", {});
  const Scene& first = paper_scene();
  ASSERT_EQ(again.faces.size(), first.faces.size());
  for (size_t f = 0; f < first.faces.size(); f += 97) {
    ASSERT_EQ(level_sizes(again.faces[f].texture), level_sizes(first.faces[f].texture));
    ASSERT_EQ(again.faces[f].texture.levels[1].texels, first.faces[f].texture.levels[1].texels);
  }
  EXPECT_EQ(again.positions, first.positions);
}

TEST(Generators, TintAndConstantColourOptions) {
  const Scene plain = generate_scene("cube", {});
  const Scene tinted = generate_scene("cube", {.tint = true, .constant_color = std::nullopt});
  std::set<std::tuple<float, float, float>> tints;
  for (size_t f = 0; f < plain.faces.size(); ++f) {
    const glm::vec3 tint = face_tint(f);
    tints.emplace(tint.r, tint.g, tint.b);
    EXPECT_GE(std::min({tint.r, tint.g, tint.b}), 0.5f) << "pastel";
    const glm::vec4 expected = plain.faces[f].texture.levels[0].texels[100] * glm::vec4(tint, 1.0f);
    EXPECT_LT(glm::distance(tinted.faces[f].texture.levels[0].texels[100], expected), 1e-6f);
  }
  EXPECT_EQ(tints.size(), plain.faces.size()) << "distinct per face";
  EXPECT_EQ(face_tint(3), face_tint(3));

  const glm::vec3 grey(0.5f);
  const Scene constant = generate_scene("cube", {.tint = false, .constant_color = grey});
  for (const Face& face : constant.faces)
    for (const TextureLevel& level : face.texture.levels)
      for (const glm::vec4& texel : level.texels)
        ASSERT_LT(glm::distance(texel, glm::vec4(grey, 1.0f)), 1e-6f);
  const Scene both = generate_scene("cube", {.tint = true, .constant_color = grey});
  EXPECT_LT(glm::distance(both.faces[2].texture.levels[3].texels[0],
                          glm::vec4(grey * face_tint(2), 1.0f)),
            1e-6f);
}

// ---------------------------------------------------------------------------------------------
// JSON scenes

json minimal_document() {
  return json::parse(R"({
    "positions": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0]],
    "faces": [
      {"vertices": [0, 1, 2, 3], "texture": {"width": 16, "height": 8}},
      {"vertices": [1, 4, 5, 2],
       "texture": {"width": 4, "height": 4, "content": "constant", "color": [1, 0, 0]}}
    ],
    "camera": {"eye": [1, 0.5, 3], "target": [1, 0.5, 0]}
  })");
}

TEST(SceneJson, EveryExampleLoads) {
  size_t loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(examples_dir() + "/scenes")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    Scene scene;
    ASSERT_NO_THROW(scene = load_scene_file(entry.path().string()));
    EXPECT_FALSE(scene.faces.empty());
    EXPECT_NO_THROW(validate_scene(scene));
    EXPECT_NO_THROW(load_scene(entry.path().string(), {}));
    ++loaded;
  }
  EXPECT_GE(loaded, 4u);
}

void expect_same_scene(const Scene& actual, const Scene& expected) {
  EXPECT_EQ(actual.name, expected.name);
  ASSERT_EQ(actual.positions.size(), expected.positions.size());
  for (size_t i = 0; i < actual.positions.size(); ++i)
    EXPECT_LT(glm::distance(actual.positions[i], expected.positions[i]), 1e-6f) << "position " << i;
  ASSERT_EQ(actual.faces.size(), expected.faces.size());
  for (size_t f = 0; f < actual.faces.size(); ++f) {
    EXPECT_EQ(actual.faces[f].vertices, expected.faces[f].vertices) << "face " << f;
    ASSERT_EQ(level_sizes(actual.faces[f].texture), level_sizes(expected.faces[f].texture))
        << "face " << f;
    const auto& texels = actual.faces[f].texture.levels[0].texels;
    const auto& expected_texels = expected.faces[f].texture.levels[0].texels;
    for (size_t t = 0; t < texels.size(); ++t)
      ASSERT_LT(glm::distance(texels[t], expected_texels[t]), 1e-5f)
          << "face " << f << " texel " << t;
  }
  EXPECT_LT(glm::distance(actual.camera.eye, expected.camera.eye), 1e-5f);
  EXPECT_EQ(actual.camera.target, expected.camera.target);
  EXPECT_EQ(actual.camera.up, expected.camera.up);
  EXPECT_EQ(actual.camera.fov_y_degrees, expected.camera.fov_y_degrees);
  ASSERT_EQ(actual.orbit.has_value(), expected.orbit.has_value());
  if (actual.orbit) {
    EXPECT_EQ(actual.orbit->center, expected.orbit->center);
    EXPECT_EQ(actual.orbit->radius, expected.orbit->radius);
    EXPECT_EQ(actual.orbit->height, expected.orbit->height);
    EXPECT_EQ(actual.orbit->start_degrees, expected.orbit->start_degrees);
  }
  EXPECT_LT(glm::distance(actual.light.to_light, expected.light.to_light), 1e-6f);
  EXPECT_EQ(actual.light.color, expected.light.color);
  EXPECT_EQ(actual.light.ambient, expected.light.ambient);
  EXPECT_EQ(actual.background, expected.background);
}

TEST(SceneJson, ExplicitExamplesMatchTheirGenerators) {
  for (const std::string name : {"quad2", "cube"}) {
    SCOPED_TRACE(name);
    expect_same_scene(load_scene_file(examples_dir() + "/scenes/" + name + ".json"),
                      generate_scene(name, {}));
  }
}

TEST(SceneJson, GeneratorDocumentsUseTheirOptions) {
  const Scene from_json =
      parse_scene_json(json::parse(R"({"generator": "cube", "options": {"tint": true}})"));
  expect_same_scene(from_json,
                    generate_scene("cube", {.tint = true, .constant_color = std::nullopt}));
  const Scene constant = parse_scene_json(
      json::parse(R"({"generator": "quad2", "options": {"constant_color": [0.1, 0.2, 0.3]}})"));
  EXPECT_LT(glm::distance(constant.faces[1].texture.levels[0].texels[7],
                          glm::vec4(0.1f, 0.2f, 0.3f, 1.0f)),
            1e-6f);
}

TEST(SceneJson, DefaultsAndContent) {
  const Scene scene = parse_scene_json(minimal_document());
  EXPECT_EQ(scene.name, "scene");
  EXPECT_EQ(scene.camera.up, glm::vec3(0, 1, 0));
  EXPECT_EQ(scene.camera.fov_y_degrees, 45.0f);
  EXPECT_FALSE(scene.orbit.has_value());
  EXPECT_EQ(scene.light.ambient, Light{}.ambient);
  EXPECT_EQ(scene.background, Scene{}.background);
  // "surface" (the default) is surface_pattern at the texel's point; "constant" is the colour.
  const auto corners = scene.corners(scene.faces[0]);
  const glm::vec4 expected = surface_pattern(face_point(corners, 2.5f / 16.0f, 5.5f / 8.0f));
  EXPECT_LT(glm::distance(scene.faces[0].texture.levels[0].at(2, 5), expected), 1e-6f);
  for (const glm::vec4& texel : scene.faces[1].texture.levels[1].texels)
    EXPECT_EQ(texel, glm::vec4(1, 0, 0, 1));

  json tinted = minimal_document();
  tinted["faces"][0]["texture"]["color"] = {0.5, 1.0, 0.25};
  tinted["light"] = {{"to_light", {0, 3, 4}}, {"ambient", 0.5}};
  tinted["name"] = "tinted";
  const Scene with_color = parse_scene_json(tinted);
  EXPECT_EQ(with_color.name, "tinted");
  EXPECT_LT(glm::distance(with_color.faces[0].texture.levels[0].at(2, 5),
                          expected * glm::vec4(0.5f, 1.0f, 0.25f, 1.0f)),
            1e-6f);
  EXPECT_LT(glm::distance(with_color.light.to_light, glm::vec3(0, 0.6f, 0.8f)), 1e-6f)
      << "normalised";
  EXPECT_EQ(with_color.light.ambient, 0.5f);
}

// One edit of minimal_document(): the value at a JSON pointer replaced (or removed when
// replacement is null), and the field path the error must name.
struct BadDocument {
  const char* field;
  const char* pointer;
  const char* replacement;
};

TEST(SceneJson, RejectsBadDocumentsNamingTheField) {
  const BadDocument cases[] = {
      // missing, wrong type, unknown
      {"positions", "/positions", nullptr},
      {"faces", "/faces", nullptr},
      {"camera", "/camera", nullptr},
      {"faces", "/faces", R"([])"},
      {"faces", "/faces", R"("all of them")"},
      {"lights", "/lights", R"({})"},
      {"name", "/name", R"(5)"},
      {"scene", "", R"([1, 2])"},
      {"positions[1]", "/positions/1", R"([1, 0])"},
      {"positions[2][1]", "/positions/2/1", R"("1")"},
      {"faces[0]", "/faces/0", R"(7)"},
      {"faces[0].uv", "/faces/0/uv", R"([])"},
      {"faces[0].texture", "/faces/0/texture", nullptr},
      {"faces[0].texture.height", "/faces/0/texture/height", nullptr},
      {"faces[0].texture.width", "/faces/0/texture/width", R"(true)"},
      {"faces[0].texture.colour", "/faces/0/texture/colour", R"([1, 1, 1])"},
      {"camera.eye", "/camera/eye", nullptr},
      {"camera.eye[1]", "/camera/eye/1", R"("0.5")"},
      {"camera.target", "/camera/target", R"([1, 2, 3, 4])"},
      {"camera.fov_y_degrees", "/camera/fov_y_degrees", R"("45")"},
      {"camera.fov", "/camera/fov", R"(45)"},
      {"light", "/light", R"([0, 1, 0])"},
      {"orbit.center", "/orbit", R"({"radius": 3})"},
      // indices
      {"faces[0].vertices", "/faces/0/vertices", R"([0, 1, 2])"},
      {"faces[1].vertices[2]", "/faces/1/vertices/2", R"(6)"},
      {"faces[0].vertices[0]", "/faces/0/vertices/0", R"(-1)"},
      {"faces[0].vertices[3]", "/faces/0/vertices/3", R"("3")"},
      {"faces[0].vertices[1]", "/faces/0/vertices/1", R"(1.5)"},
      {"faces[0].vertices", "/faces/0/vertices", R"([0, 0, 0, 0])"},
      // values out of range
      {"faces[1].texture.width", "/faces/1/texture/width", R"(48)"},
      {"faces[0].texture.height", "/faces/0/texture/height", R"(8192)"},
      {"faces[0].texture.height", "/faces/0/texture/height", R"(0)"},
      {"faces[0].texture.width", "/faces/0/texture/width", R"(16.5)"},
      {"faces[0].texture.content", "/faces/0/texture/content", R"("checker")"},
      {"faces[1].texture.color[2]", "/faces/1/texture/color/2", R"(-0.5)"},
      {"camera.eye", "/camera/eye", R"([1, 0.5, 0])"},  // == target
      {"camera.eye[0]", "/camera/eye/0", R"(1e39)"},    // beyond float
      {"camera.fov_y_degrees", "/camera/fov_y_degrees", R"(0)"},
      {"camera.fov_y_degrees", "/camera/fov_y_degrees", R"(180)"},
      {"camera.up", "/camera/up", R"([0, 0, -2])"},  // along the view direction
      {"light.to_light", "/light", R"({"to_light": [0, 0, 0]})"},
      {"light.ambient", "/light", R"({"ambient": 2})"},
      {"orbit.radius", "/orbit", R"({"center": [0, 0, 0], "radius": -1})"},
      {"background[0]", "/background", R"([-1, 0, 0])"},
      // colours past kMaxColorMagnitude (1e9), which could overflow a render to NaN
      {"faces[1].texture.color[0]", "/faces/1/texture/color/0", R"(2e9)"},
      {"background[2]", "/background", R"([1, 1, 3e38])"},
      {"light.color[1]", "/light", R"({"color": [1, 1e10, 1]})"},
      {"options.constant_color[0]", "", R"({"generator": "quad2", "options": {"constant_color": [1e38, 1, 1]}})"},
      {"options.environment.constant[0]", "",
       R"({"generator": "envmap", "options": {"environment": {"constant": [3e38, 3e38, 3e38]}}})"},
      {"faces[0].vertices", "/positions/1", R"([3e38, -3e38, 0])"},  // the quad's area overflows
      // generator documents (any other field is unknown: the first, alphabetically, is named)
      {"generator", "", R"({"generator": "teapot"})"},
      {"generator", "", R"({"generator": 3})"},
      {"camera", "/generator", R"("cube")"},
      {"options.tint", "", R"({"generator": "cube", "options": {"tint": "yes"}})"},
      {"options.constant_color[1]", "",
       R"({"generator": "cube", "options": {"constant_color": [0, "x", 0]}})"},
      {"options.seed", "", R"({"generator": "cube", "options": {"seed": 1}})"},
  };
  ASSERT_NO_THROW(parse_scene_json(minimal_document()));
  for (const BadDocument& bad : cases) {
    json doc = minimal_document();
    const json::json_pointer pointer(bad.pointer);
    if (bad.replacement)
      doc[pointer] = json::parse(bad.replacement);
    else
      doc.at(pointer.parent_pointer()).erase(pointer.back());
    SCOPED_TRACE(doc.dump());
    const std::string message = expect_input_error([&] { parse_scene_json(doc); }, bad.field);
    EXPECT_EQ(message.rfind(std::string(bad.field) + ": ", 0), 0u) << message;
    EXPECT_GT(message.size(), std::string(bad.field).size() + 4) << "says what is wrong";
  }
  EXPECT_GE(std::size(cases), 15u);
}

TEST(SceneJson, RejectsScenesTooLargeToHold) {
  json doc = minimal_document();
  doc["faces"] = json::array();
  for (int f = 0; f < 8; ++f)
    doc["faces"].push_back(
        {{"vertices", {0, 1, 2, 3}}, {"texture", {{"width", 4096}, {"height", 4096}}}});
  // 2^26 texels in all is the limit: the fifth 4096x4096 texture passes it.
  const std::string message =
      expect_input_error([&] { parse_scene_json(doc); }, "faces[4].texture");
  EXPECT_NE(message.find("texels"), std::string::npos) << message;
}

class TemporaryFile {
 public:
  explicit TemporaryFile(const std::string& content) {
    path_ = (std::filesystem::temp_directory_path() / ("seamcl_test_" + std::to_string(::getpid()) +
                                                       "_" + std::to_string(counter_++) + ".json"))
                .string();
    std::ofstream(path_) << content;
  }
  ~TemporaryFile() { std::filesystem::remove(path_); }
  const std::string& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::string path_;
};

TEST(SceneJson, FileErrorsNameThePath) {
  const std::string missing = "/nonexistent/dir/scene.json";
  std::string message = expect_input_error([&] { load_scene_file(missing); }, "scene");
  EXPECT_NE(message.find(missing), std::string::npos) << message;

  const TemporaryFile bad_syntax(R"({"positions": [[0, 0, 0],})");
  message = expect_input_error([&] { load_scene_file(bad_syntax.path()); }, "scene");
  EXPECT_NE(message.find(bad_syntax.path()), std::string::npos) << message;
  EXPECT_NE(message.find("parse error"), std::string::npos) << message;

  json doc = minimal_document();
  doc["faces"][1]["texture"]["width"] = 3;
  const TemporaryFile bad_content(doc.dump());
  message =
      expect_input_error([&] { load_scene_file(bad_content.path()); }, "faces[1].texture.width");
  EXPECT_NE(message.find(bad_content.path()), std::string::npos) << message;

  // Past the bound the text is not parsed (sparse: the file reads as zeros); a file that fails
  // mid-read is an input error, not an I/O exception.
  {
    const TemporaryFile huge("{}");
    std::filesystem::resize_file(huge.path(), (std::uintmax_t{64} << 20) + 1);
    message = expect_input_error([&] { load_scene_file(huge.path()); }, "scene");
    EXPECT_NE(message.find("larger than 64 MiB"), std::string::npos) << message;
  }
  // What the JSON parser would let through unseen: a key given twice, bytes after a NUL.
  const TemporaryFile repeated(R"({"name": "a", "name": "b", "positions": []})");
  message = expect_input_error([&] { load_scene_file(repeated.path()); }, "scene");
  EXPECT_NE(message.find("key 'name' is given twice"), std::string::npos) << message;
  // A number of 100,000 digits, which the parser's message quotes whole: the message is cut.
  const TemporaryFile long_number("{\"name\": " + std::string(100000, '7') + "}");
  message = expect_input_error([&] { load_scene_file(long_number.path()); }, "scene");
  EXPECT_NE(message.find("not valid JSON"), std::string::npos) << message.substr(0, 200);
  EXPECT_LT(message.size(), 1200u);
  EXPECT_NE(message.find(" bytes cut] "), std::string::npos) << message.substr(500, 100);
  const TemporaryFile after_nul(minimal_document().dump() + std::string(1, '\0') + "{\"garbage\"");
  message = expect_input_error([&] { load_scene_file(after_nul.path()); }, "scene");
  EXPECT_NE(message.find("NUL byte"), std::string::npos) << message;
  message = expect_input_error([&] { load_scene_source("/proc/self/mem"); }, "scene");
  EXPECT_NE(message.find("/proc/self/mem"), std::string::npos) << message;
  message = expect_input_error([&] { load_scene_file("/proc/self/mem"); }, "scene");
  EXPECT_NE(message.find("/proc/self/mem"), std::string::npos) << message;

  const TemporaryFile good(minimal_document().dump());
  EXPECT_EQ(load_scene_file(good.path()).name, std::filesystem::path(good.path()).stem().string())
      << "an unnamed scene is named after its file";
}

// A long input error keeps both ends, cut between whole UTF-8 characters.
TEST(SceneJson, LongInputErrorsKeepBothEndsAndWholeCharacters) {
  for (const size_t lead : {0, 1}) {  // the two-byte characters start on either side of the cut
    const std::string body = std::string(lead, 'a') + [] {
      std::string text;
      for (int i = 0; i < 3000; ++i) text += "\xC3\xA9";  // U+00E9, two bytes
      return text;
    }();
    const std::string message = "'" + body + "' ends here";
    const std::string what = InputError("field", message).what();
    EXPECT_LT(what.size(), 1100u);
    // Wrapped again with a prefix, as callers add a path or a field: not cut a second time.
    const std::string again = InputError("outer", "some/path.json: " + what).what();
    EXPECT_EQ(again, "outer: some/path.json: " + what);
    EXPECT_EQ(what.rfind("field: '", 0), 0u);
    EXPECT_NE(what.find("' ends here"), std::string::npos) << "the end is kept";
    EXPECT_NE(what.find(" bytes cut] "), std::string::npos);
    // Every byte after the prefix's quote and before the marker is a whole character.
    const size_t marker = what.find(" [");
    const std::string head = what.substr(8 + lead, marker - 8 - lead);
    EXPECT_EQ(head.size() % 2, 0u) << "a character split at the first cut";
    const size_t tail_start = what.find("cut] ") + 5;
    const std::string tail = what.substr(tail_start, what.find("' ends here") - tail_start);
    EXPECT_EQ(tail.size() % 2, 0u) << "a character split at the second cut";
    EXPECT_NE(static_cast<unsigned char>(tail.front()) & 0xC0u, 0x80u);
  }
  EXPECT_EQ(std::string(InputError("f", std::string(2048, 'x')).what()), "f: " + std::string(2048, 'x'))
      << "up to the bound, the message is whole";
  // Invalid text (only continuation bytes) moves no cut past a character's length.
  const std::string invalid = InputError("f", "'" + std::string(3000, '\xBF') + "' ends here").what();
  EXPECT_NE(invalid.find("' ends here"), std::string::npos);
  EXPECT_GT(invalid.find(" ["), 500u) << "the head is kept";
}

TEST(SceneJson, LoadSceneTakesNamesOrPaths) {
  EXPECT_EQ(load_scene("cube", {}).name, "cube");
  std::string message = expect_input_error([] { load_scene("teapot", {}); }, "scene");
  EXPECT_NE(message.find("known: paper, quad2, plane, cube"), std::string::npos) << message;
  expect_input_error([] { load_scene("missing.json", {}); }, "scene");

  // Options apply on top of a file's scene: tint on an explicit scene ...
  const std::string quad2_path = examples_dir() + "/scenes/quad2.json";
  const Scene plain = load_scene(quad2_path, {});
  const Scene tinted = load_scene(quad2_path, {.tint = true, .constant_color = std::nullopt});
  EXPECT_LT(
      glm::distance(tinted.faces[1].texture.levels[2].texels[3],
                    plain.faces[1].texture.levels[2].texels[3] * glm::vec4(face_tint(1), 1.0f)),
      1e-6f);
  // ... and a constant colour over a generator file's own options (which tint).
  const glm::vec3 grey(0.4f);
  const Scene paper =
      load_scene(examples_dir() + "/scenes/paper.json", {.tint = false, .constant_color = grey});
  EXPECT_EQ(paper.faces.size(), kPaperTorusFaces + kPaperGroundFaces);
  EXPECT_LT(glm::distance(paper.faces[9].texture.levels[0].texels[0],
                          glm::vec4(grey * face_tint(9), 1.0f)),
            1e-6f);
}

}  // namespace
}  // namespace seamcl
