// SamplerParams.lod_bias (kernels/texture_sample.cl, its twin host/pipeline/stages/texture_sample_twin.cpp): a
// bias of +1 reads what the next level of the chain holds, bilinear reads the level nearest the
// bias, and a non-finite footprint reads the coarsest level whatever the bias; the kernel and the
// twin alike. (Kernel against twin at many biases: test_sampler.cpp and test_traverse.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/pipeline/texture_lookups.h>
#include "test_support.h"
#include "pipeline/stages/texture_sample_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

// Level-0 sizes of the faces the tests pair up: square and not, both sides at least 2 so that
// the chain without level 0 still halves both sides (a side of 1 would stay 1).
const std::vector<std::pair<int, int>> kSizes{{64, 64}, {32, 8}, {8, 32}, {128, 32}, {4, 4}, {2, 2}};

// Faces 2 p and 2 p + 1 for each size p: a random texture, then the same chain without its
// level 0 (a face whose level 0 is the first one's level 1).
Scene chains_and_their_tails(uint32_t seed) {
  std::mt19937 rng(seed);
  Scene scene;
  scene.name = "chains and their tails";
  auto add_face = [&scene](MipChain chain) {
    const auto base = static_cast<uint32_t>(scene.positions.size());
    const float x = static_cast<float>(scene.faces.size()) * 2.0f;
    scene.positions.insert(scene.positions.end(), {{x, 0, 0}, {x + 1, 0, 0}, {x + 1, 1, 0}, {x, 1, 0}});
    Face face;
    face.vertices = {base, base + 1, base + 2, base + 3};
    face.texture = std::move(chain);
    scene.faces.push_back(std::move(face));
  };
  for (const auto& [width, height] : kSizes) {
    TextureLevel level{width, height, {}};
    for (int i = 0; i < width * height; ++i) {
      level.texels.emplace_back(uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0, 1), uniform(rng, 0.5f, 1));
    }
    MipChain chain = build_mip_chain(std::move(level));
    MipChain tail;
    tail.levels.assign(chain.levels.begin() + 1, chain.levels.end());
    add_face(std::move(chain));
    add_face(std::move(tail));
  }
  return scene;
}

// Lookups on the full chains (even faces) whose footprint's longer axis spans 1.01 texels of
// level 0 up to twice the face: a level of 0 or more before any bias, any orientation and aspect.
std::vector<Lookup> minifying_lookups(const PackedScene& packed, uint32_t seed, int count) {
  std::mt19937 rng(seed);
  std::vector<Lookup> out;
  for (int i = 0; i < count; ++i) {
    Lookup l;
    l.face = 2 * static_cast<uint32_t>(rng() % kSizes.size());
    const FaceGpu& face = packed.faces[l.face];
    const float w = static_cast<float>(face.width), h = static_cast<float>(face.height);
    l.u = uniform(rng, -0.3f, 1.3f);
    l.v = uniform(rng, -0.3f, 1.3f);
    const float texels = 1.01f * std::exp2(uniform(rng, 0.0f, std::log2(2.0f * std::max(w, h))));
    const float angle = uniform(rng, 0.0f, 6.2831853f);
    const float shorter = 1.0f / uniform(rng, 1.0f, 8.0f);
    // The longer axis x, texels long in level-0 texels; y across it, shorter.
    l.dudx = texels * std::cos(angle) / w;
    l.dvdx = texels * std::sin(angle) / h;
    l.dudy = -texels * shorter * std::sin(angle) / w;
    l.dvdy = texels * shorter * std::cos(angle) / h;
    out.push_back(l);
  }
  return out;
}

// The same lookups on each chain's tail (the next face), the footprint spanning as many of the
// tail's level-0 texels as it spanned of the full chain's: twice as long in uv, its texels being
// twice as wide. (With the same uv derivatives the tail would give the bias-0 lookup: a level is
// a size in uv.)
std::vector<Lookup> on_the_tails(std::vector<Lookup> lookups) {
  for (Lookup& l : lookups) {
    l.face += 1;
    l.dudx *= 2.0f;
    l.dvdx *= 2.0f;
    l.dudy *= 2.0f;
    l.dvdy *= 2.0f;
  }
  return lookups;
}

SamplerParams sampler_of(int filter, int address, float lod_bias) {
  SamplerParams sampler{};
  sampler.filter = filter;
  sampler.address = address;
  sampler.renormalize = address == SEAMCL_ADDRESS_BORDER ? 1 : 0;  // border: as discard runs it
  sampler.max_aniso = 8;
  sampler.zero_coverage = SEAMCL_ZERO_COVERAGE_CLAMP;
  sampler.lod_bias = lod_bias;
  return sampler;
}

