// The cube-map lookup (kernels/cube_sample.cl) against its twin for every method and filter, and
// what the methods promise at the cube's edges: direction pairs straddling each of the 12 edges
// and 8 corners converge for seamless, stretch, warp and fixup and not for clamp; the fixup lands
// on stretch-baked texel centres at integer lods; a constant environment stays exact.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <seamcl/pipeline/cube_lookups.h>
#include <seamcl/pipeline/packed_cube.h>
#include "test_support.h"
#include "pipeline/stages/cube_sample_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

const CubeMethod kAllMethods[] = {CubeMethod::Clamp, CubeMethod::Seamless, CubeMethod::Stretch,
                                  CubeMethod::Warp,  CubeMethod::Fixup,    CubeMethod::Discard};

// A smooth environment with a gradient everywhere, so a zero-order seam always shows.
glm::vec4 gradient(glm::vec3 d) { return {0.5f + 0.5f * d.x, 0.5f + 0.5f * d.y, 0.5f + 0.5f * d.z, 1.0f}; }

float distance(glm::vec4 a, glm::vec4 b) { return glm::length(glm::vec3(a - b)); }

// Directions anywhere, near edges and corners, plus zero and non-finite ones; derivatives from
// zero to huge, any orientation.
std::vector<CubeLookup> random_lookups(std::mt19937& rng, int count) {
  std::vector<CubeLookup> out;
  for (int i = 0; i < count; ++i) {
    CubeLookup l;
    l.direction = {uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1)};
    if (i % 3 == 0) {  // on or near an edge or corner
      l.direction.x = l.direction.x < 0 ? -1.0f : 1.0f;
      l.direction.y = (l.direction.y < 0 ? -1.0f : 1.0f) * uniform(rng, 0.98f, 1.0f);
      if (i % 9 == 0) l.direction.z = (l.direction.z < 0 ? -1.0f : 1.0f) * uniform(rng, 0.98f, 1.0f);
    }
    const float scale = i % 13 == 0 ? 0.0f : std::pow(10.0f, uniform(rng, -5, 0));
    l.ddx = scale * glm::vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    l.ddy = scale * uniform(rng, 0.05f, 1.0f) * glm::vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    l.roughness = i % 4 == 0 ? uniform(rng, 0, 0.5f) : 0.0f;
    l.explicit_lod = i % 7 == 0 ? uniform(rng, 0, 6) : -1.0f;
    out.push_back(l);
  }
  out.push_back({{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}});
  out.push_back({{NAN, 1, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}});
  out.push_back({{1, 1, 1}, {INFINITY, 0, 0}, {0, 0, 0}});
  out.push_back({{1, 1, 1}, {0, 0, 0}, {0, 0, 0}});
  out.push_back({{-1, -1, -1}, {0.3f, 0, 0}, {0, 0.3f, 0}, 0.0f, 2.5f});
  return out;
}

// Lookups at level 0 (explicit lod 0: bilinear) of each direction.
std::vector<glm::vec4> level0(CubeLookups& lookups, const std::vector<glm::vec3>& directions, CubeMethod method,
                              int size) {
  std::vector<CubeLookup> batch;
  for (glm::vec3 d : directions) batch.push_back({d, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, 0.0f});
  return lookups.sample(batch, cube_sampler(method, Filter::Trilinear, 16, size));
}

// Every edge of the cube: the components a, b at +-1 and the third one at `along`; the two
// directions straddle it, eps inside each face.
std::vector<std::pair<glm::vec3, glm::vec3>> edge_pairs(float eps, float along) {
  std::vector<std::pair<glm::vec3, glm::vec3>> out;
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      const int c = 3 - a - b;
      for (float sa : {-1.0f, 1.0f}) {
        for (float sb : {-1.0f, 1.0f}) {
          glm::vec3 on_a(0.0f), on_b(0.0f);
          on_a[a] = sa;
          on_a[b] = sb * (1.0f - eps);
          on_a[c] = along;
          on_b = on_a;
          on_b[a] = sa * (1.0f - eps);
          on_b[b] = sb;
          out.emplace_back(on_a, on_b);
        }
      }
    }
  }
  return out;
}

}  // namespace

