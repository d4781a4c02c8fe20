// Shading and resolve on scenes whose every face holds one constant colour: each sample counts
// the lit colour of the face that won it (colour x light x (ambient + (1 - ambient) max(0, n.l)),
// the colour after the textures' RGBA8 sRGB round trip) or the background, and a pixel is their
// mean. So a pixel inside a face shows exactly the lit colour, a pixel on an edge between faces
// of different normals the coverage-weighted mix, and a pixel no triangle touches the background.
// The fragment counter is held to the count the winners buffer implies. Expected values come from
// the winners buffer, so these tests hold shading and resolve, not coverage (test_watertight.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include "core/srgb.h"
#include "test_support.h"
#include "pipeline/stages/texture_sample_twin.h"

using namespace seamcl;

namespace {

constexpr uint32_t kSlotsPerFace = 2 * SEAMCL_CLIP_SLOTS;
constexpr float kTolerance = 1e-5f;

struct Counts {
  size_t uniform = 0;     // every sample covered, all by faces of one normal
  size_t mixed = 0;       // every sample covered, faces of different normals
  size_t partial = 0;     // some samples covered, some background
  size_t background = 0;  // no sample covered
};

// Renders `scene` (all faces painted `color`) at the given options and checks every pixel.
Counts check_constant_scene(Renderer& renderer, const Scene& scene, glm::vec3 color, int width, int height,
                            int msaa, ShadingMode shading) {
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.msaa = msaa;
  options.shading = shading;
  const RenderResult result = renderer.render(scene.camera, options);
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  EXPECT_EQ(result.pixels.size(), static_cast<size_t>(width) * height);
  EXPECT_EQ(winners.size(), static_cast<size_t>(width) * height * msaa);

  // The lit colour of each face.
  const glm::vec3 albedo = glm::vec3(decode_srgb8(encode_srgb8(glm::vec4(color, 1.0f))));
  const glm::vec3 l = glm::normalize(scene.light.to_light);
  std::vector<glm::vec3> normals, lit;
  for (const Face& face : scene.faces) {
    const glm::vec3 n = scene.face_normal(face);
    normals.push_back(n);
    const float lighting = scene.light.ambient + (1.0f - scene.light.ambient) * std::max(0.0f, glm::dot(n, l));
    lit.push_back(albedo * scene.light.color * lighting);
  }

  Counts counts;
  size_t expected_fragments = 0, bad_pixels = 0, nan_pixels = 0;
  std::string first_bad;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t pixel = static_cast<size_t>(y) * width + x;
      const uint32_t* ids = winners.data() + pixel * msaa;
      glm::dvec3 sum(0.0);
      int covered = 0;
      bool one_normal = true;
      uint32_t first_face = SEAMCL_NO_TRIANGLE;
      std::set<uint32_t> slots;
      for (int s = 0; s < msaa; ++s) {
        if (ids[s] == SEAMCL_NO_TRIANGLE) {
          sum += glm::dvec3(scene.background);
          continue;
        }
        const uint32_t face = ids[s] / kSlotsPerFace;
        if (face >= scene.faces.size()) {
          ADD_FAILURE() << "winner slot " << ids[s] << " out of range at pixel (" << x << ", " << y << ")";
          return counts;
        }
        ++covered;
        slots.insert(ids[s]);
        if (first_face == SEAMCL_NO_TRIANGLE) first_face = face;
        one_normal = one_normal && normals[face] == normals[first_face];
        sum += glm::dvec3(lit[face]);
      }
      expected_fragments += shading == ShadingMode::Sample ? static_cast<size_t>(covered) : slots.size();
      const glm::vec4 got = result.pixels[pixel];
      const bool finite = std::isfinite(got.x) && std::isfinite(got.y) && std::isfinite(got.z) && std::isfinite(got.w);
      nan_pixels += !finite;

      bool ok;
      std::string kind;
      if (covered == 0) {
        ++counts.background;
        kind = "background";
        ok = glm::vec3(got) == scene.background;
      } else {
        const glm::vec3 expected = glm::vec3(sum / static_cast<double>(msaa));
        ok = finite && glm::all(glm::lessThanEqual(glm::abs(glm::vec3(got) - expected), glm::vec3(kTolerance)));
        if (covered < msaa) {
          ++counts.partial;
          kind = "partly covered";
        } else if (one_normal) {
          ++counts.uniform;
          kind = "covered by faces of one normal";
          // The plain statement: exactly the lit colour of that face.
          ok = ok && glm::all(glm::lessThanEqual(glm::abs(glm::vec3(got) - lit[first_face]),
                                                 glm::vec3(kTolerance)));
        } else {
          ++counts.mixed;
          kind = "covered by faces of different normals";
        }
        if (!ok) {
          char text[160];
          std::snprintf(text, sizeof text, " expected (%.7f, %.7f, %.7f)", expected.x, expected.y, expected.z);
          kind += text;
        }
      }
      ok = ok && got.w == 1.0f;
      if (!ok && bad_pixels++ < 4) {
        char text[160];
        std::snprintf(text, sizeof text, "\n  pixel (%d, %d), %d of %d samples covered, %zu triangles: got (%.7f, %.7f, %.7f, %.7f), ",
                      x, y, covered, msaa, slots.size(), got.x, got.y, got.z, got.w);
        first_bad += text + kind;
      }
    }
  EXPECT_EQ(bad_pixels, 0u) << first_bad;
  EXPECT_EQ(nan_pixels, 0u);
  EXPECT_EQ(result.stats.fragments, expected_fragments);
  return counts;
}

