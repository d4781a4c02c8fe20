// Guard bands (McDonald and Burley 2011): the bands hold the neighbours' texels at the band's own
// texel density (box-filtered from a finer neighbour, interpolated from a coarser one), corners
// at every valence and at boundaries hold what guard_band.h says, the kernels read them as their
// twin does, and they cost the memory reported.
#include "test_meshes.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <set>
#include <vector>

#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/texture_lookups.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/adjacency.h"
#include "pipeline/guard_band.h"
#include "pipeline/stages/texture_sample_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

// The number of lookups whose device colour `close(device, twin)` refuses for some channel, against
// sample_texture_reference with the same sampler; the first three are reported as failures.
template <typename Close>
size_t twin_colour_mismatches(const std::vector<glm::vec4>& gpu, const PackedScene& packed, const SamplerParams& sampler,
                              const std::vector<Lookup>& lookups, Close close) {
  size_t bad = 0;
  for (size_t i = 0; i < lookups.size(); ++i) {
    const Lookup& l = lookups[i];
    const glm::vec4 twin =
        sample_texture_reference(packed.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
    bool ok = true;
    for (int c = 0; c < 4; ++c) ok &= close(gpu[i][c], twin[c]);
    if (!ok && bad++ < 3) ADD_FAILURE() << "lookup " << i << ": gpu " << gpu[i].r << " twin " << twin.r;
  }
  return bad;
}

// A 2 x 2 grid of unit quads sharing vertices, every texture 8 x 8 with a distinct value per
// texel and face: band texels can then be traced back to exactly one source texel.
Scene grid_scene() {
  Scene scene;
  scene.name = "grid";
  for (int j = 0; j <= 2; ++j) {
    for (int i = 0; i <= 2; ++i) scene.positions.emplace_back(static_cast<float>(i), static_cast<float>(j), 0.0f);
  }
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 2; ++i) {
      const auto v = [&](int x, int y) { return static_cast<uint32_t>(y * 3 + x); };
      Face face;
      face.vertices = {v(i, j), v(i + 1, j), v(i + 1, j + 1), v(i, j + 1)};
      TextureLevel level{8, 8, {}};
      const float id = static_cast<float>(scene.faces.size());
      for (int y = 0; y < 8; ++y) {
        for (int x = 0; x < 8; ++x) level.texels.emplace_back(id, static_cast<float>(x), static_cast<float>(y), 1.0f);
      }
      face.texture = build_mip_chain(std::move(level));
      scene.faces.push_back(std::move(face));
    }
  }
  scene.camera.eye = {1, 1, 3};
  scene.camera.target = {1, 1, 0};
  return scene;
}

}  // namespace

TEST(GuardBand, BandsHoldTheNeighboursTexels) {
  const Scene scene = grid_scene();
  const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
  constexpr int band = 3;
  // Face 0 is the bottom-left quad: face 1 to its right (u > 1), face 2 above (v > 1), face 3
  // diagonally (u > 1 and v > 1); left and below are the grid's boundary.
  const TextureLevel padded = guard_banded_level(scene, adjacency, 0, 0, band);
  ASSERT_EQ(padded.width, 8 + 2 * band);
  ASSERT_EQ(padded.height, 8 + 2 * band);
  auto stored = [&](int i, int j) { return padded.at(i + band, j + band); };  // face texel coordinates
  // Inside: the face itself.
  EXPECT_EQ(stored(5, 6), glm::vec4(0, 5, 6, 1));
  // Right band: face 1's first columns, same rows.
  for (int k = 0; k < band; ++k) EXPECT_EQ(stored(8 + k, 4), glm::vec4(1, static_cast<float>(k), 4, 1)) << k;
  // Top band: face 2's first rows.
  for (int k = 0; k < band; ++k) EXPECT_EQ(stored(2, 8 + k), glm::vec4(2, 2, static_cast<float>(k), 1)) << k;
  // Corner band: face 3, reached across two edges.
  EXPECT_EQ(stored(8, 8), glm::vec4(3, 0, 0, 1));
  EXPECT_EQ(stored(10, 9), glm::vec4(3, 2, 1, 1));
  // Boundary: the nearest texel of the face repeats.
  EXPECT_EQ(stored(-1, 3), glm::vec4(0, 0, 3, 1));
  EXPECT_EQ(stored(-3, -3), glm::vec4(0, 0, 0, 1));
  // Coarser levels fill from the same level of the neighbour: level 2 is 2 x 2.
  const TextureLevel coarse = guard_banded_level(scene, adjacency, 0, 2, band);
  const TextureLevel& neighbour_level = scene.faces[1].texture.levels[2];
  EXPECT_EQ(coarse.at(band + 2, band + 1), neighbour_level.at(0, 1));
}

