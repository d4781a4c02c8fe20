// Traverse (McDonald 2013): the adjacency and uv transforms it reads, the kernel against its
// twin on connected faces of different sizes and orientations, and seamlessness on constant
// scenes.
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/pipeline/render_options.h>
#include <seamcl/pipeline/texture_lookups.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/adjacency.h"
#include "twins/texture_sample.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

// Checks every link of every face: the shared edge maps onto itself in 3D, and points just
// past the edge land just inside the neighbour at the same 3D place (faces are planar here, or
// nearly: a tolerance covers the torus's slight bend).
void expect_transforms_follow_the_surface(const Scene& scene, float tolerance) {
  const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
  ASSERT_EQ(adjacency.size(), scene.faces.size());
  size_t links = 0;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const auto corners = scene.corners(scene.faces[f]);
    for (int k = 0; k < 4; ++k) {
      const int g = adjacency[f].neighbor[k];
      if (g < 0) continue;
      ++links;
      const auto other = scene.corners(scene.faces[static_cast<size_t>(g)]);
      // The neighbour links back.
      bool back = false;
      for (int j = 0; j < 4; ++j) back |= adjacency[static_cast<size_t>(g)].neighbor[j] == static_cast<int>(f);
      EXPECT_TRUE(back) << "face " << f << " edge " << k;
      for (float s : {0.0f, 0.3f, 1.0f}) {
        constexpr float u_of[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        const glm::vec2 a(u_of[k][0], u_of[k][1]), b(u_of[(k + 1) % 4][0], u_of[(k + 1) % 4][1]);
        const glm::vec2 on_edge = a + s * (b - a);
        const glm::vec2 mapped = transform_uv(adjacency[f], k, on_edge);
        EXPECT_LT(glm::length(face_point(corners, on_edge.x, on_edge.y) - face_point(other, mapped.x, mapped.y)),
                  tolerance)
            << "face " << f << " edge " << k << " s " << s;
        // A point 0.1 past the edge (outside f) lands 0.1 inside g.
        const glm::vec2 inward(-(b - a).y, (b - a).x);
        const glm::vec2 past = transform_uv(adjacency[f], k, on_edge - 0.1f * inward);
        EXPECT_TRUE(past.x >= -1e-5f && past.x <= 1 + 1e-5f && past.y >= -1e-5f && past.y <= 1 + 1e-5f)
            << "face " << f << " edge " << k << " -> " << past.x << "," << past.y;
        // Derivatives carry over by the linear part: lengths kept (a rotation or reflection).
        const glm::vec2 d = transform_uv(adjacency[f], k, glm::vec2(0.3f, -0.7f), false);
        EXPECT_NEAR(glm::length(d), glm::length(glm::vec2(0.3f, -0.7f)), 1e-5f);
      }
    }
  }
  EXPECT_GT(links, 0u);
}

}  // namespace

TEST(Adjacency, Quad2HasOneLinkEachWay) {
  const Scene scene = generate_scene("quad2", {});
  const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
  int links = 0;
  for (const FaceNeighbors& n : adjacency) {
    for (int k = 0; k < 4; ++k) links += n.neighbor[k] >= 0;
  }
  EXPECT_EQ(links, 2);  // the one shared edge, seen from both sides; the outer edges are boundaries
  expect_transforms_follow_the_surface(scene, 1e-5f);
}

TEST(Adjacency, ClosedMeshesLinkEveryEdge) {
  for (const char* name : {"cube", "paper"}) {
    SCOPED_TRACE(name);
    const Scene scene = generate_scene(name, {});
    const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
    // The cube and the torus are closed: every edge has a neighbour. The ground of paper has
    // its outer boundary.
    const size_t closed = std::string(name) == "cube" ? 6 : 1450;
    for (size_t f = 0; f < closed; ++f) {
      for (int k = 0; k < 4; ++k) EXPECT_GE(adjacency[f].neighbor[k], 0) << "face " << f << " edge " << k;
    }
    expect_transforms_follow_the_surface(scene, std::string(name) == "cube" ? 1e-5f : 2e-3f);
  }
}

