// The built-in scenes as regimes (host/scene/scene_generators.h): each generates a valid scene
// whose textures are its albedo function baked at the texel centres; the detail content has
// texel-scale features; the mixed mesh is closed, with valences 3, 4 and 5 and sizes 1 to 256.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include <seamcl/core/input_error.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>

using namespace seamcl;

namespace {

// Mean over level 0 of |texel - its right neighbour| (max channel): how fast the content changes
// per texel.
float mean_texel_step(const Scene& scene) {
  double sum = 0;
  size_t n = 0;
  for (const Face& face : scene.faces) {
    const TextureLevel& level = face.texture.levels.front();
    for (int j = 0; j < level.height; ++j)
      for (int i = 0; i + 1 < level.width; ++i) {
        const glm::vec4 d = glm::abs(level.at(i + 1, j) - level.at(i, j));
        sum += std::max({d.r, d.g, d.b});
        ++n;
      }
  }
  return n == 0 ? 0.0f : static_cast<float>(sum / static_cast<double>(n));
}

}  // namespace

TEST(Regimes, EveryGeneratorMakesAValidSceneBakedFromItsAlbedo) {
  std::set<std::string> names;
  for (const GeneratorInfo& info : scene_generators()) {
    names.insert(info.name);
    const Scene scene = generate_scene(info.name, {});
    EXPECT_NO_THROW(validate_scene(scene)) << info.name;
    ASSERT_TRUE(scene.albedo) << info.name;
    EXPECT_EQ(scene.name, info.name);
    // Level 0 is the albedo at each texel centre's surface point (a few texels of a few faces).
    for (size_t f = 0; f < scene.faces.size(); f += std::max<size_t>(1, scene.faces.size() / 7)) {
      const TextureLevel& level = scene.faces[f].texture.levels.front();
      for (auto [i, j] : {std::pair{0, 0}, std::pair{level.width - 1, level.height / 2}}) {
        const float u = (static_cast<float>(i) + 0.5f) / static_cast<float>(level.width);
        const float v = (static_cast<float>(j) + 0.5f) / static_cast<float>(level.height);
        const glm::vec4 want = scene.albedo(f, face_point(scene.corners(scene.faces[f]), u, v));
        EXPECT_LT(glm::length(level.at(i, j) - want), 1e-6f) << info.name << " face " << f;
      }
    }
  }
  for (const char* regime : {"paper", "plane", "closeup-seam", "closeup-corner", "mixed"})
    EXPECT_TRUE(names.count(regime)) << regime;
}

TEST(Regimes, DetailContentHasTexelScaleFeatures) {
  GeneratorOptions detail;
  detail.content = TextureContent::Detail;
  GeneratorOptions surface;
  surface.content = TextureContent::Surface;
  // Features of 2.5 to 4 texels change a channel by a large part of its range every texel or two,
  // where the paper scene's smooth content changes slowly in its texels.
  const Scene fine = generate_scene("paper", detail);
  const Scene smooth = generate_scene("paper", surface);
  EXPECT_GT(mean_texel_step(fine), 0.04f);
  EXPECT_GT(mean_texel_step(fine), 3.0f * mean_texel_step(smooth));
  for (const char* name : {"plane", "closeup-seam"}) EXPECT_GT(mean_texel_step(generate_scene(name, detail)), 0.08f) << name;
  // The detail is in texels of the scene's median face (of an even count, the upper middle one:
  // quad2's 32x16 face).
  EXPECT_NEAR(median_texel_spacing(generate_scene("quad2", detail)), std::sqrt(1.0f / 512.0f), 1e-6f);
  // The close-ups have it by default; the paper scene keeps its smooth content.
  EXPECT_EQ(generate_scene("closeup-seam", {}).faces[0].texture.levels[0].texels,
            generate_scene("closeup-seam", detail).faces[0].texture.levels[0].texels);
  EXPECT_EQ(scene_generators().front().content, TextureContent::Surface);
}

TEST(Regimes, ContentIsAGeneratorOptionOfSceneFiles) {
  const Scene plain = parse_scene_json(nlohmann::json::parse(R"({"generator": "quad2"})"));
  const Scene detail = parse_scene_json(nlohmann::json::parse(R"({"generator": "quad2", "options": {"content": "detail"}})"));
  EXPECT_NE(plain.faces[0].texture.levels[0].texels, detail.faces[0].texture.levels[0].texels);
  GeneratorOptions detail_options;
  detail_options.content = TextureContent::Detail;
  EXPECT_EQ(detail.faces[0].texture.levels[0].texels, generate_scene("quad2", detail_options).faces[0].texture.levels[0].texels);
  try {
    parse_scene_json(nlohmann::json::parse(R"({"generator": "quad2", "options": {"content": "noise"}})"));
    FAIL() << "unknown content accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "options.content");
    EXPECT_NE(std::string(e.what()).find("surface, detail"), std::string::npos) << e.what();
  }
  for (const std::string& name : texture_content_names()) EXPECT_EQ(to_string(*parse_texture_content(name)), name);
}

TEST(Regimes, MixedIsAClosedMeshWithValences345AndSizes1To256) {
  const Scene scene = generate_scene("mixed", {});
  EXPECT_EQ(scene.faces.size(), 30u);
  std::map<std::pair<uint32_t, uint32_t>, int> edges;  // directed edge -> count
  std::map<uint32_t, int> valence;
  std::set<std::pair<int, int>> sizes;
  for (const Face& face : scene.faces) {
    for (int k = 0; k < 4; ++k) {
      ++edges[{face.vertices[k], face.vertices[(k + 1) % 4]}];
      ++valence[face.vertices[k]];
    }
    sizes.insert({face.texture.width(), face.texture.height()});
  }
  // Closed and consistently oriented: every directed edge once, its reverse once.
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1u) << edge.first << "-" << edge.second << " is a boundary";
  }
  std::set<int> valences;
  for (const auto& [vertex, n] : valence) valences.insert(n);
  EXPECT_EQ(valences, (std::set<int>{3, 4, 5}));
  EXPECT_TRUE(sizes.count({1, 1}));
  EXPECT_TRUE(sizes.count({256, 256}));
  EXPECT_GT(sizes.size(), 10u);
  // Neighbours meet rotated: across a shared edge, the edge's index in each face differs by
  // something other than 2 (which is what unrotated neighbours have) for some pairs.
  std::map<std::pair<uint32_t, uint32_t>, int> edge_index;
  for (const Face& face : scene.faces)
    for (int k = 0; k < 4; ++k) edge_index[{face.vertices[k], face.vertices[(k + 1) % 4]}] = k;
  std::set<int> turns;
  for (const auto& [edge, k] : edge_index) turns.insert((edge_index.at({edge.second, edge.first}) - k + 4) % 4);
  EXPECT_EQ(turns, (std::set<int>{0, 1, 2, 3}));
}

TEST(Regimes, SurfacePatternHasNoDarkLines) {
  // The viewer's texture: black's darkened edges are dark lines, so the pattern has none: no
  // point of it is near black (the old stripes went down to 0.05 in every channel).
  float darkest = 1.0f;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 200; ++j) {
      const glm::vec4 c = surface_pattern(glm::vec3(i * 0.013f, j * 0.011f, (i + j) * 0.007f));
      darkest = std::min(darkest, std::max({c.r, c.g, c.b}));
    }
  EXPECT_GT(darkest, 0.2f);
}