TEST(GuardBand, PackingReportsThePaddingBytes) {
  const Scene scene = generate_scene("quad2", {});
  const PackedScene plain = pack_scene(scene, TexelFormat::Rgba8, 0);
  const PackedScene banded = pack_scene(scene, TexelFormat::Rgba8, 4);
  EXPECT_EQ(plain.padding_bytes(), 0u);
  size_t band_texels = 0;
  for (const Face& face : scene.faces) {
    for (const TextureLevel& level : face.texture.levels) {
      band_texels += static_cast<size_t>(level.width + 8) * static_cast<size_t>(level.height + 8) - level.texels.size();
    }
  }
  EXPECT_EQ(banded.padding_bytes(), band_texels * 4);
  EXPECT_EQ(banded.texture_bytes(), plain.texture_bytes() + banded.padding_bytes());
}

TEST(KernelVsTwin, GuardBandEveryFilterAndStorage) {
  for (const char* name : {"cube", "paper"}) {
    const Scene scene = generate_scene(name, {});
    std::mt19937 rng(91);
    std::vector<Lookup> lookups;
    for (int i = 0; i < 3000; ++i) {
      Lookup l;
      l.face = static_cast<uint32_t>(rng() % scene.faces.size());
      l.u = uniform(rng, -0.5f, 1.5f);
      l.v = uniform(rng, -0.5f, 1.5f);
      const float scale = std::pow(10.0f, uniform(rng, -3, 0));
      l.dudx = scale * uniform(rng, -1, 1);
      l.dvdx = scale * uniform(rng, -1, 1);
      l.dudy = scale * uniform(rng, -1, 1);
      l.dvdy = scale * uniform(rng, -1, 1);
      lookups.push_back(l);
    }
    // Every filter at both bands, and each of those meets both storages, in eight of the sixteen
    // variants: each is a build of seconds on PoCL, and storage only changes how a texel is fetched.
    int band_index = 0;
    for (int band : {1, 4}) {
      int filter_index = 0;
      for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
        const TexelFormat format = (band_index + filter_index++) % 2 == 0 ? TexelFormat::Rgba8 : TexelFormat::Rgba32f;
        const PackedScene packed = pack_scene(scene, format, band);
        TextureLookups device(shared_runtime(), packed);
        device.set_lookups(lookups);
        SCOPED_TRACE(testing::Message() << name << " band " << band << " " << to_string(format) << " "
                                        << to_string(filter));
        const SamplerParams sampler = sampler_params(Method::Guardband, filter, 8, ZeroCoverage::Clamp, band);
        const std::vector<glm::vec4> gpu = device.sample(sampler);
        EXPECT_EQ(twin_colour_mismatches(gpu, packed, sampler, lookups,
                                                       [](float a, float b) { return std::fabs(a - b) <= 1e-5f; }),
                  0u);
        // A sampler whose band differs from the packing is refused, not read out of bounds.
        EXPECT_THROW(device.sample(sampler_params(Method::Clamp, Filter::Trilinear, 8, ZeroCoverage::Clamp)),
                     std::logic_error);
      }
      ++band_index;
    }
  }
}