bool same_bits(const glm::vec4& a, const glm::vec4& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

bool same_bits(const FilterSum& a, const FilterSum& b) {
  return same_bits(a.color, b.color) && std::memcmp(&a.weight, &b.weight, sizeof a.weight) == 0;
}

// Over the colour sums and the weight; a NaN anywhere counts as infinitely far.
float largest_difference(const FilterSum& a, const FilterSum& b) {
  float d = std::fabs(a.weight - b.weight);
  for (int c = 0; c < 4; ++c) d = std::fmax(d, std::fabs(a.color[c] - b.color[c]));
  return std::isnan(d) ? INFINITY : d;
}

}  // namespace

TEST(LodBias, TrilinearAtPlusOneIsTheChainWithoutItsLevelZero) {
  // A trilinear lookup at bias +1 reads the level its footprint gives plus one: what the same
  // lookup at bias 0 reads on a face whose chain starts at the first one's level 1. The levels
  // before the bias are 0 or more, so neither side clamps at level 0; the coarsest ones clamp
  // alike (the tail has one level fewer). Compared before renormalisation (the FilterSums: colour
  // sums and weight inside), which is linear in the blend between the two levels. Not bit-exact:
  // lod + 1 is rounded to the float nearest, so the blend may move by half an ulp of a lod below
  // 16 (at most 4.8e-7), a sum by that times the difference of two texels (at most 1), plus the
  // rounding of the sums themselves: 1e-6. Kernel and twin alike.
  const Scene scene = chains_and_their_tails(21);
  for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
    const PackedScene packed = pack_scene(scene, format);
    const TextureView view = packed.textures();
    const std::vector<Lookup> full = minifying_lookups(packed, 22, 3000);
    const std::vector<Lookup> tails = on_the_tails(full);
    TextureLookups on_full(shared_runtime(), packed), on_tails(shared_runtime(), packed);
    on_full.set_lookups(full);
    on_tails.set_lookups(tails);
    for (int address : {SEAMCL_ADDRESS_CLAMP, SEAMCL_ADDRESS_WRAP, SEAMCL_ADDRESS_BORDER}) {
      const char* storage = format == TexelFormat::Rgba8 ? "rgba8" : "rgba32f";
      SCOPED_TRACE(testing::Message() << storage << " address " << address);
      const SamplerParams biased = sampler_of(SEAMCL_FILTER_TRILINEAR, address, 1.0f);
      const SamplerParams unbiased = sampler_of(SEAMCL_FILTER_TRILINEAR, address, 0.0f);
      const std::vector<FilterSum> gpu_biased = on_full.filter(biased);
      const std::vector<FilterSum> gpu_unbiased = on_full.filter(unbiased);
      const std::vector<FilterSum> gpu_tails = on_tails.filter(unbiased);
      float kernel_worst = 0.0f, twin_worst = 0.0f;
      size_t moved = 0;
      for (size_t i = 0; i < full.size(); ++i) {
        const Lookup& a = full[i];
        const Lookup& b = tails[i];
        const FilterSum twin_biased =
            method_sum_reference(view, a.face, biased, a.u, a.v, a.dudx, a.dvdx, a.dudy, a.dvdy);
        const FilterSum twin_tail = method_sum_reference(view, b.face, unbiased, b.u, b.v, b.dudx, b.dvdx, b.dudy, b.dvdy);
        kernel_worst = std::fmax(kernel_worst, largest_difference(gpu_biased[i], gpu_tails[i]));
        twin_worst = std::fmax(twin_worst, largest_difference(twin_biased, twin_tail));
        // The bias does move what the lookup reads.
        moved += largest_difference(gpu_biased[i], gpu_unbiased[i]) > 1e-3f;
      }
      EXPECT_LE(kernel_worst, 1e-6f);
      EXPECT_LE(twin_worst, 1e-6f);
      EXPECT_GT(moved, full.size() / 2);
      std::printf("[          ] %s address %d: largest difference kernel %.3g, twin %.3g; %zu of %zu moved by the bias\n",
                  storage, address, kernel_worst, twin_worst, moved, full.size());
    }
  }
}

