// Cube maps on the host: the major-axis table, the bakes' maps (map_1, map_2, warp3) and what a
// baked cube holds.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <seamcl/core/input_error.h>
#include <seamcl/scene/cube_map.h>
#include <seamcl/scene/environment.h>
#include "test_support.h"

using namespace seamcl;
using seamcl_tests::uniform;

TEST(CubeMap, TheMajorAxisTableRoundTrips) {
  std::mt19937 rng(12);
  for (int k = 0; k < 2000; ++k) {
    const int face = static_cast<int>(rng() % 6);
    const float sc = uniform(rng, -0.999f, 0.999f), tc = uniform(rng, -0.999f, 0.999f);
    const float scale = uniform(rng, 0.1f, 10.0f);
    const CubeCoords c = cube_coords(scale * cube_direction(face, sc, tc));
    ASSERT_EQ(c.face, face);
    EXPECT_NEAR(c.sc, sc, 1e-6f);
    EXPECT_NEAR(c.tc, tc, 1e-6f);
  }
}

TEST(CubeMap, FacesFollowTheGlTable) {
  // GL 4.6 Table 8.19 for a few directions: face, sc/|ma|, tc/|ma|.
  const CubeCoords px = cube_coords({2.0f, 1.0f, 0.5f});
  EXPECT_EQ(px.face, 0);
  EXPECT_FLOAT_EQ(px.sc, -0.25f);
  EXPECT_FLOAT_EQ(px.tc, -0.5f);
  const CubeCoords ny = cube_coords({0.5f, -2.0f, 1.0f});
  EXPECT_EQ(ny.face, 3);
  EXPECT_FLOAT_EQ(ny.sc, 0.25f);
  EXPECT_FLOAT_EQ(ny.tc, -0.5f);
  const CubeCoords nz = cube_coords({0.5f, 1.0f, -2.0f});
  EXPECT_EQ(nz.face, 5);
  EXPECT_FLOAT_EQ(nz.sc, -0.25f);
  EXPECT_FLOAT_EQ(nz.tc, -0.5f);
}

TEST(CubeMap, TiesGoToXThenY) {
  EXPECT_EQ(cube_coords({1, 1, 1}).face, 0);
  EXPECT_EQ(cube_coords({-1, 1, 0.5f}).face, 1);
  EXPECT_EQ(cube_coords({0.5f, -1, 1}).face, 3);
  EXPECT_EQ(cube_coords({0, 0, 0}).face, 0);
  EXPECT_EQ(cube_coords({NAN, 0, 1}).face, 0);
}

TEST(CubeMap, WarpMapsTheLastTexelCentreToTheEdge) {
  // warp3(1 - 1/n) = 1: a = n^2 / (n - 1)^3 solves a x^3 + x = 1 at x = 1 - 1/n.
  for (int n = 2; n <= 2048; n *= 2) {
    const float x = 1.0f - 1.0f / static_cast<float>(n);
    EXPECT_NEAR(cube_warp3(x, n), 1.0f, 4e-7f) << n;
    EXPECT_NEAR(cube_warp3(-x, n), -1.0f, 4e-7f) << n;
    EXPECT_NEAR(cube_bake_coordinate(CubeBake::Warp, static_cast<float>(n - 1), n), 1.0f, 4e-7f) << n;
  }
}

TEST(CubeMap, StretchPutsTheEdgeTexelsOnTheEdges) {
  for (int n = 2; n <= 256; n *= 2) {
    EXPECT_EQ(cube_map2(0, n), -1.0f);
    EXPECT_EQ(cube_map2(static_cast<float>(n - 1), n), 1.0f);
    EXPECT_FLOAT_EQ(cube_map1(0, n), -1.0f + 1.0f / static_cast<float>(n));
  }
  EXPECT_EQ(cube_map2(0, 1), 0.0f);
}

