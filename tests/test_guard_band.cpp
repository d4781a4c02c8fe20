// Guard bands (McDonald and Burley 2011): the bands hold the neighbours' texels, the kernels
// read them as their twin does, and they cost the memory reported.
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/pipeline/render_options.h>
#include <seamcl/pipeline/texture_lookups.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/adjacency.h"
#include "pipeline/guard_band.h"
#include "twins/texture_sample.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

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
    for (int band : {1, 4}) {
      for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
        const PackedScene packed = pack_scene(scene, format, band);
        TextureLookups device(shared_runtime(), packed);
        device.set_lookups(lookups);
        for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
          SCOPED_TRACE(testing::Message() << name << " band " << band << " " << to_string(format) << " "
                                          << to_string(filter));
          const SamplerParams sampler = sampler_params(Method::Guardband, filter, 8, ZeroCoverage::Clamp, band);
          const std::vector<glm::vec4> gpu = device.sample(sampler);
          size_t bad = 0;
          for (size_t i = 0; i < lookups.size(); ++i) {
            const Lookup& l = lookups[i];
            const glm::vec4 twin =
                sample_texture_reference(packed.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
            bool ok = true;
            for (int c = 0; c < 4; ++c) ok &= std::fabs(gpu[i][c] - twin[c]) <= 1e-5f;
            if (!ok && bad++ < 3) ADD_FAILURE() << "lookup " << i << ": gpu " << gpu[i].r << " twin " << twin.r;
          }
          EXPECT_EQ(bad, 0u);
        }
        // A sampler whose band differs from the packing is refused, not read out of bounds.
        EXPECT_THROW(device.sample(sampler_params(Method::Clamp, Filter::Trilinear, 8, ZeroCoverage::Clamp)),
                     std::logic_error);
      }
    }
  }
}