TEST(CubeSample, KernelMatchesTwinForEveryMethodAndFilter) {
  std::mt19937 rng(4);
  for (int size : {1, 16}) {
    const CubeMap cube = bake_cube_map(
        [&](glm::vec3) { return glm::vec4(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1), 1.0f); }, size,
        CubeBake::Centres);
    const std::vector<float> texels = pack_cube_texels(cube);
    CubeLookups lookups(shared_runtime(), cube);
    const std::vector<CubeLookup> batch = random_lookups(rng, 600);
    for (CubeMethod method : kAllMethods) {
      for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso}) {
        const CubeSampler sampler = cube_sampler(method, filter, 8, size);
        const std::vector<glm::vec4> gpu = lookups.sample(batch, sampler);
        int mismatches = 0;
        for (size_t i = 0; i < batch.size(); ++i) {
          const CubeLookup& l = batch[i];
          const glm::vec4 twin =
              sample_cube_reference(texels, sampler, l.direction, l.ddx, l.ddy, l.roughness, l.explicit_lod);
          ASSERT_TRUE(std::isfinite(gpu[i].r) && std::isfinite(gpu[i].a)) << to_string(method) << " lookup " << i;
          if (glm::length(gpu[i] - twin) > 2e-5f) ++mismatches;
        }
        EXPECT_EQ(mismatches, 0) << to_string(method) << " " << to_string(filter) << " size " << size;
      }
    }
  }
}

TEST(CubeSample, EdgeAndCornerStraddlingDirectionsConvergeExceptForClamp) {
  const int n = 16;
  std::vector<glm::vec3> directions;
  for (const auto& [a, b] : edge_pairs(1e-5f, 0.3f)) directions.insert(directions.end(), {a, b});
  const size_t edge_directions = directions.size();
  ASSERT_EQ(edge_directions, 24u);
  // The 8 corners, approached from each of their three faces.
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 sign(corner & 1 ? 1.0f : -1.0f, corner & 2 ? 1.0f : -1.0f, corner & 4 ? 1.0f : -1.0f);
    for (int major = 0; major < 3; ++major) {
      glm::vec3 d = sign * (1.0f - 1e-5f);
      d[major] = sign[major];
      directions.push_back(d);
    }
  }
  for (CubeMethod method : kAllMethods) {
    const CubeMap cube = bake_cube_map(gradient, n, cube_bake(method));
    CubeLookups lookups(shared_runtime(), cube);
    const std::vector<glm::vec4> values = level0(lookups, directions, method, n);
    float worst = 0.0f, least = INFINITY;
    for (size_t i = 0; i < edge_directions; i += 2) {
      const float jump = distance(values[i], values[i + 1]);
      worst = std::max(worst, jump);
      least = std::min(least, jump);
    }
    for (size_t i = edge_directions; i < directions.size(); i += 3) {
      const float jump = std::max(distance(values[i], values[i + 1]), distance(values[i], values[i + 2]));
      worst = std::max(worst, jump);
      least = std::min(least, jump);
    }
    const bool seamless = method != CubeMethod::Clamp && method != CubeMethod::Discard;
    if (seamless) {
      EXPECT_LT(worst, 1e-4f) << to_string(method);
    } else {
      // A whole texel's worth of the gradient (2/n of the face, times 0.5 per unit) at every edge.
      EXPECT_GT(least, 0.01f) << to_string(method);
    }
  }
}