TEST(CubeMap, BakesEveryLevelOfEveryFace) {
  const CubeMap cube = bake_cube_map([](glm::vec3 d) { return glm::vec4(d, 1.0f); }, 8, CubeBake::Centres);
  EXPECT_EQ(cube.level_count(), 4);
  EXPECT_EQ(cube.texel_count(), 6u * (64 + 16 + 4 + 1));
  for (int f = 0; f < kCubeFaces; ++f) {
    ASSERT_EQ(cube.faces[f].levels.size(), 4u);
    const TextureLevel& top = cube.faces[f].levels[0];
    // Texel (i, j) holds its centre's unit direction.
    for (int j = 0; j < 8; ++j) {
      for (int i = 0; i < 8; ++i) {
        const glm::vec3 expected = glm::normalize(cube_direction(f, cube_map1(static_cast<float>(i), 8),
                                                                 cube_map1(static_cast<float>(j), 8)));
        EXPECT_NEAR(glm::length(glm::vec3(top.at(i, j)) - expected), 0.0f, 1e-6f);
      }
    }
    // The 1x1 level is the face's centre direction: the major axis.
    const glm::vec3 centre(cube.faces[f].levels[3].at(0, 0));
    EXPECT_NEAR(glm::length(centre - cube_direction(f, 0, 0)), 0.0f, 1e-6f);
  }
}

TEST(CubeMap, StretchedEdgeTexelsAreSharedByBothFaces) {
  // +X's column 0 (sc = -1) is +Z's column n-1 (sc = +1), row for row, at every level.
  const CubeMap cube = bake_cube_map([](glm::vec3 d) { return glm::vec4(d, 1.0f); }, 16, CubeBake::Stretch);
  for (int level = 0; level < 4; ++level) {
    const TextureLevel& px = cube.faces[0].levels[level];
    const TextureLevel& pz = cube.faces[4].levels[level];
    for (int j = 0; j < px.height; ++j) EXPECT_EQ(px.at(0, j), pz.at(pz.width - 1, j)) << level << " " << j;
  }
}

TEST(CubeMap, AveragedEdgeTexelsAreEqualAcrossEveryEdgeAndCorner) {
  std::mt19937 rng(17);
  // Noise: neighbouring texels differ, so an average of the wrong texels shows.
  const CubeMap baked = bake_cube_map(
      [&](glm::vec3) { return glm::vec4(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1), 1.0f); }, 8,
      CubeBake::Centres);
  CubeMap averaged = baked;
  average_cube_edges(averaged);
  int edge_pairs = 0, corner_groups = 0;
  for (int level = 0; level < averaged.level_count(); ++level) {
    const int m = averaged.size >> level;
    for (int f = 0; f < kCubeFaces; ++f) {
      for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
          const glm::vec4 value = averaged.faces[f].levels[level].at(i, j);
          const std::vector<CubeTexel> partners = cube_edge_partners(f, m, i, j);
          if (partners.empty()) {
            EXPECT_EQ(value, baked.faces[f].levels[level].at(i, j)) << "interior texel changed";
            continue;
          }
          glm::vec4 mean = baked.faces[f].levels[level].at(i, j);
          for (const CubeTexel& p : partners) {
            // Bit for bit: a clamped lookup at the edge reads the same value from either face.
            EXPECT_EQ(averaged.faces[p.face].levels[level].at(p.i, p.j), value)
                << "level " << level << " face " << f << " (" << i << ", " << j << ") vs face " << p.face;
            mean += baked.faces[p.face].levels[level].at(p.i, p.j);
            if (m > 1) {
              // The partner is the texel across the edge: the two centres are half a texel either
              // side of it, at the same place along it (sqrt(2) / m apart in space).
              const glm::vec3 here = cube_direction(f, cube_map1(static_cast<float>(i), m), cube_map1(static_cast<float>(j), m));
              const glm::vec3 there =
                  cube_direction(p.face, cube_map1(static_cast<float>(p.i), m), cube_map1(static_cast<float>(p.j), m));
              EXPECT_NEAR(glm::length(here - there), std::sqrt(2.0f) / static_cast<float>(m), 1e-5f);
            }
          }
          mean /= static_cast<float>(partners.size() + 1);
          EXPECT_LT(glm::length(value - mean), 1e-6f);
          if (m > 1) (partners.size() == 1 ? edge_pairs : corner_groups) += 1;
        }
      }
    }
  }
  // 12 edges x (m - 2) texels x 2 faces, and 8 corners x 3 faces, summed over m = 8, 4, 2.
  EXPECT_EQ(edge_pairs, 24 * (6 + 2 + 0));
  EXPECT_EQ(corner_groups, 24 * 3);
}