TEST(KernelVsTwin, TraverseOnConnectedFacesOfMixedSizesAndOrientations) {
  // The cube's faces meet at rotated uv frames; paper's at mixed, non-square sizes.
  for (const char* name : {"cube", "paper"}) {
    const Scene scene = generate_scene(name, {});
    std::mt19937 rng(77);
    std::vector<Lookup> lookups;
    for (int i = 0; i < 3000; ++i) {
      Lookup l;
      l.face = static_cast<uint32_t>(rng() % scene.faces.size());
      l.u = uniform(rng, -0.4f, 1.4f);
      l.v = uniform(rng, -0.4f, 1.4f);
      const float scale = std::pow(10.0f, uniform(rng, -3, -0.5f));
      l.dudx = scale * uniform(rng, -1, 1);
      l.dvdx = scale * uniform(rng, -1, 1);
      l.dudy = scale * uniform(rng, -1, 1);
      l.dvdy = scale * uniform(rng, -1, 1);
      lookups.push_back(l);
    }
    for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
      const PackedScene packed = pack_scene(scene, format);
      TextureLookups device(shared_runtime(), packed);
      device.set_lookups(lookups);
      for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
        SCOPED_TRACE(testing::Message() << name << " " << to_string(format) << " " << to_string(filter));
        const SamplerParams sampler = sampler_params(Method::Traverse, filter, 8, ZeroCoverage::Clamp);
        const std::vector<glm::vec4> gpu = device.sample(sampler);
        const std::vector<FilterSum> sums = device.filter(sampler);
        size_t bad = 0, beyond_own_face = 0;
        for (size_t i = 0; i < lookups.size(); ++i) {
          const Lookup& l = lookups[i];
          const glm::vec4 twin =
              sample_texture_reference(packed.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
          const FilterSum twin_sum =
              method_sum_reference(packed.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
          bool ok = std::fabs(sums[i].weight - twin_sum.weight) <= 1e-5f * std::max(1.0f, twin_sum.weight);
          for (int c = 0; c < 4; ++c) ok &= std::fabs(gpu[i][c] - twin[c]) <= 1e-5f;
          if (!ok && bad++ < 3) ADD_FAILURE() << "lookup " << i << ": gpu " << gpu[i].r << " twin " << twin.r;
          // Traverse reads the neighbours: weight beyond what the face alone holds.
          const FilterSum own = filter_texture_reference(packed.textures(), l.face, sampler, SEAMCL_ADDRESS_BORDER, l.u,
                                                         l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
          beyond_own_face += twin_sum.weight > own.weight + 1e-3f;
        }
        EXPECT_EQ(bad, 0u);
        EXPECT_GT(beyond_own_face, lookups.size() / 10);
      }
    }
  }
}

TEST(Traverse, ContinuesAcrossTheEdgeWhereDiscardStops) {
  // Two faces of quad2, texture content continuous across the shared edge. A footprint centred
  // exactly on the edge: discard sees only its own face's half; traverse sees both halves, which
  // is what a single texture spanning both faces would give. Check the weights say so.
  const Scene scene = generate_scene("quad2", {});
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  const std::vector<FaceNeighbors>& adjacency = packed.neighbors;
  int edge = -1;
  for (int k = 0; k < 4; ++k) edge = adjacency[0].neighbor[k] == 1 ? k : edge;
  ASSERT_EQ(edge, 1);  // face 0's u = 1 edge is face 1's u = 0 edge
  const float d = 4.0f / 64.0f;  // a footprint 4 texels wide across the edge
  const FilterSum discard = method_sum_reference(packed.textures(), 0, sampler_params(Method::Discard, Filter::Trilinear, 1, ZeroCoverage::Clamp),
                                                 1.0f, 0.5f, d, 0, 0, d);
  const FilterSum traverse = method_sum_reference(packed.textures(), 0, sampler_params(Method::Traverse, Filter::Trilinear, 1, ZeroCoverage::Clamp),
                                                  1.0f, 0.5f, d, 0, 0, d);
  EXPECT_NEAR(discard.weight, 0.5f, 0.05f);
  EXPECT_NEAR(traverse.weight, 1.0f, 0.05f);
}