TEST(CubeSample, SeamlessCornerIsTheMeanOfThreeEqualTexels) {
  // The rule only, where every implementation agrees: three equal corner texels give that value.
  const int n = 4;
  const glm::vec4 corner_value(0.2f, 0.4f, 0.6f, 1.0f);
  // Every texel that touches a cube corner holds corner_value; the others hold something else.
  const CubeMap cube = bake_cube_map(
      [&](glm::vec3 d) {
        const float m = std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)});
        const glm::vec3 p = d / m;
        const float edge = 1.0f - 2.0f / n;  // beyond this, a component is in the last texel row
        const int past = (std::fabs(p.x) > edge) + (std::fabs(p.y) > edge) + (std::fabs(p.z) > edge);
        return past == 3 ? corner_value : glm::vec4(0.9f, 0.1f, 0.1f, 1.0f);
      },
      n, CubeBake::Centres);
  CubeLookups lookups(shared_runtime(), cube);
  std::vector<glm::vec3> corners;
  for (int corner = 0; corner < 8; ++corner) {
    corners.emplace_back(corner & 1 ? 1.0f : -1.0f, corner & 2 ? 1.0f : -1.0f, corner & 4 ? 1.0f : -1.0f);
  }
  const std::vector<glm::vec4> values = level0(lookups, corners, CubeMethod::Seamless, n);
  for (size_t i = 0; i < corners.size(); ++i) EXPECT_LT(glm::length(values[i] - corner_value), 1e-6f) << i;
}

TEST(CubeSample, FixupLandsOnStretchBakedTexelCentresAtIntegerLods) {
  const int n = 16;
  const CubeMap cube = bake_cube_map(gradient, n, CubeBake::Stretch);
  CubeLookups lookups(shared_runtime(), cube);
  std::vector<CubeLookup> batch;
  std::vector<glm::vec4> expected;
  for (int level = 0; level < cube.level_count(); ++level) {
    const int m = n >> level;
    for (int f = 0; f < kCubeFaces; ++f) {
      for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
          // The direction texel (i, j) was baked from, scaled by the fixup, is at texel coordinate (i, j).
          const glm::vec3 d = cube_direction(f, cube_map2(static_cast<float>(i), m), cube_map2(static_cast<float>(j), m));
          const CubeUv c = cube_project(d, glm::vec3(0.0f), glm::vec3(0.0f));
          if (c.face != f) continue;  // an edge texel whose direction another face selects (ties)
          const glm::vec2 uv = cube_fixup_uv(c.s, c.t, static_cast<float>(level), n);
          EXPECT_NEAR(uv.x * static_cast<float>(m) - 0.5f, static_cast<float>(i), 2e-4f);
          EXPECT_NEAR(uv.y * static_cast<float>(m) - 0.5f, static_cast<float>(j), 2e-4f);
          batch.push_back({d, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, static_cast<float>(level)});
          expected.push_back(cube.faces[f].levels[level].at(i, j));
        }
      }
    }
  }
  ASSERT_GT(batch.size(), 6u * 256);
  const std::vector<glm::vec4> values = lookups.sample(batch, cube_sampler(CubeMethod::Fixup, Filter::Trilinear, 16, n));
  for (size_t k = 0; k < batch.size(); ++k) EXPECT_LT(distance(values[k], expected[k]), 1e-4f) << k;
}

TEST(CubeSample, ConstantEnvironmentIsExactWithEveryMethod) {
  const glm::vec4 c(0.25f, 0.5f, 0.75f, 1.0f);
  std::mt19937 rng(9);
  const std::vector<CubeLookup> batch = random_lookups(rng, 400);
  for (CubeMethod method : kAllMethods) {
    const CubeMap cube = bake_cube_map([&](glm::vec3) { return c; }, 32, cube_bake(method), 2);
    CubeLookups lookups(shared_runtime(), cube);
    for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso}) {
      const std::vector<glm::vec4> values = lookups.sample(batch, cube_sampler(method, filter, 16, 32));
      float worst = 0.0f;
      for (const glm::vec4& v : values) worst = std::max(worst, glm::length(v - c));
      // Exact up to the rounding of the bilinear weights' sum (a few ulps).
      EXPECT_LT(worst, 4e-7f) << to_string(method) << " " << to_string(filter);
    }
  }
}