namespace {

// Two unit quads side by side (face 0 left, face 1 right, sharing the edge x = 1), level 0 of
// face 0 `left` texels square and of face 1 `right`, every texel distinct.
Scene two_quads(int left, int right) {
  Scene scene;
  scene.name = "two_quads";
  for (int j = 0; j <= 1; ++j) {
    for (int i = 0; i <= 2; ++i) scene.positions.emplace_back(static_cast<float>(i), static_cast<float>(j), 0.0f);
  }
  for (int f = 0; f < 2; ++f) {
    Face face;
    const uint32_t i = static_cast<uint32_t>(f);
    face.vertices = {i, i + 1, i + 4, i + 3};
    scene.faces.push_back(std::move(face));
  }
  seamcl_tests::set_textures(scene, {{left, left}, {right, right}}, seamcl_tests::distinct_texel);
  scene.camera.eye = {1, 0.5f, 3};
  scene.camera.target = {1, 0.5f, 0};
  return scene;
}

void expect_near(glm::vec4 got, glm::vec4 expected, const std::string& where) {
  EXPECT_LT(glm::length(got - expected), 1e-6f) << where << ": got " << got.r << "," << got.g << " expected "
                                                << expected.r << "," << expected.g;
}

// Every face one colour of its own.
glm::vec4 face_colour(size_t face, int, int) {
  return {static_cast<float>(face % 7) / 7.0f, static_cast<float>(face / 7) / 7.0f, 0.5f, 1.0f};
}

}  // namespace

TEST(GuardBand, FinerNeighboursAreBoxFilteredToTheBandsTexelDensity) {
  constexpr int band = 2;
  // A 1x1 face beside a 256x256 one: its band texel (one face wide) is that face's mean, the
  // 1x1 level of its chain, not one of its texels.
  {
    const Scene scene = two_quads(1, 256);
    const TextureLevel padded = guard_banded_level(scene, build_adjacency(scene), 0, 0, band);
    expect_near(padded.at(band + 1, band), scene.faces[1].texture.levels.back().at(0, 0), "1x1 beside 256x256");
  }
  // 4x4 beside 16x16: each band texel is the 4x4 block of the neighbour's texels it covers,
  // which is its level 2; and at level 1 (2x2 beside it) the neighbour's level 3.
  {
    const Scene scene = two_quads(4, 16);
    const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
    const TextureLevel level0 = guard_banded_level(scene, adjacency, 0, 0, band);
    const TextureLevel level1 = guard_banded_level(scene, adjacency, 0, 1, band);
    for (int k = 0; k < band; ++k) {
      for (int j = 0; j < 4; ++j) {
        expect_near(level0.at(band + 4 + k, band + j), scene.faces[1].texture.levels[2].at(k, j), "4x4 beside 16x16");
      }
      for (int j = 0; j < 2; ++j) {
        expect_near(level1.at(band + 2 + k, band + j), scene.faces[1].texture.levels[3].at(k, j), "level 1");
      }
    }
  }
}

TEST(GuardBand, CoarserNeighboursAreInterpolatedAtTheBandTexelsCentre) {
  // 16x16 beside 4x4: band texel (16, j) stands for the neighbour's uv (1/32, (j + .5) / 16):
  // its level 0 interpolated there (clamped to its first column), as a lookup of it would be.
  constexpr int band = 1;
  const Scene scene = two_quads(16, 4);
  const TextureLevel padded = guard_banded_level(scene, build_adjacency(scene), 0, 0, band);
  const TextureLevel& neighbour = scene.faces[1].texture.levels[0];
  for (int j = 0; j < 16; ++j) {
    const float y = std::clamp((static_cast<float>(j) + 0.5f) / 16.0f * 4.0f - 0.5f, 0.0f, 3.0f);
    const int row = static_cast<int>(y);
    const float t = y - static_cast<float>(row);
    const glm::vec4 expected = neighbour.at(0, row) * (1.0f - t) + neighbour.at(0, std::min(row + 1, 3)) * t;
    expect_near(padded.at(band + 16, band + j), expected, "row " + std::to_string(j));
  }
}

