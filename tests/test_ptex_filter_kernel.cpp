// kernels/ptex_filter.cl against its scalar twin (host/pipeline/stages/ptex_filter_twin.cpp): the
// golden lookups of every sample, and random lookups of every filter near edges and corners
// (cellnoise: valence 3, 4 and 9 and faces of mixed resolutions; rand_lo: uint16 with boundary
// edges; black: float16, black border), widths from a texel to more than a face; and the device
// against the Ptex library itself on every value of tests/assets/ptex/golden_filters/.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <utility>

#include <seamcl/assets/ptex_file.h>

#include "pipeline/stages/ptex_filter_launcher.h"
#include "ptex_golden_lookups.h"
#include "ptex_test_writer.h"
#include "ptexfilter/ptex_filter_texture.h"
#include "test_support.h"

namespace seamcl {
namespace {

using nlohmann::json;
using seamcl_tests::ptex_assets_dir;

std::vector<PtexFilterQuery> golden_queries(const std::string& name) {
  std::ifstream in(ptex_assets_dir() + "/golden/" + name + ".json");
  const json g = json::parse(in);
  std::vector<PtexFilterQuery> out;
  for (const json& e : g["filtered"]) {
    PtexFilterQuery q{};
    q.face = e["face"].get<int>();
    q.filter = e["filter"].get<std::string>() == "bilinear" ? SEAMCL_PTEX_BILINEAR : SEAMCL_PTEX_GAUSSIAN;
    q.u = e["u"].get<float>();
    q.v = e["v"].get<float>();
    q.uw = e["uw"].get<float>();
    q.vw = e["vw"].get<float>();
    out.push_back(q);
  }
  return out;
}

std::vector<PtexFilterQuery> edge_queries(int faces, int count, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float near[] = {0.0f, 0.0004f, 0.01f, 0.03f, 0.97f, 0.99f, 0.9996f, 1.0f};
  const int filters[] = {SEAMCL_PTEX_POINT, SEAMCL_PTEX_BILINEAR, SEAMCL_PTEX_BOX, SEAMCL_PTEX_GAUSSIAN, SEAMCL_PTEX_BICUBIC};
  std::vector<PtexFilterQuery> out;
  for (int i = 0; i < count; ++i) {
    PtexFilterQuery q{};
    q.face = static_cast<int>(random() % static_cast<unsigned>(faces));
    q.filter = filters[i % 5];
    q.sharpness = (i / 5) % 2 == 0 ? 0.0f : 1.0f;
    const int place = i % 4;  // corner, u edge, v edge, anywhere
    q.u = place == 0 || place == 1 ? near[random() % 8] : unit(random);
    q.v = place == 0 || place == 2 ? near[random() % 8] : unit(random);
    q.uw = std::exp2(-10.0f * unit(random) + 0.5f);
    q.vw = i % 3 == 0 ? q.uw : std::exp2(-10.0f * unit(random) + 0.5f);
    out.push_back(q);
  }
  return out;
}

TEST(PtexFilterKernel, MatchesTheTwinOnGoldenAndEdgeLookups) {
  for (const char* name : {"black", "cellnoise", "rand_lo", "wave_lo"}) {
    const PtexFilterData data = build_ptex_filter_data(read_ptex_stored(ptex_assets_dir() + "/" + name + ".ptx"));
    std::vector<PtexFilterQuery> queries = golden_queries(name);
    const std::vector<PtexFilterQuery> more = edge_queries(static_cast<int>(data.faces.size()), 2000, 11);
    queries.insert(queries.end(), more.begin(), more.end());
    PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
    launcher.load(data);
    const std::vector<float> device = launcher.run(queries);
    ASSERT_EQ(device.size(), queries.size() * 4);
    int nonzero = 0;
    for (size_t i = 0; i < queries.size(); ++i) {
      const std::array<float, 4> twin = ptex_filter_twin(data, queries[i]);
      for (int c = 0; c < 4; ++c) {
        ASSERT_TRUE(std::isfinite(device[4 * i + c]));
        ASSERT_NEAR(device[4 * i + c], twin[c], 2e-6f + 2e-6f * std::fabs(twin[c]))
            << name << " lookup " << i << " face " << queries[i].face << " filter " << queries[i].filter << " at ("
            << queries[i].u << ", " << queries[i].v << ") widths " << queries[i].uw << " x " << queries[i].vw << " channel " << c;
        nonzero += twin[c] != 0.0f;
      }
    }
    EXPECT_GT(nonzero, static_cast<int>(queries.size()) / 2) << name;
  }
}

// One float32 RGBA face of 16 x 16 texels, with values outside 0..1 of both signs.
PtexFilterData float_rgba_face() {
  PtexTestFile spec;
  spec.data_type = 3;
  spec.channels = 4;
  std::vector<uint8_t> level0;
  for (int j = 0; j < 16; ++j)
    for (int i = 0; i < 16; ++i)
      for (float value : {std::sin(0.7f * i) + 0.1f * j, 2.0f * std::cos(0.5f * j), 0.01f * i * j - 0.3f, 0.5f + 0.03f * i}) {
        uint8_t bytes[4];
        std::memcpy(bytes, &value, 4);
        level0.insert(level0.end(), bytes, bytes + 4);
      }
  const float average[4] = {0.5f, 0.1f, 0.3f, 0.7f};
  std::vector<uint8_t> constant(sizeof average);
  std::memcpy(constant.data(), average, sizeof average);
  spec.faces = {{4, 4, 0, {-1, -1, -1, -1}, 0, constant}};
  spec.levels = {{data_block(level0, 256, 4, 4)}};
  return build_ptex_filter_data(parse_ptex_stored(write_ptex(spec)));
}

// The float texel path, and rows of up to 40 values (three 16-value reads).
TEST(PtexFilterKernel, MatchesTheTwinOnAFloatRgbaFace) {
  const PtexFilterData data = float_rgba_face();
  const std::vector<PtexFilterQuery> queries = edge_queries(1, 2000, 13);
  PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
  launcher.load(data);
  const std::vector<float> device = launcher.run(queries);
  ASSERT_EQ(device.size(), queries.size() * 4);
  int wide = 0;
  for (size_t i = 0; i < queries.size(); ++i) {
    const std::array<float, 4> twin = ptex_filter_twin(data, queries[i]);
    for (int c = 0; c < 4; ++c)
      ASSERT_NEAR(device[4 * i + c], twin[c], 2e-6f + 2e-6f * std::fabs(twin[c]))
          << "lookup " << i << " filter " << queries[i].filter << " at (" << queries[i].u << ", " << queries[i].v
          << ") widths " << queries[i].uw << " x " << queries[i].vw << " channel " << c;
    wide += queries[i].filter >= SEAMCL_PTEX_GAUSSIAN && queries[i].uw < 0.25f;
  }
  EXPECT_GT(wide, 200);  // width-4 kernels under a quarter face: rows of 4 to 10 taps, 16 to 40 values
}

// A batch of point lookups alone runs through ptex_point_lookups: the same values as the twin's and
// as the same lookups in a mixed batch, every type (uint8 of 1 and 3 channels, uint16, float16,
// float32 RGBA), faces out of range and points outside the face included.
TEST(PtexFilterKernel, PointBatchesMatchTheTwinAndMixedBatches) {
  std::vector<std::pair<std::string, PtexFilterData>> textures;
  for (const char* name : {"black", "cellnoise", "cube_text", "rand_lo", "wave_lo"})
    textures.emplace_back(name, build_ptex_filter_data(read_ptex_stored(ptex_assets_dir() + "/" + name + ".ptx")));
  textures.emplace_back("float rgba", float_rgba_face());
  for (const auto& [name, data] : textures) {
    const int faces = static_cast<int>(data.faces.size());
    std::mt19937 random(7);
    std::uniform_real_distribution<float> coordinate(-0.25f, 1.25f);
    std::vector<PtexFilterQuery> points;
    for (int i = 0; i < 3000; ++i) {
      PtexFilterQuery q{};
      q.filter = SEAMCL_PTEX_POINT;
      q.face = i % 100 == 0 ? -1 : i % 100 == 1 ? faces : static_cast<int>(random() % static_cast<unsigned>(faces));
      q.u = i % 7 == 0 ? 1.0f : coordinate(random);
      q.v = i % 11 == 0 ? 0.0f : coordinate(random);
      q.uw = q.vw = 0.01f;
      points.push_back(q);
    }
    std::vector<PtexFilterQuery> mixed = points;
    PtexFilterQuery bilinear = points[5];
    bilinear.filter = SEAMCL_PTEX_BILINEAR;
    mixed.push_back(bilinear);
    PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
    launcher.load(data);
    const std::vector<float> alone = launcher.run(points);
    const std::vector<float> among = launcher.run(mixed);
    int nonzero = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const std::array<float, 4> twin = ptex_filter_twin(data, points[i]);
      for (int c = 0; c < 4; ++c) {
        ASSERT_EQ(alone[4 * i + c], twin[c]) << name << " lookup " << i << " face " << points[i].face << " at ("
                                             << points[i].u << ", " << points[i].v << ") channel " << c;
        ASSERT_EQ(among[4 * i + c], twin[c]) << name << " lookup " << i << " in the mixed batch, channel " << c;
        nonzero += twin[c] != 0.0f;
      }
      if (points[i].face < 0 || points[i].face >= faces)
        for (int c = 0; c < 4; ++c) EXPECT_EQ(alone[4 * i + c], 0.0f) << name << " face " << points[i].face;
    }
    EXPECT_GT(nonzero, static_cast<int>(points.size()) / 2) << name;
  }
}

// One launch per file (the launcher's compile dominates the time); the twin's own test holds the
// same values, so a failure here alone points at the kernel.
TEST(PtexFilterKernel, MatchesThePtexLibraryOnEveryFilterNearEdgesCornersAndResolutionChanges) {
  PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
  for (const char* name : {"black", "cellnoise", "cube_text", "rand_lo", "wave_lo"}) {
    const PtexFilterData data = build_ptex_filter_data(read_ptex_stored(ptex_assets_dir() + "/" + name + ".ptx"));
    const std::vector<seamcl_tests::PtexGoldenLookup> lookups = seamcl_tests::ptex_golden_filter_lookups(name);
    ASSERT_GE(lookups.size(), 1000u) << name;
    std::vector<PtexFilterQuery> queries;
    for (const seamcl_tests::PtexGoldenLookup& l : lookups) queries.push_back(l.query);
    launcher.load(data);
    const std::vector<float> device = launcher.run(queries);
    ASSERT_EQ(device.size(), queries.size() * 4);
    seamcl_tests::PtexGoldenTally tally(name, 1e-4);
    for (size_t i = 0; i < lookups.size(); ++i) {
      ASSERT_EQ(lookups[i].value.size(), static_cast<size_t>(data.texture.channels)) << name;
      tally.add(lookups[i], &device[4 * i], data.texture.channels);
    }
    tally.print("device");
    EXPECT_EQ(tally.failures(), "");
  }
}

TEST(PtexFilterKernel, OutOfRangeFacesGiveZerosOnTheDevice) {
  const PtexFilterData data = build_ptex_filter_data(read_ptex_stored(ptex_assets_dir() + "/rand_lo.ptx"));
  PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
  launcher.load(data);
  PtexFilterQuery bad{};
  bad.face = 9;
  bad.filter = SEAMCL_PTEX_BILINEAR;
  bad.u = bad.v = 0.5f;
  PtexFilterQuery good = bad;
  good.face = 0;
  const std::vector<float> out = launcher.run({bad, good});
  for (int c = 0; c < 4; ++c) EXPECT_EQ(out[c], 0.0f);
  EXPECT_GT(out[4], 0.0f);
}

}  // namespace
}  // namespace seamcl
