// Traverse (McDonald 2013, with Ptex's corners) and traverse-edges (without them): the adjacency,
// corner rings and uv transforms they read, the kernel against its twin on connected faces of
// different sizes and orientations, the diagonal face's share past a corner, and the bound that
// lets interior lookups skip the neighbours.
#include "test_meshes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <utility>

#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/texture_lookups.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/adjacency.h"
#include "pipeline/stages/texture_sample_twin.h"

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

SamplerParams with_bias(SamplerParams sampler, float lod_bias) {
  sampler.lod_bias = lod_bias;
  return sampler;
}

// Biases for the early-outs' tests, taken in turn: a positive one reads coarser texels, whose taps
// reach further than the footprint alone says; a negative one finer.
constexpr float kBiases[] = {0.0f, -1.5f, 0.5f, 1.0f, 2.75f, 4.0f};
float bias_in_turn(size_t i) { return kBiases[i % std::size(kBiases)]; }

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

TEST(Adjacency, CollapsedEdgesLinkNothing) {
  // Two triangles written as quads (vertex 0 twice), sharing the real edge 0-2 and, as written,
  // the collapsed edge 0-0: only the real edge links them. Three more such faces around a pole
  // (vertex 5) share nothing but it: no links, and no "non-manifold" edge 5-5.
  Scene scene;
  scene.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 2, 0}, {5, 5, 1},
                     {6, 5, 0}, {5, 6, 0}, {4, 5, 0}, {5, 4, 0}};
  for (std::array<uint32_t, 4> v : std::vector<std::array<uint32_t, 4>>{
           {0, 0, 1, 2}, {0, 0, 2, 3}, {5, 5, 6, 7}, {5, 5, 7, 8}, {5, 5, 8, 9}}) {
    Face face;
    face.vertices = v;
    scene.faces.push_back(face);
  }
  const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
  ASSERT_EQ(adjacency.size(), 5u);
  for (size_t f = 0; f < adjacency.size(); ++f) {
    EXPECT_EQ(adjacency[f].neighbor[0], -1) << "face " << f << ": its collapsed edge";
  }
  EXPECT_EQ(adjacency[0].neighbor[3], 1);  // 2-0 of face 0 is 0-2 of face 1
  EXPECT_EQ(adjacency[1].neighbor[1], 0);
  int links = 0;
  for (const FaceNeighbors& n : adjacency) {
    for (int k = 0; k < 4; ++k) links += n.neighbor[k] >= 0;
  }
  EXPECT_EQ(links, 2 + 4);  // 0-2 both ways; around the pole 5-7 and 5-8, each both ways
  EXPECT_EQ(non_manifold_edges(scene).count, 0u);
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
  // The cube's faces meet at rotated uv frames; paper's at mixed, non-square sizes, valence 4
  // everywhere; the prism's at sizes from 1x1 to 256x256 and valence 3, 4 and 5.
  Scene prism = seamcl_tests::split_pentagonal_prism();
  seamcl_tests::set_textures(prism, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  for (const char* name : {"cube", "paper", "prism"}) {
    const Scene scene = std::string(name) == "prism" ? prism : generate_scene(name, {});
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
    // Each method and filter in one storage, the two storages alternating: each pair is a kernel
    // variant (seconds to build on PoCL), and storage only changes how a texel is fetched, which
    // the sampler's tests hold to the twin in both.
    std::map<TexelFormat, PackedScene> packed_by_format;
    std::map<TexelFormat, std::unique_ptr<TextureLookups>> devices;
    for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
      packed_by_format.emplace(format, pack_scene(scene, format));
      devices.emplace(format, std::make_unique<TextureLookups>(shared_runtime(), packed_by_format.at(format)));
      devices.at(format)->set_lookups(lookups);
    }
    {
      int pair = 0;
      for (const auto& [method, filter] : std::vector<std::pair<Method, Filter>>{
               {Method::Traverse, Filter::Bilinear}, {Method::Traverse, Filter::Trilinear},
               {Method::Traverse, Filter::Aniso}, {Method::Traverse, Filter::Ewa},
               {Method::TraverseEdges, Filter::Trilinear}, {Method::TraverseEdges, Filter::Ewa}}) {
        const TexelFormat format = pair++ % 2 == 0 ? TexelFormat::Rgba8 : TexelFormat::Rgba32f;
        const PackedScene& packed = packed_by_format.at(format);
        TextureLookups& device = *devices.at(format);
        SCOPED_TRACE(testing::Message() << name << " " << to_string(format) << " " << to_string(method) << " "
                                        << to_string(filter));
        for (float lod_bias : {0.0f, -1.5f, 2.75f}) {
          SCOPED_TRACE(testing::Message() << "lod_bias " << lod_bias);
          const SamplerParams sampler = with_bias(sampler_params(method, filter, 8, ZeroCoverage::Clamp), lod_bias);
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
}

TEST(Adjacency, MapsAndSidesRoundTripThroughTheirBytes) {
  // Every signed permutation with every whole offset in -1..2: 128 maps, each its own byte, and
  // back to the same exact coefficients (the kernels decode the same bits: decode_uv_map).
  std::set<uint8_t> codes;
  int swaps = 0;
  for (int linear = 0; linear < 8; ++linear) {
    for (int ou = -1; ou <= 2; ++ou) {
      for (int ov = -1; ov <= 2; ++ov) {
        const float su = (linear & 2) != 0 ? -1.0f : 1.0f, sv = (linear & 4) != 0 ? -1.0f : 1.0f;
        UvMap map;
        map.linear = (linear & 1) != 0 ? glm::mat2(0.0f, sv, su, 0.0f) : glm::mat2(su, 0.0f, 0.0f, sv);
        map.offset = glm::vec2(static_cast<float>(ou), static_cast<float>(ov));
        const uint8_t code = encode_uv_map(map);
        codes.insert(code);
        const UvMap back = uv_map(code);
        EXPECT_TRUE(back.linear == map.linear && back.offset == map.offset) << "code " << int(code);
        // A point lands where the map puts it: u' = su (u or v) + ou.
        const glm::vec2 p = back.point({0.25f, 0.75f});
        EXPECT_EQ(p.x, su * ((linear & 1) != 0 ? 0.75f : 0.25f) + static_cast<float>(ou));
        EXPECT_EQ(p.y, sv * ((linear & 1) != 0 ? 0.25f : 0.75f) + static_cast<float>(ov));
        const std::array<float, 6> t = map_coefficients(code);
        swaps += map_swaps_axes(t.data());
        EXPECT_EQ(map_swaps_axes(t.data()), (linear & 1) != 0);
      }
    }
  }
  EXPECT_EQ(codes.size(), 128u);
  EXPECT_EQ(swaps, 64);
  UvMap sheared;
  sheared.linear = glm::mat2(1.0f, 1.0f, 0.0f, 1.0f);
  EXPECT_THROW(encode_uv_map(sheared), std::logic_error);
  UvMap far_away;
  far_away.offset = glm::vec2(3.0f, 0.0f);
  EXPECT_THROW(encode_uv_map(far_away), std::logic_error);
  UvMap halfway;
  halfway.offset = glm::vec2(0.5f, 0.0f);
  EXPECT_THROW(encode_uv_map(halfway), std::logic_error);

  // Reach sides: powers of two exactly; 0 and anything else read back as 0 (never skips).
  for (int e = -126; e <= 127; ++e) EXPECT_EQ(reach_side(encode_reach_side(std::ldexp(1.0f, e))), std::ldexp(1.0f, e));
  for (float other : {0.0f, 3.0f, 0.75f, -2.0f, INFINITY, NAN, std::ldexp(1.0f, -130)}) {
    EXPECT_EQ(encode_reach_side(other), SEAMCL_SIDE_NONE) << other;
  }
  EXPECT_EQ(reach_side(SEAMCL_SIDE_NONE), 0.0f);
}

TEST(Adjacency, KernelsDecodeEveryByteAsTheHostDoes) {
  // Every byte as a map and as a reach side, decoded by the kernels' decode_uv_map and reach_side:
  // the same floats, bit for bit (signed zeros included), as map_coefficients and reach_side.
  cl::Kernel kernel(shared_runtime().program(KernelProgram::Sampling), "neighbor_bytes_decoded");
  cl::Buffer out(shared_runtime().context(), CL_MEM_WRITE_ONLY, sizeof(float) * 7 * 256);
  kernel.setArg(0, out);
  shared_runtime().queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(256));
  std::vector<float> device(7 * 256);
  shared_runtime().queue().enqueueReadBuffer(out, CL_TRUE, 0, sizeof(float) * device.size(), device.data());
  for (int b = 0; b < 256; ++b) {
    const std::array<float, 6> host = map_coefficients(static_cast<uint8_t>(b));
    EXPECT_EQ(std::memcmp(host.data(), &device[7 * static_cast<size_t>(b)], sizeof(float) * 6), 0) << "map byte " << b;
    const float side = reach_side(static_cast<uint8_t>(b));
    EXPECT_EQ(std::memcmp(&side, &device[7 * static_cast<size_t>(b) + 6], sizeof(float)), 0)
        << "side byte " << b << ": host " << side << ", kernel " << device[7 * static_cast<size_t>(b) + 6];
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

namespace {

// How many faces hold each vertex.
std::vector<int> faces_per_vertex(const Scene& scene) {
  std::vector<int> count(scene.positions.size(), 0);
  for (const Face& face : scene.faces) {
    for (uint32_t v : face.vertices) ++count[v];
  }
  return count;
}

// The cube with one side left out: its rim is a mesh boundary.
Scene open_box() {
  Scene scene = seamcl_tests::subdivided_cube(2);
  scene.faces.erase(scene.faces.begin() + 4, scene.faces.begin() + 8);
  return scene;
}

bool same_map(const UvMap& a, const UvMap& b) {
  return glm::all(glm::equal(a.linear[0], b.linear[0])) && glm::all(glm::equal(a.linear[1], b.linear[1])) &&
         glm::all(glm::equal(a.offset, b.offset));
}

}  // namespace

TEST(Adjacency, CornerRingsFindEveryVertexsValence) {
  // Closed meshes: every ring closes, around as many faces as hold the vertex; the diagonal face
  // is linked exactly at valence 4.
  for (const Scene& scene : {seamcl_tests::subdivided_cube(2), seamcl_tests::split_pentagonal_prism(),
                             generate_scene("cube", {})}) {
    SCOPED_TRACE(scene.name);
    const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
    const std::vector<int> holding = faces_per_vertex(scene);
    std::set<int> valences;
    for (uint32_t f = 0; f < scene.faces.size(); ++f) {
      for (int k = 0; k < 4; ++k) {
        const VertexRing ring = corner_ring(scene, adjacency, f, k);
        const uint32_t vertex = scene.faces[f].vertices[k];
        EXPECT_TRUE(ring.closed) << "face " << f << " corner " << k;
        EXPECT_EQ(ring.valence(), holding[vertex]) << "face " << f << " corner " << k;
        valences.insert(ring.valence());
        // Every face of the ring holds the vertex, at the corner recorded.
        for (const RingFace& r : ring.faces) EXPECT_EQ(scene.faces[r.face].vertices[r.corner], vertex);
        EXPECT_EQ(adjacency[f].corner[k] >= 0, ring.valence() == 4) << "face " << f << " corner " << k;
      }
    }
    if (scene.name == "split_pentagonal_prism") EXPECT_EQ(valences, (std::set<int>{3, 4, 5}));
    if (scene.name == "subdivided_cube") EXPECT_EQ(valences, (std::set<int>{3, 4}));
  }
  // At a boundary the ring is open and nothing is linked past the corner.
  const Scene box = open_box();
  const std::vector<FaceNeighbors> adjacency = build_adjacency(box);
  size_t open = 0;
  for (uint32_t f = 0; f < box.faces.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      const VertexRing ring = corner_ring(box, adjacency, f, k);
      if (ring.closed) continue;
      ++open;
      EXPECT_EQ(ring.valence(), 0);
      EXPECT_EQ(adjacency[f].corner[k], -1);
    }
  }
  EXPECT_GT(open, 8u);
}

TEST(Adjacency, DiagonalMapIsTheEdgeMapsComposedEitherWayRound) {
  // At a valence-4 vertex the diagonal face is reached across edge k and then across the
  // neighbour's other edge at the vertex, or across edge k-1 and on: both give the same map, the
  // one corner_map builds from the corners alone, and it follows the surface where it is flat.
  for (const Scene& scene : {seamcl_tests::subdivided_cube(2), generate_scene("paper", {})}) {
    SCOPED_TRACE(scene.name);
    const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
    size_t checked = 0, flat = 0;
    for (uint32_t f = 0; f < scene.faces.size(); ++f) {
      for (int k = 0; k < 4; ++k) {
        const int diagonal = adjacency[f].corner[k];
        if (diagonal < 0) continue;
        ++checked;
        const UvMap stored = uv_map(adjacency[f].corner_map[k]);
        const VertexRing ring = corner_ring(scene, adjacency, f, k);
        ASSERT_EQ(ring.valence(), 4);
        EXPECT_TRUE(same_map(stored, corner_map(k, ring.faces[1].corner, corner_swap(scene, ring.faces[1]))))
            << "face " << f << " corner " << k;
        // The other way round: across edge k-1, then across that neighbour's edge into the diagonal.
        const int before = (k + 3) % 4;
        const uint32_t side = static_cast<uint32_t>(adjacency[f].neighbor[before]);
        bool found = false;
        for (int e = 0; e < 4 && !found; ++e) {
          if (adjacency[side].neighbor[e] != diagonal) continue;
          const UvMap other_way = compose(uv_map(adjacency[side].edge_map[e]), uv_map(adjacency[f].edge_map[before]));
          found = same_map(other_way, stored);
        }
        EXPECT_TRUE(found) << "face " << f << " corner " << k;
        // Where the four faces are coplanar squares, a point past the corner lands on the same
        // 3D point of the diagonal face as the face's own plane continued gives.
        const auto corners = scene.corners(scene.faces[f]);
        const auto diagonal_corners = scene.corners(scene.faces[static_cast<size_t>(diagonal)]);
        constexpr float cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
        const glm::vec2 past(cu[k] + (cu[k] > 0 ? 0.3f : -0.3f), cv[k] + (cv[k] > 0 ? 0.2f : -0.2f));
        const glm::vec3 continued = corners[0] + past.x * (corners[1] - corners[0]) + past.y * (corners[3] - corners[0]);
        const glm::vec2 mapped = stored.point(past);
        EXPECT_TRUE(mapped.x > 0 && mapped.x < 1 && mapped.y > 0 && mapped.y < 1) << mapped.x << "," << mapped.y;
        if (scene.name == "subdivided_cube" && std::fabs(glm::dot(scene.face_normal(scene.faces[f]),
                                                                  scene.face_normal(scene.faces[static_cast<size_t>(diagonal)]))) > 0.999f) {
          ++flat;
          EXPECT_LT(glm::length(face_point(diagonal_corners, mapped.x, mapped.y) - continued), 1e-5f);
        }
      }
    }
    EXPECT_GT(checked, 0u);
    // The four faces around each side's centre (the others fold over the cube's edges).
    if (scene.name == "subdivided_cube") EXPECT_EQ(flat, 24u);
  }
}

TEST(Traverse, DiagonalFaceTakesThePartOfTheFootprintPastTheCorner) {
  // A footprint centred on the vertex where four coplanar squares of the subdivided cube meet:
  // traverse-edges reads three of the four quadrants, traverse all four, as one texture would.
  Scene scene = seamcl_tests::subdivided_cube(2);
  seamcl_tests::set_textures(scene, {{64, 64}}, seamcl_tests::distinct_texel);
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  const std::vector<FaceNeighbors>& adjacency = packed.neighbors;
  // A face and a valence-4 corner of it.
  uint32_t face = 0;
  int corner = -1;
  for (uint32_t f = 0; f < scene.faces.size() && corner < 0; ++f) {
    for (int k = 0; k < 4 && corner < 0; ++k) {
      if (adjacency[f].corner[k] >= 0) {
        face = f;
        corner = k;
      }
    }
  }
  ASSERT_GE(corner, 0);
  constexpr float cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
  const float d = 4.0f / 64.0f;  // four texels
  for (Filter filter : {Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
    SCOPED_TRACE(to_string(filter));
    auto weight = [&](Method method) {
      return method_sum_reference(packed.textures(), face, sampler_params(method, filter, 8, ZeroCoverage::Clamp),
                                  cu[corner], cv[corner], d, 0, 0, d)
          .weight;
    };
    EXPECT_NEAR(weight(Method::Discard), 0.25f, 0.03f);
    EXPECT_NEAR(weight(Method::TraverseEdges), 0.75f, 0.05f);
    EXPECT_NEAR(weight(Method::Traverse), 1.0f, 0.05f);
  }
}

TEST(Traverse, SkipsOnlyNeighboursThatWouldAddNothing) {
  // neighbor_may_contribute is what lets an interior lookup skip the neighbours' filters; it must
  // never rule out a neighbour that holds a tap of any weight. Checked on every neighbour of
  // random lookups (sizes 1x1 to 256x256, non-square ones too), every filter, and on purpose
  // near the bound: footprints from a hundredth of a texel to a whole face.
  Scene scene = seamcl_tests::subdivided_cube(2);
  seamcl_tests::set_textures(scene, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  const TextureView view = packed.textures();
  std::mt19937 rng(5);
  size_t skipped = 0, kept = 0;
  for (int i = 0; i < 20000; ++i) {
    const uint32_t face = static_cast<uint32_t>(rng() % scene.faces.size());
    const float u = uniform(rng, -0.1f, 1.1f), v = uniform(rng, -0.1f, 1.1f);
    const float scale = std::pow(10.0f, uniform(rng, -4.0f, 0.0f));
    const float dudx = scale * uniform(rng, -1, 1), dvdx = scale * uniform(rng, -1, 1);
    const float dudy = scale * uniform(rng, -1, 1), dvdy = scale * uniform(rng, -1, 1);
    const Filter filter = static_cast<Filter>(rng() % 4);
    const SamplerParams sampler = with_bias(
        sampler_params(Method::Traverse, filter, 1 + static_cast<int>(rng() % 16), ZeroCoverage::Clamp), bias_in_turn(i));
    const FaceNeighbors& n = packed.neighbors[face];
    const float inside[4] = {v, 1.0f - u, 1.0f - v, u};
    for (int j = 0; j < 8; ++j) {
      const int k = j % 4;
      const int other = j < 4 ? n.neighbor[k] : n.corner[k];
      if (other < 0) continue;
      // Along u and v: an edge's distance on its axis (v for edges 0 and 2), a corner's on both.
      const bool k_along_v = k % 2 == 0;
      const float a = j < 4 ? -1.0f : inside[(k + 3) % 4], b = inside[k];
      const float distance_u = k_along_v ? a : b, distance_v = k_along_v ? b : a;
      const uint8_t code = j < 4 ? n.edge_map[k] : n.corner_map[k];
      if (neighbor_may_contribute(packed.faces[static_cast<size_t>(other)], map_swaps_axes(map_coefficients(code).data()), sampler.filter,
                                  sampler.max_aniso, sampler.lod_bias, 0, distance_u, distance_v, dudx, dvdx, dudy, dvdy)) {
        ++kept;
        continue;
      }
      ++skipped;
      const UvMap map = uv_map(code);
      const glm::vec2 p = map.point({u, v}), dx = map.direction({dudx, dvdx}), dy = map.direction({dudy, dvdy});
      const FilterSum s = filter_texture_reference(view, static_cast<uint32_t>(other), sampler, SEAMCL_ADDRESS_BORDER,
                                                   p.x, p.y, dx.x, dx.y, dy.x, dy.y);
      ASSERT_EQ(s.weight, 0.0f) << "face " << face << " neighbour " << other << " (" << (j < 4 ? "edge " : "corner ") << k
                                << ") at " << u << "," << v << " scale " << scale << " " << to_string(filter)
                                << " lod_bias " << sampler.lod_bias;
    }
  }
  // The bound is not vacuous: interior lookups do skip.
  EXPECT_GT(skipped, kept / 4);
}

namespace {

// Lookups that crowd the edges and corners of their face, footprints from a hundredth of a
// texel to a whole face, isotropic to needle-thin: where an early-out would go wrong if it could.
std::vector<Lookup> lookups_near_edges(size_t face_count, size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Lookup> lookups(count);
  for (Lookup& l : lookups) {
    l.face = static_cast<uint32_t>(rng() % face_count);
    // Half the points within a tenth of an edge (either side), the rest anywhere around the face.
    auto coordinate = [&]() {
      if (rng() % 2 == 0) return uniform(rng, -0.2f, 1.2f);
      const float edge = static_cast<float>(rng() % 2);
      return edge + std::pow(10.0f, uniform(rng, -5.0f, -1.0f)) * (rng() % 2 == 0 ? 1.0f : -1.0f);
    };
    l.u = coordinate();
    l.v = coordinate();
    const float scale = std::pow(10.0f, uniform(rng, -4.5f, 0.0f));
    const float stretch = std::pow(10.0f, uniform(rng, -2.0f, 0.0f));
    const float angle = uniform(rng, 0.0f, 6.2831853f);
    // Axis x the major one, axis y shorter by `stretch`, both turned by `angle`.
    l.dudx = scale * std::cos(angle);
    l.dvdx = scale * std::sin(angle);
    l.dudy = -scale * stretch * std::sin(angle) * (rng() % 2 == 0 ? 1.0f : -1.0f);
    l.dvdy = scale * stretch * std::cos(angle);
  }
  return lookups;
}

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_bits(const FilterSum& a, const FilterSum& b) {
  bool same = same_bits(a.weight, b.weight);
  for (int c = 0; c < 4; ++c) same &= same_bits(a.color[c], b.color[c]);
  return same;
}

}  // namespace

TEST(Traverse, ReachTestSkipsOnlyNeighboursThatWouldAddNothing) {
  // lookup_may_reach_face tests the probes a bilinear, trilinear or aniso lookup takes on the
  // neighbour against its square: every neighbour it rules out must weigh exactly zero, and it
  // must rule out most neighbours of lookups well inside their face (what makes traverse cheap).
  Scene scene = seamcl_tests::subdivided_cube(2);
  seamcl_tests::set_textures(scene, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  const TextureView view = packed.textures();
  const std::vector<Lookup> lookups = lookups_near_edges(scene.faces.size(), 20000, 9);
  std::mt19937 rng(10);
  size_t skipped = 0, kept = 0, reaching = 0;
  for (size_t i = 0; i < lookups.size(); ++i) {
    const Lookup& l = lookups[i];
    const Filter filter = static_cast<Filter>(rng() % 3);  // bilinear, trilinear, aniso
    const SamplerParams sampler = with_bias(
        sampler_params(Method::Traverse, filter, 1 + static_cast<int>(rng() % 16), ZeroCoverage::Clamp), bias_in_turn(i));
    const FaceNeighbors& n = packed.neighbors[l.face];
    for (int j = 0; j < 8; ++j) {
      const int k = j % 4;
      const int other = j < 4 ? n.neighbor[k] : n.corner[k];
      if (other < 0) continue;
      const UvMap map = uv_map(j < 4 ? n.edge_map[k] : n.corner_map[k]);
      const glm::vec2 p = map.point({l.u, l.v}), dx = map.direction({l.dudx, l.dvdx}), dy = map.direction({l.dudy, l.dvdy});
      const FaceGpu& g = packed.faces[static_cast<size_t>(other)];
      const FilterSum s = filter_texture_reference(view, static_cast<uint32_t>(other), sampler, SEAMCL_ADDRESS_BORDER,
                                                   p.x, p.y, dx.x, dx.y, dy.x, dy.y);
      reaching += s.weight > 0.0f;
      if (lookup_may_reach_face(g, 0, sampler.filter, sampler.max_aniso, sampler.lod_bias, p.x, p.y, dx.x, dx.y, dy.x, dy.y)) {
        ++kept;
        continue;
      }
      ++skipped;
      ASSERT_EQ(s.weight, 0.0f) << "face " << l.face << " neighbour " << other << " (" << (j < 4 ? "edge " : "corner ")
                                << k << ") at " << l.u << "," << l.v << " " << to_string(filter) << " lod_bias "
                                << sampler.lod_bias;
      ASSERT_TRUE(same_bits(s, FilterSum{})) << "a skipped neighbour adds colour";
    }
  }
  EXPECT_GT(skipped, kept);
  // Not loose: of the neighbours it keeps, most do hold weight (the test is about the probes).
  EXPECT_GT(reaching, kept / 2) << "kept " << kept << " reaching " << reaching;
}

TEST(Traverse, EdgeReachTestSkipsOnlyFacesThatWouldAddNothing) {
  // edges_may_reach decides from the lookup's own FaceNeighbors record (the sides pack_scene
  // stores per edge) whether a face across edge k or past its ends can be reached; a clear bit
  // skips those three faces unread. Each face it skips must be one neighbor_may_contribute skips
  // too (the stored sides bound every face's) and must weigh exactly zero. Faces of mixed sizes
  // (1x1 to 256x256, non-square), valence 3, 4 and 5, every filter.
  Scene prism = seamcl_tests::split_pentagonal_prism();
  seamcl_tests::set_textures(prism, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  Scene cube = seamcl_tests::subdivided_cube(2);
  seamcl_tests::set_textures(cube, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  for (const Scene* scene : {&prism, &cube}) {
    const PackedScene packed = pack_scene(*scene, TexelFormat::Rgba32f);
    const TextureView view = packed.textures();
    const std::vector<Lookup> lookups = lookups_near_edges(scene->faces.size(), 20000, 12);
    std::mt19937 rng(13);
    size_t edges_skipped = 0, edges_kept = 0, interior_decided = 0, interior = 0;
    for (size_t i = 0; i < lookups.size(); ++i) {
      const Lookup& l = lookups[i];
      const Filter filter = static_cast<Filter>(rng() % 4);
      const SamplerParams sampler = with_bias(
          sampler_params(Method::Traverse, filter, 1 + static_cast<int>(rng() % 16), ZeroCoverage::Clamp), bias_in_turn(i));
      const FaceNeighbors& n = packed.neighbors[l.face];
      const int mask = edges_may_reach(n, sampler.filter, sampler.max_aniso, sampler.lod_bias, 0, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
      const bool inside_face = l.u > 0.1f && l.u < 0.9f && l.v > 0.1f && l.v < 0.9f;
      interior += inside_face;
      interior_decided += inside_face && mask == 0;
      const float inside[4] = {l.v, 1.0f - l.u, 1.0f - l.v, l.u};
      for (int k = 0; k < 4; ++k) {
        if ((mask >> k) & 1) {
          ++edges_kept;
          continue;
        }
        ++edges_skipped;
        // The neighbour across edge k, and the diagonal faces past its ends (corners k and k + 1).
        for (int j : {k, 4 + k, 4 + (k + 1) % 4}) {
          const int c = j % 4;
          const int other = j < 4 ? n.neighbor[c] : n.corner[c];
          if (other < 0) continue;
          const bool c_along_v = c % 2 == 0;
          const float a = j < 4 ? -1.0f : inside[(c + 3) % 4], b = inside[c];
          const uint8_t code = j < 4 ? n.edge_map[c] : n.corner_map[c];
          ASSERT_FALSE(neighbor_may_contribute(packed.faces[static_cast<size_t>(other)], map_swaps_axes(map_coefficients(code).data()),
                                               sampler.filter, sampler.max_aniso, sampler.lod_bias, 0, c_along_v ? a : b,
                                               c_along_v ? b : a, l.dudx, l.dvdx, l.dudy, l.dvdy))
              << "edge " << k << " skips face " << other << " that the per-face test keeps (lod_bias "
              << sampler.lod_bias << ")";
          const UvMap map = uv_map(code);
          const glm::vec2 p = map.point({l.u, l.v}), dx = map.direction({l.dudx, l.dvdx}),
                          dy = map.direction({l.dudy, l.dvdy});
          const FilterSum s = filter_texture_reference(view, static_cast<uint32_t>(other), sampler,
                                                       SEAMCL_ADDRESS_BORDER, p.x, p.y, dx.x, dx.y, dy.x, dy.y);
          ASSERT_TRUE(same_bits(s, FilterSum{})) << "a skipped face adds weight " << s.weight << " (lod_bias "
                                                 << sampler.lod_bias << ")";
        }
      }
    }
    // Not vacuous: a good share of the edges of these lookups (footprints up to a whole face,
    // crowded at edges: about 40% measured) and of the lookups well inside (about 12%) decide here.
    EXPECT_GT(edges_skipped, edges_kept / 2) << edges_skipped << " skipped, " << edges_kept << " kept";
    EXPECT_GT(interior_decided, interior / 16) << interior_decided << " of " << interior;
  }
}

TEST(Traverse, EdgeReachRecordsBoundTheFacesAround) {
  // pack_scene fills reach_min_side / reach_max_side per edge from the faces across it and past
  // its ends, their sides as they lie in this face's uv: the smallest side along the axis that
  // crosses the edge, and that times the largest ratio of the other axis's side to it. Checked
  // through the maps themselves: the other face's extent along this face's axis is its side
  // mapped back. An edge with no face around keeps 0, and a record of zeros (SEAMCL_SIDE_NONE)
  // rules nothing out.
  Scene prism = seamcl_tests::split_pentagonal_prism();
  seamcl_tests::set_textures(prism, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  const PackedScene packed = pack_scene(prism, TexelFormat::Rgba32f);
  size_t filled = 0, swapped = 0;
  for (size_t f = 0; f < packed.neighbors.size(); ++f) {
    const FaceNeighbors& n = packed.neighbors[f];
    for (int k = 0; k < 4; ++k) {
      const bool along_v = k % 2 == 0;
      float side = 0.0f, ratio = 0.0f;
      const int across[3] = {n.neighbor[k], n.corner[k], n.corner[(k + 1) % 4]};
      const uint8_t maps[3] = {n.edge_map[k], n.corner_map[k], n.corner_map[(k + 1) % 4]};
      for (int i = 0; i < 3; ++i) {
        if (across[i] < 0) continue;
        const FaceGpu& g = packed.faces[static_cast<size_t>(across[i])];
        // This face's unit step along u (or v) in the other face's uv: along which of its axes it runs.
        const UvMap map = uv_map(maps[i]);
        const glm::vec2 step_u = map.direction({1.0f, 0.0f}), step_v = map.direction({0.0f, 1.0f});
        const float side_u = std::fabs(step_u.x) * static_cast<float>(g.width) + std::fabs(step_u.y) * static_cast<float>(g.height);
        const float side_v = std::fabs(step_v.x) * static_cast<float>(g.width) + std::fabs(step_v.y) * static_cast<float>(g.height);
        swapped += step_u.x == 0.0f;
        const float along = along_v ? side_v : side_u, cross = along_v ? side_u : side_v;
        side = side == 0.0f ? along : std::min(side, along);
        ratio = std::max(ratio, cross / along);
      }
      EXPECT_EQ(reach_side(n.reach_min_side[k]), side) << "face " << f << " edge " << k;
      EXPECT_EQ(reach_side(n.reach_max_side[k]), side * ratio) << "face " << f << " edge " << k;
      filled += side > 0.0f;
    }
  }
  EXPECT_GT(filled, packed.neighbors.size() * 3);
  EXPECT_GT(swapped, 0u) << "the prism should hold maps that swap u and v";
  FaceNeighbors unfilled{};
  for (int k = 0; k < 4; ++k) unfilled.neighbor[k] = unfilled.corner[k] = -1;
  for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
    EXPECT_EQ(edges_may_reach(unfilled, sampler_params(Method::Traverse, filter, 16, ZeroCoverage::Clamp).filter, 16, 0.0f, 0,
                              0.5f, 0.5f, 1e-4f, 0.0f, 0.0f, 1e-4f),
              15);
  }
}

TEST(Traverse, EarlyOutsChangeNoBitOfTheTwin) {
  // The twin's traverse with its early-outs (neighbor_may_contribute, lookup_may_reach_face)
  // and without them, on faces of mixed sizes (valence 3, 4, 5) and on paper: the same bits.
  Scene prism = seamcl_tests::split_pentagonal_prism();
  seamcl_tests::set_textures(prism, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  for (const char* name : {"prism", "paper"}) {
    const Scene scene = std::string(name) == "prism" ? prism : generate_scene(name, {});
    const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
    const std::vector<Lookup> lookups = lookups_near_edges(scene.faces.size(), 4000, 11);
    size_t changed = 0, crossing = 0;
    for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
      for (Method method : {Method::Traverse, Method::TraverseEdges}) {
        for (size_t i = 0; i < lookups.size(); ++i) {
          const Lookup& l = lookups[i];
          const SamplerParams sampler = with_bias(sampler_params(method, filter, 16, ZeroCoverage::Clamp), bias_in_turn(i));
          const FilterSum fast = method_sum_reference(packed.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx,
                                                      l.dudy, l.dvdy, true);
          const FilterSum every = method_sum_reference(packed.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx,
                                                       l.dudy, l.dvdy, false);
          const FilterSum own = filter_texture_reference(packed.textures(), l.face, sampler, SEAMCL_ADDRESS_BORDER,
                                                         l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
          crossing += every.weight > own.weight;
          if (!same_bits(fast, every) && changed++ < 3) {
            ADD_FAILURE() << name << " " << to_string(method) << " " << to_string(filter) << " lod_bias "
                          << sampler.lod_bias << " face " << l.face << " at " << l.u << "," << l.v << ": weight "
                          << fast.weight << " vs " << every.weight;
          }
        }
      }
    }
    EXPECT_EQ(changed, 0u) << name;
    EXPECT_GT(crossing, lookups.size()) << name << ": the lookups should cross edges often";
  }
}

TEST(KernelVsTwin, TraverseEarlyOutsChangeNoBitOfTheKernel) {
  // The kernel built with SEAMCL_TRAVERSE_EARLY_OUT=0 filters every neighbour; with the early-outs
  // (as renders run) its sums and colours must be the same bits.
  Scene prism = seamcl_tests::split_pentagonal_prism();
  seamcl_tests::set_textures(prism, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
  // Each filter in one storage, alternating as in TraverseOnConnectedFaces (whose variants these
  // early-out ones are): a kernel variant takes seconds to build on PoCL.
  for (const char* name : {"prism", "paper"}) {
    const Scene scene = std::string(name) == "prism" ? prism : generate_scene(name, {});
    const std::vector<Lookup> lookups = lookups_near_edges(scene.faces.size(), 4000, 12);
    int filter_index = 0;
    for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
      const TexelFormat format = filter_index++ % 2 == 0 ? TexelFormat::Rgba8 : TexelFormat::Rgba32f;
      const PackedScene packed = pack_scene(scene, format);
      TextureLookups fast(shared_runtime(), packed), every(shared_runtime(), packed);
      every.set_traverse_early_out(false);
      fast.set_lookups(lookups);
      every.set_lookups(lookups);
      for (float lod_bias : {0.0f, -1.5f, 2.75f}) {
        SCOPED_TRACE(testing::Message() << name << " " << to_string(filter) << " " << to_string(format) << " lod_bias "
                                        << lod_bias);
        const SamplerParams sampler = with_bias(sampler_params(Method::Traverse, filter, 16, ZeroCoverage::Clamp), lod_bias);
        const std::vector<FilterSum> a = fast.filter(sampler), b = every.filter(sampler);
        const std::vector<glm::vec4> ca = fast.sample(sampler), cb = every.sample(sampler);
        size_t changed = 0;
        for (size_t i = 0; i < lookups.size(); ++i) {
          bool same = same_bits(a[i], b[i]);
          for (int c = 0; c < 4; ++c) same &= same_bits(ca[i][c], cb[i][c]) || (std::isnan(ca[i][c]) && std::isnan(cb[i][c]));
          if (!same && changed++ < 3) {
            ADD_FAILURE() << "lookup " << i << ": weight " << a[i].weight << " vs " << b[i].weight << ", red " << ca[i].r
                          << " vs " << cb[i].r;
          }
        }
        EXPECT_EQ(changed, 0u);
      }
    }
  }
}