struct SceneCase {
  std::string name;
  int width, height;
  bool has_edges_between_normals;  // some pixels mix faces of different normals
  bool has_background;
};

void check_generator(const SceneCase& c) {
  const glm::vec3 color(0.7f, 0.45f, 0.2f);
  GeneratorOptions generator_options;
  generator_options.constant_color = color;
  const Scene scene = generate_scene(c.name, generator_options);
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  for (const int msaa : {1, 4, 16})
    for (const ShadingMode shading : {ShadingMode::Pixel, ShadingMode::Centroid, ShadingMode::Sample}) {
      SCOPED_TRACE(c.name + ", msaa " + std::to_string(msaa) + ", shading " + to_string(shading));
      const Counts counts = check_constant_scene(renderer, scene, color, c.width, c.height, msaa, shading);
      EXPECT_GT(counts.uniform, static_cast<size_t>(c.width) * c.height / 10);
      if (c.has_background) {
        EXPECT_GT(counts.background, 0u);
      }
      if (msaa > 1) {
        EXPECT_GT(counts.partial + counts.mixed, 0u);
      }
      if (c.has_edges_between_normals && msaa > 1) {
        EXPECT_GT(counts.mixed, 0u);
      }
      if (!c.has_edges_between_normals) {
        EXPECT_EQ(counts.mixed, 0u);
      }
    }
}

}  // namespace

TEST(Shading, ConstantQuad2IsLitColour) { check_generator({"quad2", 64, 64, false, true}); }

TEST(Shading, ConstantPlaneIsLitColour) { check_generator({"plane", 96, 72, false, true}); }

TEST(Shading, ConstantCubeIsLitColour) { check_generator({"cube", 64, 64, true, true}); }

TEST(Shading, ConstantPaperIsLitColour) { check_generator({"paper", 72, 81, true, true}); }

TEST(Shading, LightColourAndAmbientScale) {
  // A coloured light and another ambient on the cube: the formula holds channel by channel.
  const glm::vec3 color(0.3f, 0.8f, 0.55f);
  GeneratorOptions generator_options;
  generator_options.constant_color = color;
  Scene scene = generate_scene("cube", generator_options);
  scene.light.color = glm::vec3(0.9f, 0.6f, 1.3f);
  scene.light.ambient = 0.1f;
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  // (Not 8 samples: there the default background picks up rounding, which
  // BackgroundIsExactAtEverySampleCount reports on its own.)
  for (const int msaa : {1, 4}) {
    SCOPED_TRACE("msaa " + std::to_string(msaa));
    const Counts counts = check_constant_scene(renderer, scene, color, 48, 40, msaa, ShadingMode::Sample);
    EXPECT_GT(counts.uniform, 0u);
    EXPECT_GT(counts.background, 0u);
  }
}