TEST(CubeMap, PostsFovPutsEdgeTexelCentresAQuarterTexelShortOfTheEdge) {
  for (int n : {2, 16, 256}) {
    const float nf = static_cast<float>(n);
    // The post's FOV 2 atan(n / (n - 0.5)): the face plane spans n / (n - 0.5), texel centres
    // spread uniformly over it. The last one lands at (n - 1) / (n - 0.5), not at 1 ...
    EXPECT_NEAR(cube_map_fov(nf - 1.0f, n), (nf - 1.0f) / (nf - 0.5f), 1e-6f) << n;
    const float tweaked_texel = 2.0f / (nf - 0.5f);
    EXPECT_NEAR((1.0f - cube_map_fov(nf - 1.0f, n)) / tweaked_texel, 0.25f, 1e-4f) << n;
    EXPECT_NEAR(cube_map_fov(0.0f, n), -cube_map_fov(nf - 1.0f, n), 1e-6f) << n;
    // ... while the FOV 2 atan(n / (n - 1)) puts them on the edge, and that is map_2 (stretch).
    for (int x = 0; x < n; ++x) {
      EXPECT_NEAR(cube_map1(static_cast<float>(x), n) * nf / (nf - 1.0f), cube_map2(static_cast<float>(x), n), 1e-6f);
    }
  }
}

TEST(CubeMap, BorderedLayoutCountsEveryLevelsBorder) {
  // Faces hold 341 texels at n = 16 (16^2 + 8^2 + 4^2 + 2^2 + 1), bordered 18^2 + 10^2 + 6^2 + 4^2 + 3^2 = 485.
  EXPECT_EQ(cube_texel_count(16, false), 6u * 341);
  EXPECT_EQ(cube_texel_count(16, true), 6u * 485);
  EXPECT_EQ(cube_texel_count(1, true), 6u * 9);
  EXPECT_EQ(cube_texel_count(0, true), 0u);
}

TEST(CubeMap, RefusesSizesThatAreNotPowersOfTwo) {
  try {
    bake_cube_map([](glm::vec3) { return glm::vec4(1.0f); }, 12, CubeBake::Centres);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "cube_size");
    EXPECT_NE(std::string(e.what()).find("power of two"), std::string::npos);
  }
}

TEST(Environment, HasASunAHorizonAndAGradient) {
  const AnalyticEnvironment e;
  const glm::vec4 sun = environment_radiance(e, e.sun_direction);
  EXPECT_NEAR(sun.r, e.sun_color.r, 1e-4f);
  // The horizon is a step: just above and just below differ by the sky-ground contrast.
  const glm::vec4 above = environment_radiance(e, glm::normalize(glm::vec3(-1, 1e-4f, 0)));
  const glm::vec4 below = environment_radiance(e, glm::normalize(glm::vec3(-1, -1e-4f, 0)));
  EXPECT_GT(glm::length(glm::vec3(above - below)), 0.3f);
  const glm::vec4 zenith = environment_radiance(e, {0, 1, 0});
  EXPECT_NEAR(glm::length(glm::vec3(zenith) - e.zenith), 0.0f, 1e-4f);
  for (float x : {-1.0f, 0.0f, 1.0f}) {
    const glm::vec4 c = environment_radiance(e, glm::normalize(glm::vec3(x, 0.3f, -0.5f)));
    EXPECT_GE(std::min({c.r, c.g, c.b}), 0.0f);
    EXPECT_LE(std::max({c.r, c.g, c.b}), 1.0f);
    EXPECT_EQ(c.a, 1.0f);
  }
}

TEST(Environment, ValidationNamesTheField) {
  Environment e;
  e.cube_size = 48;
  try {
    validate_environment(e);
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "environment.cube_size");
  }
}
