// The cube-map lookup (kernels/cube_sample.cl) against its twin for every method and filter, and
// what the methods promise at the cube's edges: direction pairs straddling each of the 12 edges
// and 8 corners converge for seamless, stretch, warp and fixup and not for clamp; the fixup lands
// on stretch-baked texel centres at integer lods; a constant environment stays exact; the edge
// measures (host/eval/cube_metrics.h) tell the methods apart in zero and first order.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <seamcl/eval/cube_metrics.h>
#include <seamcl/pipeline/cube_lookups.h>
#include <seamcl/pipeline/packed_cube.h>
#include "test_support.h"
#include "pipeline/stages/cube_sample_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

const CubeMethod kAllMethods[] = {CubeMethod::Clamp,   CubeMethod::Seamless,   CubeMethod::Stretch, CubeMethod::Warp,
                                  CubeMethod::Fixup,   CubeMethod::Discard,    CubeMethod::FixupLevel,
                                  CubeMethod::Fov,     CubeMethod::Average,    CubeMethod::Border};

// The method's cube of `radiance`, as the renderer prepares it, and its lookups.
struct MethodCube {
  CubeMap cube;
  std::vector<float> texels;
  CubeLookups lookups;
  MethodCube(CubeMethod method, const DirectionFunction& radiance, int n, int samples = 1)
      : cube(bake_cube_for(method, radiance, n, samples)),
        texels(pack_cube_texels(cube, cube_preparation(method).border)),
        lookups(shared_runtime(), cube, cube_preparation(method).border) {}
};

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
    const std::vector<CubeLookup> batch = random_lookups(rng, 600);
    for (bool border : {false, true}) {
    const std::vector<float> texels = pack_cube_texels(cube, border);
    CubeLookups lookups(shared_runtime(), cube, border);
    for (CubeMethod method : kAllMethods) {
      if (cube_preparation(method).border != border) continue;  // each layout is read by its methods only
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
  std::vector<float> clamp_jumps, fov_jumps;
  for (CubeMethod method : kAllMethods) {
    MethodCube prepared(method, gradient, n);
    const std::vector<glm::vec4> values = level0(prepared.lookups, directions, method, n);
    float worst = 0.0f, least = INFINITY;
    std::vector<float> jumps;
    for (size_t i = 0; i < edge_directions; i += 2) jumps.push_back(distance(values[i], values[i + 1]));
    for (size_t i = edge_directions; i < directions.size(); i += 3) {
      jumps.push_back(std::max(distance(values[i], values[i + 1]), distance(values[i], values[i + 2])));
    }
    for (float jump : jumps) {
      worst = std::max(worst, jump);
      least = std::min(least, jump);
    }
    if (method == CubeMethod::Clamp) clamp_jumps = jumps;
    if (method == CubeMethod::Fov) {
      fov_jumps = jumps;
      continue;  // below: against clamp's
    }
    const bool seamless = method != CubeMethod::Clamp && method != CubeMethod::Discard;
    if (seamless) {
      EXPECT_LT(worst, 1e-4f) << to_string(method);
    } else {
      // A whole texel's worth of the gradient (2/n of the face, times 0.5 per unit) at every edge.
      EXPECT_GT(least, 0.01f) << to_string(method);
    }
  }
  // The post's FOV leaves each face's edge texel centre 1/4 of its texel (0.5 / (n - 0.5) of the
  // face) short of the edge where clamp's is 1 / n short: about half of clamp's seam stays.
  // 0.5 n / (n - 0.5) = 0.52 of clamp's at every edge and corner.
  ASSERT_EQ(fov_jumps.size(), clamp_jumps.size());
  for (size_t i = 0; i < fov_jumps.size(); ++i) {
    EXPECT_GT(fov_jumps[i], 0.45f * clamp_jumps[i]) << i;
    EXPECT_LT(fov_jumps[i], 0.6f * clamp_jumps[i]) << i;
  }
}

TEST(CubeSample, FovLookupsReadEachTexelAtTheDirectionItWasBakedFrom) {
  const int n = 16;
  const CubeMap cube = bake_cube_map(gradient, n, CubeBake::Fov);
  CubeLookups lookups(shared_runtime(), cube);
  std::vector<CubeLookup> batch;
  std::vector<glm::vec4> expected;
  for (int level = 0; level < cube.level_count(); ++level) {
    const int m = n >> level;
    for (int f = 0; f < kCubeFaces; ++f) {
      for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
          // Each level spreads its texel centres by its own m / (m - 0.5): the lookup's scale
          // must be that level's, or a texel is read from another level's direction.
          const glm::vec3 d =
              cube_direction(f, cube_map_fov(static_cast<float>(i), m), cube_map_fov(static_cast<float>(j), m));
          batch.push_back({d, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, static_cast<float>(level)});
          expected.push_back(cube.faces[f].levels[level].at(i, j));
        }
      }
    }
  }
  const std::vector<glm::vec4> values = lookups.sample(batch, cube_sampler(CubeMethod::Fov, Filter::Trilinear, 16, n));
  for (size_t k = 0; k < batch.size(); ++k) EXPECT_LT(distance(values[k], expected[k]), 1e-4f) << k;
}

