// The sampler (kernels/texture_sample.cl) against its twin for every filter, address mode,
// storage, method and a range of mip-level biases, and the properties Discard rests on: a
// constant texture stays exactly constant, weights sum to one, nothing outside a face is read,
// NaN only where every tap is out.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <set>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/texture_lookups.h>
#include "core/srgb.h"
#include "test_support.h"
#include "pipeline/stages/texture_sample_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

// Faces side by side, each with its own texture; `fill` gives level 0's texel (face, i, j).
template <typename Fill>
Scene texture_scene(const std::vector<std::pair<int, int>>& sizes, Fill fill) {
  Scene scene;
  scene.name = "textures";
  for (size_t f = 0; f < sizes.size(); ++f) {
    const auto base = static_cast<uint32_t>(scene.positions.size());
    const float x = static_cast<float>(f) * 2.0f;
    scene.positions.insert(scene.positions.end(), {{x, 0, 0}, {x + 1, 0, 0}, {x + 1, 1, 0}, {x, 1, 0}});
    TextureLevel level{sizes[f].first, sizes[f].second, {}};
    for (int j = 0; j < level.height; ++j) {
      for (int i = 0; i < level.width; ++i) level.texels.push_back(fill(static_cast<int>(f), i, j));
    }
    Face face;
    face.vertices = {base, base + 1, base + 2, base + 3};
    face.texture = build_mip_chain(std::move(level));
    scene.faces.push_back(std::move(face));
  }
  return scene;
}

Scene random_texture_scene(uint32_t seed) {
  std::mt19937 rng(seed);
  return texture_scene({{64, 64}, {32, 8}, {1, 16}, {128, 32}, {1, 1}}, [&](int, int, int) {
    return glm::vec4(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0.5f, 1));
  });
}

// Coordinates near and far outside [0,1]^2, derivatives from zero through tiny to huge, any
// orientation; a few non-finite ones.
std::vector<Lookup> random_lookups(std::mt19937& rng, uint32_t faces, int count) {
  std::vector<Lookup> out;
  for (int i = 0; i < count; ++i) {
    Lookup l;
    l.face = rng() % faces;
    const bool far = i % 11 == 0;
    l.u = far ? uniform(rng, -50, 50) : uniform(rng, -0.3f, 1.3f);
    l.v = far ? uniform(rng, -50, 50) : uniform(rng, -0.3f, 1.3f);
    const float scale = i % 13 == 0 ? 0.0f : std::pow(10.0f, uniform(rng, -6, 1));
    const float angle = uniform(rng, 0, 6.2831853f);
    const float ratio = uniform(rng, 1, 24);
    l.dudx = std::cos(angle) * scale;
    l.dvdx = std::sin(angle) * scale;
    l.dudy = -std::sin(angle) * scale / ratio;
    l.dvdy = std::cos(angle) * scale / ratio;
    out.push_back(l);
  }
  out.push_back({0, NAN, 0.5f, 0.01f, 0, 0, 0.01f});
  out.push_back({1, 0.5f, 0.5f, INFINITY, 0, 0, 1});
  out.push_back({2, 0.5f, 0.5f, NAN, NAN, NAN, NAN});
  out.push_back({3, 1e30f, -1e30f, 1e20f, -1e20f, 1e20f, 1e20f});
  return out;
}

bool near(float gpu, float twin, float tolerance) {
  if (std::isnan(twin) || std::isnan(gpu)) return std::isnan(twin) && std::isnan(gpu);
  return std::fabs(gpu - twin) <= tolerance * std::max(1.0f, std::fabs(twin));
}

const SamplerParams kDiscard = sampler_params(Method::Discard, Filter::Aniso, 16, ZeroCoverage::Clamp);

SamplerParams with_filter(SamplerParams p, int filter) {
  p.filter = filter;
  return p;
}

}  // namespace

