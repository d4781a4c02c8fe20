// Every seam method is a function of the surface, not of how its faces are written down: turning
// a face's vertex list (rotating it, or mirroring it) with its texture turned to match changes no
// lookup, on that face or on its neighbours, beyond float rounding (1e-5), through valence 3, 4
// and 5 vertices and mesh boundaries, at neighbours of any resolution. (Held on lookups rather
// than renders: a turned quad is split along its other diagonal, and the raster's interpolation
// then rounds differently for every method alike; a mirrored one faces the other way.) And on closed meshes
// whose faces all hold one colour at sizes from 1x1 to 256x256 side by side, every method but
// black returns that colour exactly, corners included; black darkens, never brightens.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/pipeline/texture_lookups.h>
#include "core/srgb.h"
#include "pipeline/adjacency.h"
#include "lit_constant.h"
#include "test_meshes.h"
#include "test_support.h"
#include "pipeline/stages/texture_sample_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

constexpr int kBand = 4;

std::vector<Method> all_methods() {
  std::vector<Method> out;
  for (const std::string& name : method_names()) out.push_back(*parse_method(name));
  return out;
}

// The cube with one side left out: boundary edges, and boundary vertices at its rim.
Scene open_box() {
  Scene scene = seamcl_tests::subdivided_cube(2);
  scene.name = "open_box";
  scene.faces.erase(scene.faces.begin() + 4, scene.faces.begin() + 8);  // the second side, x = -1
  return scene;
}

// Faces that share a vertex with `face` (the ones whose lookups may read it).
std::set<uint32_t> faces_around(const Scene& scene, uint32_t face) {
  std::set<uint32_t> out;
  for (size_t g = 0; g < scene.faces.size(); ++g) {
    for (uint32_t a : scene.faces[g].vertices) {
      for (uint32_t b : scene.faces[face].vertices) {
        if (a == b) out.insert(static_cast<uint32_t>(g));
      }
    }
  }
  return out;
}

struct TurnCase {
  std::string mesh;
  Scene scene;
  std::vector<uint32_t> faces;  // faces to turn, one at a time
};

std::vector<TurnCase> turn_cases() {
  std::vector<TurnCase> cases;
  // Face 0 of the cube touches a valence-3 corner and valence-4 vertices.
  cases.push_back({"subdivided_cube", seamcl_tests::subdivided_cube(2), {0, 13}});
  // Faces 0 and 12 of the prism: a cap quad (valence 5 at its centre) and a side (valence 3).
  cases.push_back({"split_pentagonal_prism", seamcl_tests::split_pentagonal_prism(), {0, 12}});
  // Face 4 of the open box lies at its rim: boundary edges and boundary vertices.
  cases.push_back({"open_box", open_box(), {4, 0}});
  // Smooth content, different on every face: float rounding of a probe's position (1e-7 of a
  // face) then moves a result by far less than 1e-5, while a texel out of place moves it by more.
  const std::vector<glm::ivec2>& sizes = seamcl_tests::mixed_texture_sizes();
  auto smooth = [&](size_t face, int i, int j) {
    const glm::ivec2 size = sizes[face % sizes.size()];
    const float u = (static_cast<float>(i) + 0.5f) / static_cast<float>(size.x);
    const float v = (static_cast<float>(j) + 0.5f) / static_cast<float>(size.y);
    const float phase = 0.37f * static_cast<float>(face);
    return glm::vec4(0.5f + 0.3f * std::sin(6.2831853f * (u + phase)) * std::cos(3.1415927f * v),
                     0.5f + 0.3f * std::cos(6.2831853f * (0.7f * v - phase)), 0.5f + 0.2f * std::sin(9.0f * u * v + phase),
                     1.0f);
  };
  for (TurnCase& c : cases) seamcl_tests::set_textures(c.scene, sizes, smooth);
  return cases;
}

// Lookups over the face and a margin past its edges, footprints from a fraction of a texel to
// most of a face, on `face` and on every face around it.
std::vector<Lookup> lookups_around(const Scene& scene, uint32_t face, std::mt19937& rng) {
  std::vector<Lookup> out;
  for (uint32_t g : faces_around(scene, face)) {
    for (int i = 0; i < 300; ++i) {
      Lookup l;
      l.face = g;
      // On a grid of 1/4096: the turned face's coordinates (1 - v and the like) are then exact,
      // and what is left to differ is the order of float sums.
      l.u = std::round(uniform(rng, -0.15f, 1.15f) * 4096.0f) / 4096.0f;
      l.v = std::round(uniform(rng, -0.15f, 1.15f) * 4096.0f) / 4096.0f;
      const float scale = std::pow(10.0f, uniform(rng, -3.0f, -0.5f));
      l.dudx = scale * uniform(rng, -1, 1);
      l.dvdx = scale * uniform(rng, -1, 1);
      l.dudy = scale * uniform(rng, -1, 1);
      l.dvdy = scale * uniform(rng, -1, 1);
      out.push_back(l);
    }
  }
  return out;
}