TEST(Shading, BackgroundIsExactAtEverySampleCount) {
  // A pixel no triangle touches is the scene's background, bit for bit, whatever the background
  // and the sample count (the mean of equal values must not pick up rounding).
  GeneratorOptions generator_options;
  generator_options.constant_color = glm::vec3(0.5f);
  Scene scene = generate_scene("quad2", generator_options);
  Renderer renderer(seamcl_tests::shared_runtime());
  for (const glm::vec3 background : {glm::vec3(0.02f, 0.02f, 0.03f), glm::vec3(0.2f, 0.1f, 0.05f),
                                     glm::vec3(0.7f, 0.3f, 0.9f), glm::vec3(1.0f / 3.0f, 0.123456f, 0.0f)}) {
    scene.background = background;
    renderer.load_scene(scene);
    for (const int msaa : {1, 2, 4, 8, 16}) {
      RenderOptions options;
      options.width = 32;
      options.height = 32;
      options.msaa = msaa;
      const RenderResult result = renderer.render(scene.camera, options);
      const std::vector<uint32_t> winners = renderer.read_sample_triangles();
      size_t background_pixels = 0, wrong = 0;
      std::string first;
      for (size_t pixel = 0; pixel < result.pixels.size(); ++pixel) {
        bool untouched = true;
        for (int s = 0; s < msaa; ++s) untouched = untouched && winners[pixel * msaa + s] == SEAMCL_NO_TRIANGLE;
        if (!untouched) continue;
        ++background_pixels;
        const glm::vec3 got(result.pixels[pixel]);
        if (got != background && wrong++ == 0) {
          char text[200];
          std::snprintf(text, sizeof text, "pixel %zu: got (%.9g, %.9g, %.9g), background (%.9g, %.9g, %.9g)", pixel,
                        got.x, got.y, got.z, background.x, background.y, background.z);
          first = text;
        }
      }
      EXPECT_GT(background_pixels, 0u);
      EXPECT_EQ(wrong, 0u) << "msaa " << msaa << ": " << wrong << " of " << background_pixels
                           << " background pixels differ, first " << first;
    }
  }
}

// Colour values as large as a scene may hold them (kMaxColorMagnitude: textures, the light, the
// background, a constant environment) render without NaN or infinity with the default settings
// (zero_coverage clamp) under the seam methods and filters, at 1x and 4x: 1e9 * 1e9 stays far from a float's
// range, where a light of 3e38 on such a texture once put NaN (infinity times a zero n.l) in the
// image.
TEST(Shading, ColoursAtTheirBoundRenderFinite) {
  const glm::vec3 largest(kMaxColorMagnitude);
  GeneratorOptions generator_options;
  generator_options.constant_color = largest;
  for (const char* name : {"mixed", "envmap"}) {
    Scene scene = generate_scene(name, generator_options);
    scene.light.color = largest;
    scene.background = largest;
    ASSERT_NO_THROW(validate_scene(scene)) << name;
    if (std::string(name) == "envmap") {
      ASSERT_TRUE(scene.environment && scene.environment->constant) << "envmap's environment is the constant colour";
    }
    Renderer renderer(seamcl_tests::shared_runtime());
    renderer.load_scene(scene, TexelFormat::Rgba32f);
    // One filter per method (each pair a program variant to build): the renormalising methods,
    // the one with bands and a plain one.
    for (const auto& [method, filter] : {std::pair{Method::Discard, Filter::Aniso}, std::pair{Method::Traverse, Filter::Ewa},
                                         std::pair{Method::Guardband, Filter::Aniso}, std::pair{Method::Clamp, Filter::Trilinear}}) {
      {
        for (const int msaa : {1, 4}) {
          RenderOptions options;
          options.method = method;
          options.filter = filter;
          options.msaa = msaa;
          options.texels = TexelFormat::Rgba32f;
          options.width = 48;
          options.height = 40;
          SCOPED_TRACE(std::string(name) + " " + to_string(method) + " " + to_string(filter) + " " + std::to_string(msaa) + "x");
          const RenderResult result = renderer.render(scene.camera, options);
          size_t nonfinite = 0;
          float brightest = 0.0f;
          for (const glm::vec4& p : result.pixels) {
            nonfinite += !(std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b));
            brightest = std::max({brightest, p.r, p.g, p.b});
          }
          EXPECT_EQ(nonfinite, 0u);
          EXPECT_GT(brightest, 1e8f);  // the large values reached the image
        }
      }
    }
  }
}