namespace {

// One filter against the twin at every address mode, storage and method: a kernel variant each,
// so each filter is a test of its own. Every address mode meets every method (renormalised or
// not, and the NaN zero-coverage rule), and each of those meets both storages, in nine of the
// eighteen variants: on PoCL each variant is a compile of seconds on a cold cache, and storage
// (how a texel is fetched) is independent of the address and method logic it feeds.
void expect_sampler_matches_twin(int filter) {
  std::mt19937 rng(5);
  const Scene scene = random_texture_scene(3);
  const std::vector<Lookup> lookups = random_lookups(rng, static_cast<uint32_t>(scene.faces.size()), 3000);
  // Each combination runs at bias 0 and at one of these in turn: every bias meets every filter.
  const float biases[] = {-1.5f, -0.25f, 0.5f, 1.0f, 2.75f};
  struct MethodBits {
    int renormalize;
    int zero_coverage;
  };
  const MethodBits methods[] = {{0, SEAMCL_ZERO_COVERAGE_CLAMP},
                                {1, SEAMCL_ZERO_COVERAGE_CLAMP},
                                {1, SEAMCL_ZERO_COVERAGE_NAN}};
  const int addresses[] = {SEAMCL_ADDRESS_CLAMP, SEAMCL_ADDRESS_WRAP, SEAMCL_ADDRESS_BORDER};
  std::map<TexelFormat, PackedScene> packed;
  std::map<TexelFormat, std::unique_ptr<TextureLookups>> devices;
  for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
    packed.emplace(format, pack_scene(scene, format));
    devices.emplace(format, std::make_unique<TextureLookups>(shared_runtime(), packed.at(format)));
    devices.at(format)->set_lookups(lookups);
  }
  size_t combination = 0;
  std::set<std::pair<int, TexelFormat>> address_storage, method_storage;
  for (size_t a = 0; a < std::size(addresses); ++a) {
    for (size_t m = 0; m < std::size(methods); ++m) {
      const TexelFormat format = (a + m) % 2 == 0 ? TexelFormat::Rgba8 : TexelFormat::Rgba32f;
      address_storage.insert({addresses[a], format});
      method_storage.insert({static_cast<int>(m), format});
      TextureLookups& device = *devices.at(format);
      const PackedScene& textures = packed.at(format);
      const int address = addresses[a];
      const int renormalize = methods[m].renormalize;
      const int zero_coverage = methods[m].zero_coverage;
      SamplerParams sampler{};
      sampler.filter = filter;
      sampler.address = address;
      sampler.renormalize = renormalize;
      sampler.max_aniso = 1 + static_cast<int>(rng() % 16);
      sampler.zero_coverage = zero_coverage;
      // The bias is read at run time: every bias runs on the variant built for the first.
      const float other_bias = biases[combination++ % std::size(biases)];
      for (float lod_bias : {0.0f, other_bias}) {
        sampler.lod_bias = lod_bias;
        SCOPED_TRACE(testing::Message() << "format " << to_string(format) << " filter " << filter << " address "
                                        << address << " renormalize " << renormalize << " zero_coverage "
                                        << zero_coverage << " max_aniso " << sampler.max_aniso << " lod_bias "
                                        << lod_bias);
        const std::vector<glm::vec4> gpu = device.sample(sampler);
        const std::vector<FilterSum> gpu_sums = device.filter(sampler);
        size_t bad = 0;
        for (size_t i = 0; i < lookups.size(); ++i) {
          const Lookup& l = lookups[i];
          const glm::vec4 twin =
              sample_texture_reference(textures.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
          const FilterSum twin_sum =
              method_sum_reference(textures.textures(), l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
          // 1e-5: the kernels round as the twin does except in the exp and sqrt builtins (EWA, aniso).
          bool ok = near(gpu_sums[i].weight, twin_sum.weight, 1e-5f);
          for (int c = 0; c < 4; ++c) {
            ok &= near(gpu[i][c], twin[c], 1e-5f) && near(gpu_sums[i].color[c], twin_sum.color[c], 1e-5f);
          }
          if (!ok && bad++ < 3) {
            ADD_FAILURE() << "lookup " << i << " face " << l.face << " uv " << l.u << "," << l.v << " d " << l.dudx
                          << "," << l.dvdx << "," << l.dudy << "," << l.dvdy << ": gpu " << gpu[i].r << " twin "
                          << twin.r << " weight " << gpu_sums[i].weight << " / " << twin_sum.weight;
          }
        }
        EXPECT_EQ(bad, 0u);
      }
    }
  }
  // The nine variants meet every pair of settings: each address mode and each method with both storages.
  EXPECT_EQ(address_storage.size(), 6u);
  EXPECT_EQ(method_storage.size(), 6u);
}

}  // namespace

TEST(KernelVsTwin, SamplerBilinearEveryAddressModeStorageAndMethod) { expect_sampler_matches_twin(SEAMCL_FILTER_BILINEAR); }
TEST(KernelVsTwin, SamplerTrilinearEveryAddressModeStorageAndMethod) { expect_sampler_matches_twin(SEAMCL_FILTER_TRILINEAR); }
TEST(KernelVsTwin, SamplerAnisoEveryAddressModeStorageAndMethod) { expect_sampler_matches_twin(SEAMCL_FILTER_ANISO); }
TEST(KernelVsTwin, SamplerEwaEveryAddressModeStorageAndMethod) { expect_sampler_matches_twin(SEAMCL_FILTER_EWA); }

// The table the kernels read log2(N) from holds exactly what approx_log2 gives for each probe
// count (so the table changed no lod), and that is log2(N) to within the polynomial's 5e-6.
TEST(Sampler, ProbeCountLog2TableIsTheKernelsPolynomial) {
  for (int n = 1; n <= SEAMCL_MAX_PROBES; ++n) {
    const float from_table = log2_probe_count(n);
    const float from_polynomial = approx_log2(static_cast<float>(n));
    EXPECT_EQ(std::bit_cast<uint32_t>(from_table), std::bit_cast<uint32_t>(from_polynomial))
        << n << " probes: table " << from_table << ", polynomial " << from_polynomial;
    EXPECT_NEAR(from_table, std::log2(static_cast<double>(n)), 5e-6) << n << " probes";
  }
}

TEST(Discard, ConstantTextureIsReturnedExactlyEverywhere) {
  const glm::vec4 constant(0.3f, 0.6f, 0.9f, 1.0f);
  const Scene scene = texture_scene({{64, 64}, {16, 128}, {1, 4}, {8, 8}}, [&](int, int, int) { return constant; });
  std::mt19937 rng(9);
  // Footprints that straddle edges and corners: centres near the border, wide derivatives.
  std::vector<Lookup> lookups;
  for (int i = 0; i < 4000; ++i) {
    const float edge = uniform(rng, -0.05f, 0.05f);
    Lookup l;
    l.face = rng() % 4;
    l.u = i % 2 ? edge : uniform(rng, -0.1f, 1.1f);
    l.v = i % 3 ? 1.0f + edge : uniform(rng, -0.1f, 1.1f);
    const float scale = std::pow(10.0f, uniform(rng, -4, 0));
    l.dudx = scale * uniform(rng, -1, 1);
    l.dvdx = scale * uniform(rng, -1, 1);
    l.dudy = scale * uniform(rng, -1, 1) * 0.1f;
    l.dvdy = scale * uniform(rng, -1, 1);
    lookups.push_back(l);
  }
  for (TexelFormat format : {TexelFormat::Rgba32f, TexelFormat::Rgba8}) {
    const PackedScene packed = pack_scene(scene, format);
    // RGBA8 stores the constant after an sRGB round trip; that is the constant it must return.
    const glm::vec4 stored = format == TexelFormat::Rgba8 ? decode_srgb8(encode_srgb8(constant)) : constant;
    TextureLookups device(shared_runtime(), packed);
    device.set_lookups(lookups);
    for (int filter : {SEAMCL_FILTER_BILINEAR, SEAMCL_FILTER_TRILINEAR, SEAMCL_FILTER_ANISO, SEAMCL_FILTER_EWA}) {
      SCOPED_TRACE(testing::Message() << to_string(format) << " filter " << filter);
      const std::vector<glm::vec4> colors = device.sample(with_filter(kDiscard, filter));
      const std::vector<FilterSum> sums = device.filter(with_filter(kDiscard, filter));
      size_t partial = 0;
      for (size_t i = 0; i < lookups.size(); ++i) {
        for (int c = 0; c < 4; ++c) ASSERT_NEAR(colors[i][c], stored[c], 1e-6f) << "lookup " << i;
        partial += sums[i].weight > 0.0f && sums[i].weight < 0.999f;
      }
      EXPECT_GT(partial, lookups.size() / 10) << "the cases must straddle edges for the test to mean anything";
      // Black (no renormalisation) on the same lookups darkens wherever taps fell outside.
      const std::vector<glm::vec4> black =
          device.sample(sampler_params(Method::Black, static_cast<Filter>(filter), 16, ZeroCoverage::Clamp));
      size_t darker = 0;
      for (size_t i = 0; i < lookups.size(); ++i) darker += black[i].g < stored.g - 1e-3f;
      EXPECT_GE(darker, partial / 2);
    }
  }
}

TEST(Discard, WeightsSumToOneInsideAndWithClampOrWrap) {
  const Scene scene = random_texture_scene(4);
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  TextureLookups device(shared_runtime(), packed);
  std::mt19937 rng(12);
  std::vector<Lookup> lookups = random_lookups(rng, static_cast<uint32_t>(scene.faces.size()), 3000);
  device.set_lookups(lookups);
  for (int filter : {SEAMCL_FILTER_BILINEAR, SEAMCL_FILTER_TRILINEAR, SEAMCL_FILTER_ANISO, SEAMCL_FILTER_EWA}) {
    for (int address : {SEAMCL_ADDRESS_CLAMP, SEAMCL_ADDRESS_WRAP, SEAMCL_ADDRESS_BORDER}) {
      SamplerParams sampler = with_filter(kDiscard, filter);
      sampler.address = address;
      const std::vector<FilterSum> sums = device.filter(sampler);
      for (size_t i = 0; i < lookups.size(); ++i) {
        if (address == SEAMCL_ADDRESS_BORDER) {
          EXPECT_GE(sums[i].weight, 0.0f);
          EXPECT_LE(sums[i].weight, 1.0f + 1e-5f);
        } else {
          EXPECT_NEAR(sums[i].weight, 1.0f, 1e-5f) << "filter " << filter << " address " << address << " lookup " << i;
        }
      }
    }
  }
}

TEST(Discard, NaNInNeighbouringMemoryNeverLeaks) {
  // Faces 0 and 2 are all NaN; face 1, between them in memory, is finite. No lookup on face 1,
  // whatever its coordinates, may read its neighbours.
  const Scene scene = texture_scene({{16, 16}, {32, 8}, {16, 16}}, [](int face, int i, int j) {
    return face == 1 ? glm::vec4(0.1f + 0.02f * static_cast<float>(i % 7), 0.5f, 0.02f * static_cast<float>(j), 1.0f)
                     : glm::vec4(NAN);
  });
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  ASSERT_TRUE(std::isnan(packed.texels32.front()));
  TextureLookups device(shared_runtime(), packed);
  std::mt19937 rng(21);
  std::vector<Lookup> lookups = random_lookups(rng, 1, 3000);
  for (Lookup& l : lookups) l.face = 1;
  device.set_lookups(lookups);
  for (Method method : {Method::Clamp, Method::Black, Method::Discard}) {
    for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
      const std::vector<glm::vec4> colors = device.sample(sampler_params(method, filter, 16, ZeroCoverage::Clamp));
      for (size_t i = 0; i < colors.size(); ++i) {
        for (int c = 0; c < 4; ++c) {
          ASSERT_TRUE(std::isfinite(colors[i][c])) << to_string(method) << " " << to_string(filter) << " lookup " << i;
        }
      }
    }
  }
}