TEST(CubeSample, FixupLevelClosesTheSeamAtFractionalLodsWhereOneScaleLeavesOne) {
  const int n = 16;
  const CubeMap cube = bake_cube_map(gradient, n, CubeBake::Stretch);
  CubeLookups lookups(shared_runtime(), cube);
  std::vector<CubeLookup> batch;
  for (float lod : {0.5f, 1.5f}) {
    for (const auto& [a, b] : edge_pairs(1e-5f, 0.3f)) {
      batch.push_back({a, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, lod});
      batch.push_back({b, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, lod});
    }
  }
  auto worst_jump = [&](CubeMethod method) {
    const std::vector<glm::vec4> values = lookups.sample(batch, cube_sampler(method, Filter::Trilinear, 16, n));
    float worst = 0.0f;
    for (size_t i = 0; i < values.size(); i += 2) worst = std::max(worst, distance(values[i], values[i + 1]));
    return worst;
  };
  // One scale, 1 - exp2(lod) / n, lands neither level's edge texel on the edge at lod 0.5: the
  // finer level reads a fraction of the texel inside, which differs between the faces.
  EXPECT_GT(worst_jump(CubeMethod::Fixup), 1e-3f);
  EXPECT_LT(worst_jump(CubeMethod::FixupLevel), 1e-4f);
}

TEST(CubeSample, BorderReadsWhatSeamlessReadsWithinATexelOfTheEdge) {
  std::mt19937 rng(23);
  const int n = 8;
  const DirectionFunction noise = [&](glm::vec3) {
    return glm::vec4(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1), 1.0f);
  };
  const CubeMap cube = bake_cube_map(noise, n, CubeBake::Centres);
  CubeLookups plain(shared_runtime(), cube), bordered(shared_runtime(), cube, true);
  // Single-probe lookups (explicit lod) near edges and corners: every tap within one texel out.
  // Levels down to 2 x 2: at 1 x 1 seamless clamps its tap coordinate to 2 m - 2 = 0 and so never
  // reads the neighbours right of or below the face, where the border does.
  std::vector<CubeLookup> batch;
  for (int k = 0; k < 300; ++k) {
    glm::vec3 d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    d[k % 3] = d[k % 3] < 0 ? -1.0f : 1.0f;
    d[(k + 1) % 3] = (d[(k + 1) % 3] < 0 ? -1.0f : 1.0f) * uniform(rng, 0.9f, 1.0f);
    if (k % 4 == 0) d[(k + 2) % 3] = (d[(k + 2) % 3] < 0 ? -1.0f : 1.0f) * uniform(rng, 0.9f, 1.0f);
    batch.push_back({d, glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, uniform(rng, 0.0f, 1.99f)});
  }
  const std::vector<glm::vec4> seamless = plain.sample(batch, cube_sampler(CubeMethod::Seamless, Filter::Trilinear, 16, n));
  const std::vector<glm::vec4> border = bordered.sample(batch, cube_sampler(CubeMethod::Border, Filter::Trilinear, 16, n));
  for (size_t k = 0; k < batch.size(); ++k) EXPECT_LT(distance(seamless[k], border[k]), 1e-5f) << k;
  // The price: every level of every face one texel wider on each side (+42% at n = 16).
  EXPECT_EQ(cube_bytes(CubeMethod::Border, n), cube_texel_count(n, true) * 16);
  EXPECT_EQ(cube_bytes(CubeMethod::Clamp, n), cube.texel_count() * 16);
  EXPECT_EQ(pack_cube_texels(cube, true).size(), cube_texel_count(n, true) * 4);
}

TEST(CubeEdgeMeasures, FirstOrderBandSeesTheFlatBandTheZeroOrderStepDoesNot) {
  // The default analytic sky at n = 16, 8 points per edge.
  const Environment sky;
  auto measure = [&](CubeMethod method) { return measure_cube_edges(shared_runtime(), sky, method, 16, 8); };
  const EdgeMeasures clamp = measure(CubeMethod::Clamp), stretch = measure(CubeMethod::Stretch),
                     seamless = measure(CubeMethod::Seamless), fixup = measure(CubeMethod::Fixup);
  // Stretch has no zero-order seam at lod 0 ...
  EXPECT_LT(stretch.seam_step_mean[0], 1e-6);
  EXPECT_GT(clamp.seam_step_mean[0], 1e-3);
  // ... and keeps clamp's flat band: lookups constant over the last half texel of each face,
  // about half the environment's own slope there, twice seamless's and more than fixup's.
  EXPECT_GT(stretch.first_order_band, 0.9 * clamp.first_order_band);
  EXPECT_GT(stretch.first_order_band, 0.35 * stretch.environment_band_slope);
  EXPECT_GT(stretch.first_order_band, 1.8 * seamless.first_order_band);
  EXPECT_LT(fixup.first_order_band, seamless.first_order_band);
  // Half lods: the post's one fixup scale leaves a step, the per-level scale none.
  const EdgeMeasures fixup_level = measure(CubeMethod::FixupLevel);
  ASSERT_EQ(fixup.seam_step_half_lod.size(), 4u);
  EXPECT_GT(fixup.seam_step_half_lod[0], 1e-3);
  EXPECT_LT(fixup_level.seam_step_half_lod[0], 1e-4);
  // The costs: bytes of the packed cube.
  EXPECT_EQ(measure(CubeMethod::Border).cube_bytes, cube_texel_count(16, true) * 16);
  EXPECT_EQ(clamp.cube_bytes, cube_texel_count(16, false) * 16);
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
    MethodCube prepared(method, [&](glm::vec3) { return c; }, 32, 2);
    CubeLookups& lookups = prepared.lookups;
    for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso}) {
      const std::vector<glm::vec4> values = lookups.sample(batch, cube_sampler(method, filter, 16, 32));
      float worst = 0.0f;
      for (const glm::vec4& v : values) worst = std::max(worst, glm::length(v - c));
      // Exact up to the rounding of the bilinear weights' sum (a few ulps).
      EXPECT_LT(worst, 4e-7f) << to_string(method) << " " << to_string(filter);
    }
  }
}
