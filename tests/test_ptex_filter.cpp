// Ptex's own filters (host/pipeline/stages/ptex_filter_twin.*, host/ptexfilter/): every value of
// the Ptex library's filters in tests/assets/ptex/golden/ (written by the library itself, 96 per
// file, a third of them within 2% of an edge) and in tests/assets/ptex/golden_filters/ (1,200 per
// file: every filter near edges, corners of every valence and resolution changes) is matched
// within 1e-4; the kernels' normalisation
// holds across edges and corners of every valence for every filter; bad textures are refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <string>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/core/input_error.h>

#include "ptex_golden_lookups.h"
#include "ptex_test_writer.h"
#include "ptexfilter/ptex_filter_texture.h"

namespace seamcl {
namespace {

using nlohmann::json;
using seamcl_tests::kPtexSamples;
using seamcl_tests::ptex_assets_dir;
using seamcl_tests::ptex_golden;


const PtexStored& stored_sample(const std::string& name) {
  static std::map<std::string, PtexStored> files;
  auto it = files.find(name);
  if (it == files.end()) it = files.emplace(name, read_ptex_stored(ptex_assets_dir() + "/" + name + ".ptx")).first;
  return it->second;
}

const PtexFilterData& filter_sample(const std::string& name) {
  static std::map<std::string, PtexFilterData> data;
  auto it = data.find(name);
  if (it == data.end()) it = data.emplace(name, build_ptex_filter_data(stored_sample(name))).first;
  return it->second;
}

int filter_code(const std::string& name) {
  if (name == "bilinear") return SEAMCL_PTEX_BILINEAR;
  if (name == "gaussian") return SEAMCL_PTEX_GAUSSIAN;
  if (name == "box") return SEAMCL_PTEX_BOX;
  if (name == "bicubic") return SEAMCL_PTEX_BICUBIC;
  ADD_FAILURE() << "a golden filter this test does not know: " << name;
  return -1;
}

TEST(PtexFilter, MatchesThePtexLibraryOnEveryGoldenValue) {
  for (const char* name : kPtexSamples) {
    const json g = ptex_golden(name);
    const PtexFilterData& data = filter_sample(name);
    ASSERT_EQ(g["filtered"].size(), 96u) << name;
    std::map<std::string, double> largest;
    for (const json& e : g["filtered"]) {
      PtexFilterQuery q{};
      q.face = e["face"].get<int>();
      q.filter = filter_code(e["filter"].get<std::string>());
      q.u = e["u"].get<float>();
      q.v = e["v"].get<float>();
      q.uw = e["uw"].get<float>();
      q.vw = e["vw"].get<float>();
      const std::array<float, 4> value = ptex_filter_twin(data, q);
      ASSERT_EQ(e["value"].size(), static_cast<size_t>(data.texture.channels)) << name;
      double difference = 0.0;
      for (size_t c = 0; c < e["value"].size(); ++c) {
        EXPECT_NEAR(value[c], e["value"][c].get<double>(), 1e-4) << name << " " << e.dump() << " channel " << c;
        difference = std::max(difference, std::fabs(value[c] - e["value"][c].get<double>()));
      }
      for (size_t c = e["value"].size(); c < 4; ++c) EXPECT_EQ(value[c], 0.0f);
      double& worst = largest[e["filter"].get<std::string>()];
      worst = std::max(worst, difference);
    }
    for (const auto& [filter, worst] : largest)
      std::cout << "[ptex golden] " << name << " " << filter << ": largest difference " << worst << "\n";
  }
}

// Values of the file's scale (0..1 for integer files, as the library returns them): 1e-4 is well
// under a uint8 step and the float rounding of a wide kernel's sums stays far below it.
TEST(PtexFilter, MatchesThePtexLibraryOnEveryFilterNearEdgesCornersAndResolutionChanges) {
  for (const char* name : kPtexSamples) {
    const PtexFilterData& data = filter_sample(name);
    const std::vector<seamcl_tests::PtexGoldenLookup> lookups = seamcl_tests::ptex_golden_filter_lookups(name);
    ASSERT_GE(lookups.size(), 1000u) << name;
    seamcl_tests::PtexGoldenTally tally(name, 1e-4);
    for (const seamcl_tests::PtexGoldenLookup& l : lookups) {
      ASSERT_EQ(l.value.size(), static_cast<size_t>(data.texture.channels)) << name;
      const std::array<float, 4> value = ptex_filter_twin(data, l.query);
      tally.add(l, value.data(), data.texture.channels);
    }
    tally.print("twin");
    EXPECT_EQ(tally.failures(), "");
    EXPECT_EQ(tally.lookups(), static_cast<int>(lookups.size()));
  }
}

// The seam rules of renders whose method reads no neighbour (PtexFilterTexture::seams), against a
// model: a bilinear lookup on a face's left edge at the centre of texel row j weighs the edge texel
// and one tap past the edge, half each. Clamp folds that tap onto the edge texel (the edge texel),
// black drops it (half the edge texel), discard drops it and renormalises (the edge texel); Ptex's
// own rule reads the neighbour there, and a lookup inside the face is the same under every rule.
TEST(PtexFilter, SeamRulesWithoutNeighboursKeepToTheFace) {
  const PtexFilterData data = filter_sample("cube_text");
  ASSERT_EQ(data.texture.data_type, 0);
  ASSERT_EQ(data.texture.channels, 1);
  for (int face = 0; face < 6; ++face) {
    const PtexFilterFace& f = data.faces[face];
    const int resu = 1 << f.ulog2, resv = 1 << f.vlog2;
    const int j = resv / 2 + face;
    const size_t level = data.level_offsets[f.level_base + static_cast<size_t>(f.ulog2) * (f.vlog2 + 1) + f.vlog2];
    const float edge = static_cast<float>(data.texels[level + static_cast<size_t>(j) * resu]) / 255.0f;
    PtexFilterQuery q{};
    q.face = face;
    q.filter = SEAMCL_PTEX_BILINEAR;
    q.u = 0.0f;
    q.v = (static_cast<float>(j) + 0.5f) / static_cast<float>(resv);
    PtexFilterTexture rule = data.texture;
    auto with = [&](int seams, const PtexFilterQuery& query) {
      rule.seams = seams;
      return ptex_filter_twin(data, rule, query)[0];
    };
    EXPECT_FLOAT_EQ(with(SEAMCL_PTEX_SEAMS_CLAMP, q), edge) << face;
    EXPECT_FLOAT_EQ(with(SEAMCL_PTEX_SEAMS_BLACK, q), 0.5f * edge) << face;
    EXPECT_FLOAT_EQ(with(SEAMCL_PTEX_SEAMS_DISCARD, q), edge) << face;
    EXPECT_EQ(with(SEAMCL_PTEX_SEAMS_PTEX, q), ptex_filter_twin(data, q)[0]) << face;
    // A point outside the face is clamped into it: the same as on its edge.
    PtexFilterQuery outside = q;
    outside.u = -0.3f;
    EXPECT_FLOAT_EQ(with(SEAMCL_PTEX_SEAMS_DISCARD, outside), edge) << face;
    PtexFilterQuery inside = q;
    inside.u = 0.5f + 0.5f / static_cast<float>(resu);
    inside.filter = SEAMCL_PTEX_GAUSSIAN;
    inside.uw = inside.vw = 2.0f / static_cast<float>(resu);
    const float own = ptex_filter_twin(data, inside)[0];
    for (int seams : {SEAMCL_PTEX_SEAMS_CLAMP, SEAMCL_PTEX_SEAMS_BLACK, SEAMCL_PTEX_SEAMS_DISCARD})
      EXPECT_EQ(with(seams, inside), own) << face << " rule " << seams;
  }
}

// The same texture with every texel (every resolution) set to one value: whatever the filter, the
// point and the widths, near any edge or corner (cube_text: valence 3, 4, 5 and 6; cellnoise: 3, 4
// and 9, faces of mixed resolutions), the weights Ptex applies must sum to what it divides by.
TEST(PtexFilter, EveryFilterReturnsAConstantTextureAcrossEdgesAndCorners) {
  for (const char* name : {"cellnoise", "cube_text", "rand_lo"}) {
    PtexFilterData data = filter_sample(name);
    const float level = data.texture.data_type == 0 ? 200.0f : 50000.0f;
    for (size_t t = 0; t < data.texels.size() / (data.texture.data_type == 0 ? 1 : 2); ++t) {
      if (data.texture.data_type == 0) {
        data.texels[t] = static_cast<uint8_t>(level);
      } else {
        const uint16_t x = static_cast<uint16_t>(level);
        std::memcpy(&data.texels[2 * t], &x, 2);
      }
    }
    const float expected = level / data.texture.one_value;
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    const float edges[] = {0.0f, 0.001f, 0.02f, 0.98f, 0.999f, 1.0f};
    for (int i = 0; i < 400; ++i) {
      PtexFilterQuery q{};
      q.face = static_cast<int>(random() % data.faces.size());
      q.filter = std::array{SEAMCL_PTEX_BILINEAR, SEAMCL_PTEX_BOX, SEAMCL_PTEX_GAUSSIAN, SEAMCL_PTEX_BICUBIC}[i % 4];
      q.sharpness = (i / 4) % 3 == 0 ? 0.0f : 2.0f / 3.0f;
      q.u = i % 3 == 0 ? unit(random) : edges[random() % 6];
      q.v = i % 2 == 0 ? edges[random() % 6] : unit(random);
      q.uw = std::exp2(-9.0f * unit(random));  // a texel to a whole face
      q.vw = i % 5 == 0 ? q.uw : std::exp2(-9.0f * unit(random));
      const std::array<float, 4> value = ptex_filter_twin(data, q);
      for (int c = 0; c < data.texture.channels; ++c)
        ASSERT_NEAR(value[c], expected, 2e-5f) << name << " face " << q.face << " filter " << q.filter << " at ("
                                               << q.u << ", " << q.v << ") widths " << q.uw << " x " << q.vw;
    }
  }
}

// Resolutions the file does not store are the library's on-demand reductions in the file's type:
// a 16x16 uint16 face read at 16x8 holds floor((a + b) / 2) of the level-0 pairs, not their mean.
TEST(PtexFilter, UnstoredResolutionsHalveInTheFilesTypeRoundingDown) {
  const PtexStored& stored = stored_sample("rand_lo");
  const PtexFilterData& data = filter_sample("rand_lo");
  int checked = 0, odd_pairs = 0;
  for (size_t f = 0; f < stored.file.faces.size(); ++f) {
    const PtexFaceInfo& info = stored.file.faces[f];
    if (info.ulog2 < 1 || info.vlog2 < 1) continue;
    const PtexFilterFace& face = data.faces[f];
    const size_t offset = data.level_offsets[face.level_base + info.ulog2 * (info.vlog2 + 1) + (info.vlog2 - 1)];
    const std::vector<float>& level0 = stored.faces[f].levels.at(0);
    const int width = 1 << info.ulog2;
    for (int y = 0; y < (1 << (info.vlog2 - 1)); ++y)
      for (int x = 0; x < width; ++x) {
        const float a = level0[size_t(2 * y) * width + x], b = level0[size_t(2 * y + 1) * width + x];
        uint16_t got;
        std::memcpy(&got, &data.texels[2 * (offset + size_t(y) * width + x)], 2);
        ASSERT_EQ(got, static_cast<uint16_t>(std::floor((a + b) / 2))) << "face " << f;
        odd_pairs += (static_cast<int>(a + b) & 1);
        ++checked;
      }
  }
  EXPECT_GT(checked, 500);
  EXPECT_GT(odd_pairs, 50);  // pairs where rounding down differs from the mean
}

// A float16 file's unstored resolutions round the mean of two halves as the library's PtexHalf
// does: to the nearest half, ties away from zero (IEEE's ties to even moves about half the texels
// of black.ptx's 4x2 level by a half step, 5e-4 near 1).
TEST(PtexFilter, UnstoredFloat16ResolutionsRoundTiesAwayFromZero) {
  const PtexStored& stored = stored_sample("black");
  const PtexFilterData& data = filter_sample("black");
  ASSERT_EQ(stored.faces[0].levels.size(), 1u);  // no mip levels: every coarser one is made here
  const PtexFilterFace& face = data.faces[0];
  ASSERT_EQ(face.ulog2, 2);
  ASSERT_EQ(face.vlog2, 2);
  const size_t offset = data.level_offsets[face.level_base + 2 * (face.vlog2 + 1) + 1];  // 4x2
  const std::vector<float>& level0 = stored.faces[0].levels.at(0);
  int ties = 0;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) {
        const double a = level0[(size_t(2 * y) * 4 + x) * 3 + c], b = level0[(size_t(2 * y + 1) * 4 + x) * 3 + c];
        const double mean = 0.5 * (a + b);
        ASSERT_GT(mean, std::ldexp(1.0, -14));  // normal halves: a step of 2^(exponent - 10)
        const double step = std::ldexp(1.0, static_cast<int>(std::floor(std::log2(mean))) - 10);
        const double steps = mean / step;
        ties += steps - std::floor(steps) == 0.5;
        const double expected = std::floor(steps + 0.5) * step;
        uint16_t h;
        std::memcpy(&h, &data.texels[2 * ((offset + size_t(y) * 4 + x) * 3 + c)], 2);
        const int exponent = (h >> 10) & 0x1f;
        const double got = std::ldexp(1024.0 + (h & 0x3ff), exponent - 25);
        ASSERT_EQ(got, expected) << "texel (" << x << ", " << y << ") channel " << c;
      }
  EXPECT_GE(ties, 6);
}

TEST(PtexFilter, RefusesSubfacesUnknownModesAndTexturesOverTheLimitNamingTexture) {
  PtexStored stored = stored_sample("rand_lo");
  PtexFilterLimits small;
  small.max_bytes = 1000;
  try {
    build_ptex_filter_data(stored, small);
    ADD_FAILURE() << "a texture over the byte limit was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "texture");
    EXPECT_NE(std::string(e.what()).find("more than the limit of 1000"), std::string::npos) << e.what();
  }
  PtexStored odd_mode = stored;
  odd_mode.v_border_mode = 3;
  try {
    build_ptex_filter_data(odd_mode);
    ADD_FAILURE() << "border mode 3 was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "texture");
    EXPECT_NE(std::string(e.what()).find("v border mode 3"), std::string::npos) << e.what();
  }
  stored.faces[4].flags |= SEAMCL_PTEX_FLAG_SUBFACE;
  try {
    build_ptex_filter_data(stored);
    ADD_FAILURE() << "a subface was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "texture");
    EXPECT_NE(std::string(e.what()).find("face 4 is a subface"), std::string::npos) << e.what();
  }
}

TEST(PtexFilter, OutOfRangeFaceGivesZerosAndBlackBorderDarkens) {
  const PtexFilterData& data = filter_sample("black");
  PtexFilterQuery q{};
  q.face = 5;
  q.filter = SEAMCL_PTEX_BILINEAR;
  q.u = q.v = 0.5f;
  q.uw = q.vw = 0.25f;
  for (float x : ptex_filter_twin(data, q)) EXPECT_EQ(x, 0.0f);
  // black.ptx has black borders and one face: far outside is black, at a corner a quarter of the
  // bilinear weight lies on the face.
  q.face = 0;
  q.u = q.v = 2.5f;
  for (float x : ptex_filter_twin(data, q)) EXPECT_EQ(x, 0.0f);
  q.u = q.v = 0.0f;
  const std::array<float, 4> corner = ptex_filter_twin(data, q);
  const std::vector<float>& texel = stored_sample("black").faces[0].levels.at(0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_GT(texel[c], 0.0f);
    EXPECT_FLOAT_EQ(corner[c], 0.25f * texel[c]) << "channel " << c;
  }
}

}  // namespace
}  // namespace seamcl