TEST(ZeroCoverage, NanOnlyWhereEveryTapFallsOutside) {
  const Scene scene = random_texture_scene(6);
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba8);
  TextureLookups device(shared_runtime(), packed);
  std::mt19937 rng(33);
  const std::vector<Lookup> lookups = random_lookups(rng, static_cast<uint32_t>(scene.faces.size()), 4000);
  device.set_lookups(lookups);
  for (Filter filter : {Filter::Bilinear, Filter::Trilinear, Filter::Aniso, Filter::Ewa}) {
    const std::vector<FilterSum> sums = device.filter(sampler_params(Method::Discard, filter, 16, ZeroCoverage::Nan));
    const std::vector<glm::vec4> raw = device.sample(sampler_params(Method::Discard, filter, 16, ZeroCoverage::Nan));
    const std::vector<glm::vec4> fixed = device.sample(sampler_params(Method::Discard, filter, 16, ZeroCoverage::Clamp));
    size_t nan_count = 0;
    for (size_t i = 0; i < lookups.size(); ++i) {
      const bool no_tap_inside = sums[i].weight == 0.0f;
      EXPECT_EQ(std::isnan(raw[i].r), no_tap_inside) << to_string(filter) << " lookup " << i;
      nan_count += std::isnan(raw[i].r);
      for (int c = 0; c < 4; ++c) ASSERT_TRUE(std::isfinite(fixed[i][c])) << to_string(filter) << " lookup " << i;
    }
    EXPECT_GT(nan_count, 0u) << "far-outside lookups must provoke the failure";
  }
}

