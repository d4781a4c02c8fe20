// The shade stage's environment branch: reflective faces of the envmap scene and its skybox,
// kernel against twin for every cube method, a constant environment rendered exactly, and the
// cube_method option.
#include <gtest/gtest.h>

#include <cmath>

#include <seamcl/core/input_error.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/cube_map.h>
#include <seamcl/scene/envmap_scene.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>
#include "test_support.h"
#include "pipeline/stages/shade_resolve_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;

namespace {

Scene small_envmap(std::optional<glm::vec3> constant = std::nullopt) {
  GeneratorOptions options;
  options.constant_color = constant;
  Scene scene = generate_scene("envmap", options);
  scene.environment->cube_size = 16;
  return scene;
}

RenderOptions small_render(CubeMethod method, int msaa) {
  RenderOptions options;
  options.scene = "envmap";
  options.width = 56;
  options.height = 40;
  options.msaa = msaa;
  options.cube_method = method;
  return options;
}

}  // namespace

TEST(EnvmapScene, IsReflectiveWithOutwardUnitNormals) {
  const Scene scene = small_envmap();
  ASSERT_TRUE(scene.environment.has_value());
  ASSERT_EQ(scene.normals.size(), scene.positions.size());
  int mirrors = 0, glossy = 0;
  for (const Face& face : scene.faces) {
    ASSERT_GE(face.roughness, 0.0f);
    (face.roughness == 0.0f ? mirrors : glossy)++;
    glm::vec3 average(0.0f);
    for (uint32_t v : face.vertices) {
      EXPECT_NEAR(glm::length(scene.normals[v]), 1.0f, 1e-5f);
      average += scene.normals[v];
    }
    // Wound counter-clockwise seen from the side the shading normals face.
    EXPECT_GT(glm::dot(scene.face_normal(face), average), 0.0f);
  }
  EXPECT_GT(mirrors, 0);
  EXPECT_GT(glossy, 0);
}

TEST(EnvmapScene, ShadeKernelMatchesTwinForEveryCubeMethod) {
  const Scene scene = small_envmap();
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  for (const std::string& name : cube_method_names()) {
    for (Filter filter : {Filter::Trilinear, Filter::Aniso}) {
      RenderOptions options = small_render(*parse_cube_method(name), 2);
      options.filter = filter;
      const RenderResult result = renderer.render(scene.camera, options);
      const ResolveReference twin =
          shade_resolve_reference(renderer.packed_scene(), renderer.last_frame_params(), renderer.read_setups(),
                                  renderer.read_sample_triangles(), &renderer.cube_texels());
      ASSERT_EQ(twin.pixels.size(), result.pixels.size());
      float worst = 0.0f;
      for (size_t i = 0; i < twin.pixels.size(); ++i) worst = std::max(worst, glm::length(twin.pixels[i] - result.pixels[i]));
      EXPECT_LT(worst, 1e-4f) << name << " " << to_string(filter);
      EXPECT_EQ(twin.fragments, result.stats.fragments) << name;
    }
  }
}

TEST(EnvmapScene, ConstantEnvironmentRendersExactlyWithEveryCubeMethod) {
  const glm::vec3 c(0.25f, 0.5f, 0.75f);
  const Scene scene = small_envmap(c);
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  for (const std::string& name : cube_method_names()) {
    const RenderResult result = renderer.render(scene.camera, small_render(*parse_cube_method(name), 4));
    float worst = 0.0f;
    for (const glm::vec4& p : result.pixels) worst = std::max(worst, glm::length(glm::vec3(p) - c));
    EXPECT_LT(worst, 1e-6f) << name;
  }
}

TEST(EnvmapScene, SkyboxShowsTheEnvironmentAndMethodsDifferOnlyNearEdges) {
  const Scene scene = small_envmap();
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const RenderResult seamless = renderer.render(scene.camera, small_render(CubeMethod::Seamless, 1));
  const RenderResult clamp = renderer.render(scene.camera, small_render(CubeMethod::Clamp, 1));
  size_t same = 0;
  for (size_t i = 0; i < seamless.pixels.size(); ++i) {
    EXPECT_GT(seamless.pixels[i].r + seamless.pixels[i].g + seamless.pixels[i].b, 0.05f) << "pixel " << i;
    same += glm::length(seamless.pixels[i] - clamp.pixels[i]) < 1e-6f;
  }
  // Away from the cube's edges both read the same texels.
  EXPECT_GT(same, seamless.pixels.size() / 2);
  EXPECT_LT(same, seamless.pixels.size());
}