TEST(GuardBand, CornerBandsAtEveryValenceAndAtBoundaries) {
  // Faces of one colour each, so a corner band texel shows which faces filled it: the diagonal
  // face at valence 4; at valence 5 the mean of the faces that share only the vertex; at valence
  // 3 and at boundary vertices the mean of the two edges' continuations (the face across each
  // edge, or this face where there is none).
  Scene prism = seamcl_tests::split_pentagonal_prism();
  Scene box = seamcl_tests::subdivided_cube(2);
  box.faces.erase(box.faces.begin() + 4, box.faces.begin() + 8);
  std::set<int> valences_seen;
  size_t boundary_corners = 0;
  for (Scene* scene : {&prism, &box}) {
    seamcl_tests::set_textures(*scene, {{4, 4}, {2, 8}, {1, 1}, {16, 16}}, face_colour);
    const std::vector<FaceNeighbors> adjacency = build_adjacency(*scene);
    auto colour = [&](int face) { return scene->faces[static_cast<size_t>(face)].texture.levels[0].at(0, 0); };
    for (uint32_t f = 0; f < scene->faces.size(); ++f) {
      constexpr int band = 2;
      const TextureLevel padded = guard_banded_level(*scene, adjacency, f, 0, band);
      const int w = scene->faces[f].texture.width(), h = scene->faces[f].texture.height();
      // The band texel next to each corner, outside both edges.
      const int corner_i[4] = {band - 1, band + w, band + w, band - 1};
      const int corner_j[4] = {band - 1, band - 1, band + h, band + h};
      for (int k = 0; k < 4; ++k) {
        const VertexRing ring = corner_ring(*scene, adjacency, f, k);
        glm::vec4 expected(0.0f);
        if (ring.valence() == 4) {
          expected = colour(static_cast<int>(ring.faces[1].face));
        } else if (ring.valence() >= 5) {
          for (int i = 1; i + 2 < ring.valence(); ++i) expected += colour(static_cast<int>(ring.faces[static_cast<size_t>(i)].face));
          expected /= static_cast<float>(ring.valence() - 3);
        } else {
          boundary_corners += !ring.closed;
          for (int e : {(k + 3) % 4, k}) {
            const int other = adjacency[f].neighbor[e];
            expected += colour(other >= 0 ? other : static_cast<int>(f)) * 0.5f;
          }
        }
        valences_seen.insert(ring.valence());
        expect_near(padded.at(corner_i[k], corner_j[k]), expected,
                    scene->name + " face " + std::to_string(f) + " corner " + std::to_string(k) + " valence " +
                        std::to_string(ring.valence()));
      }
    }
  }
  EXPECT_EQ(valences_seen, (std::set<int>{0, 3, 4, 5}));
  EXPECT_GT(boundary_corners, 0u);
}

namespace {

// The same scene with every texture deferred to a source that hands out the baked chains, and
// counts how often each face's chain is made.
Scene deferred_copy(const Scene& baked, std::shared_ptr<std::vector<std::atomic<int>>> made = nullptr) {
  Scene deferred = baked;
  for (Face& face : deferred.faces) face.texture = deferred_mip_chain(face.texture.width(), face.texture.height());
  auto chains = std::make_shared<std::vector<MipChain>>();
  for (const Face& face : baked.faces) chains->push_back(face.texture);
  deferred.texture_source = [chains, made](size_t f) {
    if (made) ++(*made)[f];
    return (*chains)[f];
  };
  return deferred;
}

}  // namespace