TEST(LodBias, BilinearReadsTheLevelNearestTheBias) {
  // Bilinear has no footprint level: it reads level floor(bias + 0.5) of the chain, so level 0
  // below 0.5, and from 0.5 to 1.5 the level a chain's tail holds as its level 0, which the tail
  // reads at bias 0: the same texels at the same places, the same bits. Compared before
  // renormalisation: a lookup with no tap inside a border-addressed face falls back to a trilinear
  // one, whose level the footprint sets.
  const Scene scene = chains_and_their_tails(23);
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  const TextureView view = packed.textures();
  const std::vector<Lookup> full = minifying_lookups(packed, 24, 2000);
  const std::vector<Lookup> tails = on_the_tails(full);
  TextureLookups on_full(shared_runtime(), packed), on_tails(shared_runtime(), packed);
  on_full.set_lookups(full);
  on_tails.set_lookups(tails);
  for (int address : {SEAMCL_ADDRESS_CLAMP, SEAMCL_ADDRESS_BORDER}) {
    const std::vector<FilterSum> level0 = on_full.filter(sampler_of(SEAMCL_FILTER_BILINEAR, address, 0.0f));
    const std::vector<FilterSum> tail0 = on_tails.filter(sampler_of(SEAMCL_FILTER_BILINEAR, address, 0.0f));
    for (float lod_bias : {-4.0f, -1.5f, 0.25f, 0.5f, 1.0f, 1.25f}) {
      SCOPED_TRACE(testing::Message() << "address " << address << " lod_bias " << lod_bias);
      const SamplerParams sampler = sampler_of(SEAMCL_FILTER_BILINEAR, address, lod_bias);
      const std::vector<FilterSum>& expected = lod_bias < 0.5f ? level0 : tail0;
      const std::vector<FilterSum> gpu = on_full.filter(sampler);
      size_t bad = 0, inside = 0;
      for (size_t i = 0; i < full.size(); ++i) {
        const Lookup& l = full[i];
        const FilterSum twin = method_sum_reference(view, l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
        const bool ok = same_bits(gpu[i], expected[i]) && same_bits(twin, expected[i]);
        inside += expected[i].weight > 0.0f;
        if (!ok && bad++ < 3) {
          ADD_FAILURE() << "lookup " << i << ": kernel " << gpu[i].color.r << " twin " << twin.color.r << " expected "
                        << expected[i].color.r;
        }
      }
      EXPECT_EQ(bad, 0u);
      EXPECT_GT(inside, full.size() / 4);
    }
  }
}

TEST(LodBias, NonFiniteFootprintsReadTheCoarsestLevelAtAnyBias) {
  // NaN or infinite derivatives read the coarsest level (1x1) whatever the bias: the same bits at
  // -4, 0 and 4, for every filter that has a footprint, kernel and twin.
  const Scene scene = chains_and_their_tails(25);
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f);
  const TextureView view = packed.textures();
  std::vector<Lookup> lookups;
  for (uint32_t face = 0; face < packed.faces.size(); ++face) {
    lookups.push_back({face, 0.3f, 0.6f, NAN, 0.0f, 0.0f, 0.01f});
    lookups.push_back({face, 0.7f, 0.2f, INFINITY, 0.0f, 0.0f, 1.0f});
  }
  TextureLookups device(shared_runtime(), packed);
  device.set_lookups(lookups);
  for (int filter : {SEAMCL_FILTER_TRILINEAR, SEAMCL_FILTER_ANISO, SEAMCL_FILTER_EWA}) {
    SCOPED_TRACE(testing::Message() << "filter " << filter);
    const std::vector<glm::vec4> unbiased = device.sample(sampler_of(filter, SEAMCL_ADDRESS_CLAMP, 0.0f));
    for (size_t i = 0; i < lookups.size(); ++i) {
      // The coarsest level's one texel (all four taps of a clamped 1x1 level read it).
      const FaceGpu& face = packed.faces[lookups[i].face];
      const uint32_t texel = packed.level_offsets[face.level_table + static_cast<uint32_t>(face.level_count - 1)];
      for (int c = 0; c < 4; ++c) EXPECT_NEAR(unbiased[i][c], packed.texels32[4 * texel + static_cast<uint32_t>(c)], 1e-6f);
    }
    for (float lod_bias : {-4.0f, 4.0f}) {
      const SamplerParams sampler = sampler_of(filter, SEAMCL_ADDRESS_CLAMP, lod_bias);
      const std::vector<glm::vec4> gpu = device.sample(sampler);
      for (size_t i = 0; i < lookups.size(); ++i) {
        const Lookup& l = lookups[i];
        const glm::vec4 twin = sample_texture_reference(view, l.face, sampler, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy);
        EXPECT_TRUE(same_bits(gpu[i], unbiased[i])) << "lookup " << i << " lod_bias " << lod_bias;
        EXPECT_TRUE(same_bits(twin, unbiased[i])) << "lookup " << i << " lod_bias " << lod_bias;
      }
    }
  }
}