// The same lookups written in the turned face's uv (the other faces' are unchanged).
std::vector<Lookup> carried(std::vector<Lookup> lookups, uint32_t face, const UvMap& to_new) {
  for (Lookup& l : lookups) {
    if (l.face != face) continue;
    const glm::vec2 uv = to_new.point({l.u, l.v});
    const glm::vec2 dx = to_new.direction({l.dudx, l.dvdx});
    const glm::vec2 dy = to_new.direction({l.dudy, l.dvdy});
    l.u = uv.x;
    l.v = uv.y;
    l.dudx = dx.x;
    l.dvdx = dx.y;
    l.dudy = dy.x;
    l.dvdy = dy.y;
  }
  return lookups;
}

struct Comparison {
  size_t off = 0;
  float worst = 0.0f;
  std::string first;
};

void compare_colours(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b, const std::vector<Lookup>& lookups,
                     Comparison& out) {
  for (size_t i = 0; i < a.size(); ++i) {
    const float difference = glm::length(a[i] - b[i]);
    out.worst = std::max(out.worst, std::isnan(difference) ? INFINITY : difference);
    if (difference <= 1e-5f) continue;
    if (out.off++ == 0) {
      out.first = "lookup on face " + std::to_string(lookups[i].face) + " at (" + std::to_string(lookups[i].u) + ", " +
                  std::to_string(lookups[i].v) + "): " + std::to_string(a[i].r) + " vs " + std::to_string(b[i].r);
    }
  }
}

}  // namespace

TEST(Methods, LookupsDoNotDependOnTheVertexOrderOfAnyFace) {
  const std::vector<Method> methods = all_methods();
  ASSERT_GE(methods.size(), 6u);
  const std::vector<std::pair<int, bool>> turns{{1, false}, {2, false}, {3, false}, {0, true}, {1, true}};
  for (const TurnCase& c : turn_cases()) {
    const PackedScene plain = pack_scene(c.scene, TexelFormat::Rgba32f);
    const PackedScene banded = pack_scene(c.scene, TexelFormat::Rgba32f, kBand);
    TextureLookups plain_device(shared_runtime(), plain), banded_device(shared_runtime(), banded);
    std::mt19937 rng(2024);
    for (uint32_t face : c.faces) {
      const std::vector<Lookup> lookups = lookups_around(c.scene, face, rng);
      plain_device.set_lookups(lookups);
      banded_device.set_lookups(lookups);
      for (const auto& [rotation, mirror] : turns) {
        UvMap to_new;
        const Scene turned = seamcl_tests::turn_face(c.scene, face, rotation, mirror, &to_new);
        const std::vector<Lookup> turned_lookups = carried(lookups, face, to_new);
        const PackedScene turned_plain = pack_scene(turned, TexelFormat::Rgba32f);
        const PackedScene turned_banded = pack_scene(turned, TexelFormat::Rgba32f, kBand);
        TextureLookups turned_plain_device(shared_runtime(), turned_plain);
        TextureLookups turned_banded_device(shared_runtime(), turned_banded);
        turned_plain_device.set_lookups(turned_lookups);
        turned_banded_device.set_lookups(turned_lookups);
        for (Method method : methods) {
          const bool bands = method == Method::Guardband;
          for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
            SCOPED_TRACE(testing::Message() << c.mesh << " face " << face << " rotation " << rotation
                                            << (mirror ? " mirrored " : " ") << to_string(method) << " "
                                            << to_string(filter));
            const SamplerParams sampler = sampler_params(method, filter, 8, ZeroCoverage::Clamp, kBand);
            Comparison comparison;
            compare_colours((bands ? banded_device : plain_device).sample(sampler),
                            (bands ? turned_banded_device : turned_plain_device).sample(sampler), lookups, comparison);
            EXPECT_EQ(comparison.off, 0u) << "worst " << comparison.worst << "; first: " << comparison.first;
          }
        }
      }
    }
  }
}


TEST(Methods, ConstantColourIsExactOnClosedMeshesOfMixedResolution) {
  const glm::vec3 color(0.7f, 0.45f, 0.25f);
  const glm::vec3 stored(decode_srgb8(encode_srgb8(glm::vec4(color, 1.0f))));
  for (Scene scene : {seamcl_tests::subdivided_cube(3), seamcl_tests::split_pentagonal_prism()}) {
    seamcl_tests::set_textures(scene, seamcl_tests::mixed_texture_sizes(),
                               [&](size_t, int, int) { return glm::vec4(color, 1.0f); });
    Renderer renderer(shared_runtime());
    renderer.load_scene(scene);
    for (Method method : all_methods()) {
      for (Filter filter : {Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
        for (int msaa : {1, 4}) {
          SCOPED_TRACE(testing::Message() << scene.name << " " << to_string(method) << " " << to_string(filter)
                                          << " msaa " << msaa);
          RenderOptions options;
          options.width = 64;
          options.height = 64;
          options.msaa = msaa;
          options.method = method;
          options.filter = filter;
          const seamcl_tests::SeamCheck check =
              seamcl_tests::compare_with_lit_constant(renderer, renderer.render(scene.camera, options), stored);
          EXPECT_GT(check.checked, 64u * 64u / 4);
          EXPECT_EQ(check.brighter, 0u) << "worst " << check.worst;
          if (method == Method::Black) {
            // Taps past the edges weigh zero and nothing renormalises: the seams darken.
            EXPECT_GT(check.off, 10u);
          } else {
            EXPECT_EQ(check.off, 0u) << "worst " << check.worst;
          }
        }
      }
    }
  }
}