TEST(EnvmapScene, MemoryEstimateCoversTheBorderedCube) {
  const Scene scene = small_envmap();
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  size_t estimated[2], used[2];
  int k = 0;
  for (CubeMethod method : {CubeMethod::Clamp, CubeMethod::Border}) {
    const RenderOptions options = small_render(method, 1);
    renderer.render(scene.camera, options);
    used[k] = renderer.cube_texels().size() * sizeof(float);
    estimated[k] = render_memory(scene, options).environment;
    // The plan is never below what the render holds.
    EXPECT_GE(estimated[k], used[k]) << to_string(method);
    ++k;
  }
  // The border's price, texel for texel: every level one texel wider on each side.
  EXPECT_EQ(used[0], cube_texel_count(16, false) * 16);
  EXPECT_EQ(used[1], cube_texel_count(16, true) * 16);
  EXPECT_GE(estimated[1] - estimated[0], used[1] - used[0]);
}

TEST(CubeMethodOption, ParsesItsNamesAndRefusesOthers) {
  for (const std::string& name : cube_method_names()) {
    const RenderOptions o = parse_render_options({{"cube_method", name}});
    EXPECT_EQ(to_string(o.cube_method), name);
    EXPECT_EQ(to_json(o)["cube_method"], name);
  }
  EXPECT_EQ(cube_method_names().size(), 10u);
  EXPECT_EQ(RenderOptions{}.cube_method, CubeMethod::Seamless);
  try {
    parse_render_options({{"cube_method", "seamless"}});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "cube_method");
    EXPECT_NE(std::string(e.what()).find("cube-seamless"), std::string::npos);
  }
}

TEST(EnvmapSceneJson, ReadsEnvironmentNormalsAndRoughness) {
  const nlohmann::json doc = {
      {"positions", {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}},
      {"normals", {{0, 0, 2}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}}},
      {"faces", {{{"vertices", {0, 1, 2, 3}}, {"roughness", 0.25}}}},
      {"camera", {{"eye", {0, 0, 3}}, {"target", {0, 0, 0}}}},
      {"environment", {{"cube_size", 8}, {"sun_direction", {0, 0, 1}}, {"skybox", false}}}};
  const Scene scene = parse_scene_json(doc);
  ASSERT_TRUE(scene.environment.has_value());
  EXPECT_EQ(scene.environment->cube_size, 8);
  EXPECT_FALSE(scene.environment->skybox);
  EXPECT_EQ(scene.faces[0].roughness, 0.25f);
  EXPECT_EQ(scene.faces[0].texture.width(), 1);
  EXPECT_NEAR(glm::length(scene.normals[0] - glm::vec3(0, 0, 1)), 0.0f, 1e-6f);

  const Scene own = load_scene(SEAMCL_EXAMPLES_DIR "/scenes/envmap_own.json", {});
  EXPECT_EQ(own.environment->cube_size, 32);
  EXPECT_EQ(own.faces.front().roughness, 0.0f);

  auto field_of = [](const nlohmann::json& bad) {
    try {
      parse_scene_json(bad);
    } catch (const InputError& e) {
      return e.field();
    }
    return std::string("no error");
  };
  nlohmann::json no_normals = doc;
  no_normals.erase("normals");
  EXPECT_EQ(field_of(no_normals), "normals");
  nlohmann::json bad_size = doc;
  bad_size["environment"]["cube_size"] = 12;
  EXPECT_EQ(field_of(bad_size), "environment.cube_size");
  nlohmann::json no_environment = doc;
  no_environment.erase("environment");
  EXPECT_EQ(field_of(no_environment), "faces[0].roughness");
  nlohmann::json bad_roughness = {{"generator", "envmap"}, {"options", {{"roughness", {0, -1, 0}}}}};
  EXPECT_EQ(field_of(bad_roughness), "options.roughness[1]");
}