TEST(GuardBand, DeferredScenesBandFromEdgeStripsToTheBakedBits) {
  // Packing a deferred scene keeps only the strips of its faces that bands read: the bands must
  // come out bit for bit as from the whole chains, at every valence, at boundaries, beside
  // anisotropic, finer and coarser neighbours and turned faces, for narrow and wide bands, and
  // each face's chain must be made once.
  Scene prism = seamcl_tests::split_pentagonal_prism();
  Scene box = seamcl_tests::subdivided_cube(2);
  box.faces.erase(box.faces.begin() + 4, box.faces.begin() + 8);
  Scene cube = seamcl_tests::subdivided_cube(3);
  std::vector<Scene> scenes;
  for (Scene* scene : {&prism, &box, &cube}) {
    seamcl_tests::set_textures(*scene, seamcl_tests::mixed_texture_sizes(), seamcl_tests::distinct_texel);
    scenes.push_back(*scene);
  }
  scenes.push_back(seamcl_tests::turn_face(seamcl_tests::turn_face(cube, 4, 1, false), 10, 3, false));
  for (const Scene& baked : scenes) {
    for (int band : {1, 4, kMaxGuardBand}) {
      for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
        SCOPED_TRACE(baked.name + " band " + std::to_string(band) + " " + to_string(format));
        auto made = std::make_shared<std::vector<std::atomic<int>>>(baked.faces.size());
        const Scene deferred = deferred_copy(baked, made);
        const PackedScene expected = pack_scene(baked, format, band);
        const PackedScene packed = pack_scene(deferred, format, band);
        EXPECT_EQ(packed.level_offsets, expected.level_offsets);
        EXPECT_TRUE(packed.texels8 == expected.texels8);
        ASSERT_EQ(packed.texels32.size(), expected.texels32.size());
        EXPECT_EQ(std::memcmp(packed.texels32.data(), expected.texels32.data(), packed.texels32.size() * sizeof(float)), 0);
        for (size_t f = 0; f < made->size(); ++f) EXPECT_EQ((*made)[f].load(), 1) << "face " << f;
      }
    }
  }
}

TEST(GuardBand, BandsReadStripsAboutABandDeepAtEqualDensity) {
  // A closed cube of 64x64 faces: at level 0 the bands of 4 read 4 texels deep into each
  // neighbour (the band's texels are the neighbour's own); the coarsest levels are read whole.
  // The strips hold those texels exactly as the chain does, and far fewer of them.
  constexpr int band = 4;
  Scene cube = seamcl_tests::subdivided_cube(2);
  seamcl_tests::set_textures(cube, {{64, 64}}, seamcl_tests::distinct_texel);
  const std::vector<std::vector<int>> depths = band_read_depths(cube, build_adjacency(cube), band);
  ASSERT_EQ(depths.size(), cube.faces.size());
  size_t chain_texels = 0;
  for (const TextureLevel& level : cube.faces[0].texture.levels) chain_texels += level.texels.size();
  for (size_t f = 0; f < cube.faces.size(); ++f) {
    SCOPED_TRACE("face " + std::to_string(f));
    const MipChain& chain = cube.faces[f].texture;
    ASSERT_EQ(depths[f].size(), chain.levels.size());
    EXPECT_EQ(depths[f][0], band);
    EXPECT_EQ(depths[f][1], band);
    EXPECT_GE(2 * depths[f].back(), 1);  // the 1x1 level is read
    const EdgeStrips strips(chain, depths[f]);
    EXPECT_LT(strips.texel_count() * 3, chain_texels);
    for (size_t l = 0; l < chain.levels.size(); ++l) {
      const TextureLevel& level = chain.levels[l];
      for (int j = 0; j < level.height; ++j) {
        for (int i = 0; i < level.width; ++i) {
          const int from_edge = std::min(std::min(i, level.width - 1 - i), std::min(j, level.height - 1 - j));
          if (from_edge < depths[f][l]) {
            ASSERT_EQ(strips.at(l, i, j), level.at(i, j)) << "level " << l << " texel " << i << "," << j;
          } else {
            EXPECT_THROW(strips.at(l, i, j), std::logic_error) << "level " << l << " texel " << i << "," << j;
          }
        }
      }
    }
    EXPECT_THROW(strips.at(0, 64, 0), std::logic_error);
  }
  // Anisotropic faces read deeper: a 4x64 face beside a 64x64 one, sharing its long edge, has
  // band texels a quarter of the face deep, which reach 16 texels into the square neighbour.
  Scene pair = two_quads(4, 64);
  seamcl_tests::set_textures(pair, {{4, 64}, {64, 64}}, seamcl_tests::distinct_texel);
  EXPECT_EQ(band_read_depths(pair, build_adjacency(pair), 1)[1][0], 16);
}
