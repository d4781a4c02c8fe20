// kernels/ptex_filter.cl against its scalar twin (host/pipeline/stages/ptex_filter_twin.cpp): the
// golden lookups of every sample, and random lookups of every filter near edges and corners
// (cellnoise: valence 3, 4 and 9 and faces of mixed resolutions; rand_lo: uint16 with boundary
// edges; black: float16, black border), widths from a texel to more than a face; and the device
// against the Ptex library itself on every value of tests/assets/ptex/golden_filters/.
#include <gtest/gtest.h>
#include <glm/gtc/packing.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <limits>
#include <random>
#include <set>
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
using seamcl_tests::data_block;
using seamcl_tests::kEncConstant;
using seamcl_tests::ptex_assets_dir;
using seamcl_tests::PtexBlock;
using seamcl_tests::PtexTestFile;
using seamcl_tests::write_ptex;

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

// One face of 16 x 16 texels of float32 (data type 3) or float16 (2), of 1 to 4 channels, with
// values outside 0..1 of both signs; with `pair`, a second such face of other values right of it
// (its left edge on the first's right edge).
PtexFilterData float_face(uint32_t data_type, int channels, bool pair = false) {
  PtexTestFile spec;
  spec.data_type = data_type;
  spec.channels = static_cast<uint16_t>(channels);
  const int element_bytes = data_type == 3 ? 4 : 2;
  const auto put = [&](std::vector<uint8_t>& out, float value) {
    uint8_t bytes[4];
    if (data_type == 3) {
      std::memcpy(bytes, &value, 4);
    } else {
      const uint16_t half = static_cast<uint16_t>(glm::packHalf1x16(value));
      std::memcpy(bytes, &half, 2);
    }
    out.insert(out.end(), bytes, bytes + element_bytes);
  };
  std::vector<PtexBlock> blocks;
  for (int face = 0; face < (pair ? 2 : 1); ++face) {
    std::vector<uint8_t> level0;
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 16; ++i) {
        const float values[4] = {std::sin(0.7f * i) + 0.1f * j + 3.0f * face, 2.0f * std::cos(0.5f * j),
                                 0.01f * i * j - 0.3f - face, 0.5f + 0.03f * i};
        for (int c = 0; c < channels; ++c) put(level0, values[c]);
      }
    blocks.push_back(data_block(level0, 256, channels, element_bytes));
  }
  std::vector<uint8_t> constant;
  for (int c = 0; c < channels; ++c) put(constant, 0.25f * c);
  if (pair)
    spec.faces = {{4, 4, 0, {-1, 1, -1, -1}, 3 << 2, constant}, {4, 4, 0, {-1, -1, -1, 0}, 1 << 6, constant}};
  else
    spec.faces = {{4, 4, 0, {-1, -1, -1, -1}, 0, constant}};
  spec.levels = {blocks};
  return build_ptex_filter_data(parse_ptex_stored(write_ptex(spec)));
}

// The float32 and float16 texel paths, one channel's 16-lane product and rows of several channels
// (up to 32 values, two 16-value reads), with NaN in the padding after the last texel: reads past
// a row's end must be discarded, never summed.
TEST(PtexFilterKernel, MatchesTheTwinOnFloatFacesWithNanPadding) {
  for (const auto& [data_type, channels] : {std::pair{3u, 4}, {3u, 1}, {2u, 1}, {2u, 2}}) {
    SCOPED_TRACE("data type " + std::to_string(data_type) + ", " + std::to_string(channels) + " channels");
    PtexFilterData data = float_face(data_type, channels);
    std::fill(data.texels.end() - SEAMCL_PTEX_TEXEL_TAIL, data.texels.end(), uint8_t{0xff});
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
    EXPECT_GT(wide, 200);  // width-4 kernels under a quarter face: rows of 4 to 8 taps
  }
}

// Face 0: 8 x 8 uint8 texels 3 * (8 * row + column); right of it face 1, constant `value` (so
// neither is neighbourhood-constant).
PtexFilterData textured_beside_constant(uint8_t value) {
  PtexTestFile spec;
  std::vector<uint8_t> texels;
  for (int t = 0; t < 64; ++t) texels.push_back(static_cast<uint8_t>(3 * t));
  spec.faces = {{3, 3, 0, {-1, 1, -1, -1}, 3 << 2, {90}}, {3, 3, 1, {-1, -1, -1, 0}, 1 << 6, {value}}};
  spec.levels = {{data_block(texels, 64, 1, 1), PtexBlock{kEncConstant, {}}}};
  return build_ptex_filter_data(parse_ptex_stored(write_ptex(spec)));
}

// A constant face beside a textured one holds one texel: a point lookup anywhere on it gives that
// value, as the library's point filter does, in a batch of points alone and in a mixed one.
TEST(PtexFilterKernel, PointLookupsOnAConstantFaceGiveItsValue) {
  const PtexFilterData data = textured_beside_constant(200);
  ASSERT_EQ(data.faces[1].flags & (SEAMCL_PTEX_FLAG_CONSTANT | SEAMCL_PTEX_FLAG_NEIGHBORHOOD_CONSTANT),
            SEAMCL_PTEX_FLAG_CONSTANT);
  std::vector<PtexFilterQuery> points;
  for (float u : {0.0f, 0.3f, 0.99f, 1.0f})
    for (float v : {0.0f, 0.6f, 1.0f}) {
      PtexFilterQuery q{};
      q.face = 1;
      q.filter = SEAMCL_PTEX_POINT;
      q.u = u;
      q.v = v;
      points.push_back(q);
    }
  std::vector<PtexFilterQuery> mixed = points;
  mixed.push_back(points[0]);
  mixed.back().filter = SEAMCL_PTEX_BILINEAR;
  PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
  launcher.load(data);
  const std::vector<float> alone = launcher.run(points);
  const std::vector<float> among = launcher.run(mixed);
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_FLOAT_EQ(ptex_filter_twin(data, points[i])[0], 200.0f / 255.0f) << "lookup " << i;
    EXPECT_FLOAT_EQ(alone[4 * i], 200.0f / 255.0f) << "lookup " << i;
    EXPECT_FLOAT_EQ(among[4 * i], 200.0f / 255.0f) << "lookup " << i;
    for (int c = 1; c < 4; ++c) EXPECT_EQ(alone[4 * i + c], 0.0f);
  }
}

// A batch of point lookups alone runs through ptex_point_lookups: the same values as the twin's and
// as the same lookups in a mixed batch, every type (uint8 of 1 and 3 channels, uint16, float16,
// float32 RGBA), faces out of range and points outside the face included.
TEST(PtexFilterKernel, PointBatchesMatchTheTwinAndMixedBatches) {
  std::vector<std::pair<std::string, PtexFilterData>> textures;
  for (const char* name : {"black", "cellnoise", "cube_text", "rand_lo", "wave_lo"})
    textures.emplace_back(name, build_ptex_filter_data(read_ptex_stored(ptex_assets_dir() + "/" + name + ".ptx")));
  textures.emplace_back("float rgba", float_face(3, 4));
  int bilinear_differs = 0;  // the textures where the bilinear lookup is not its point's texel
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
    bilinear.uw = bilinear.vw = 0.4f;
    mixed.push_back(bilinear);
    PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
    launcher.load(data);
    const std::vector<float> alone = launcher.run(points);
    const std::vector<float> among = launcher.run(mixed);
    int nonzero = 0;
    for (size_t i = 0; i < points.size(); ++i) {
      const std::array<float, 4> twin = ptex_filter_twin(data, points[i]);
      for (int c = 0; c < 4; ++c) {
        ASSERT_FLOAT_EQ(alone[4 * i + c], twin[c]) << name << " lookup " << i << " face " << points[i].face << " at ("
                                                   << points[i].u << ", " << points[i].v << ") channel " << c;
        ASSERT_FLOAT_EQ(among[4 * i + c], twin[c]) << name << " lookup " << i << " in the mixed batch, channel " << c;
        nonzero += twin[c] != 0.0f;
      }
      if (points[i].face < 0 || points[i].face >= faces)
        for (int c = 0; c < 4; ++c) EXPECT_EQ(alone[4 * i + c], 0.0f) << name << " face " << points[i].face;
    }
    EXPECT_GT(nonzero, static_cast<int>(points.size()) / 2) << name;
    // The batch opens with point lookups, so the point kernel runs first: the one bilinear lookup at
    // its end must still get its own filter's value, not its texel.
    const std::array<float, 4> bilinear_twin = ptex_filter_twin(data, bilinear);
    for (int c = 0; c < 4; ++c)
      EXPECT_FLOAT_EQ(among[4 * points.size() + static_cast<size_t>(c)], bilinear_twin[c]) << name << " channel " << c;
    bilinear_differs += bilinear_twin != ptex_filter_twin(data, points[5]);
    // Into the caller's memory: every value written, whatever the array held.
    std::vector<float> reused(4 * mixed.size(), std::numeric_limits<float>::quiet_NaN());
    launcher.run(mixed, reused.data());
    for (size_t i = 0; i < reused.size(); ++i) ASSERT_EQ(reused[i], among[i]) << name << " value " << i;
  }
  EXPECT_GE(bilinear_differs, 3);
}

// Bilinear and box lookups whose taps stay in their face or cross one edge run, 16 to a work-item, as vector lanes
// (ptexf_small_lanes), their taps past an edge read on the neighbour there; the rest of a
// work-item's lookups through ptexf_lookup. Every value must be the twin's, whatever shares its
// work-item and however long the batch (its last work-item part full): box kernels of 1, 2 and 3
// taps per axis, widths on texel boundaries, points on and beside face edges (neighbours turned
// every way, of other resolutions), faces out of range, other filters between, on every texel
// type and 1 to 4 channels.
TEST(PtexFilterKernel, SmallKernelsMatchTheTwinAcrossEdgesInBatchesOfAnyLength) {
  std::vector<std::pair<std::string, PtexFilterData>> textures;
  for (const char* name : {"cube_text", "cellnoise", "rand_lo", "black"})
    textures.emplace_back(name, build_ptex_filter_data(read_ptex_stored(ptex_assets_dir() + "/" + name + ".ptx")));
  textures.emplace_back("float rgba", float_face(3, 4));
  textures.emplace_back("half, 2 channels", float_face(2, 2));
  textures.emplace_back("float rgba pair", float_face(3, 4, true));
  textures.emplace_back("half pair", float_face(2, 1, true));
  // The tangent-vector edge mode turns the first two channels with the kernel across an edge.
  textures.emplace_back("cellnoise, tangent vectors", textures[1].second);
  textures.back().second.texture.edge_filter_mode = 1;
  // The quarter turns into the neighbour across the edges the lookups below cross (u or v at 0).
  std::set<int> turns;
  const float coordinates[] = {0.0f, 0.03f, 0.125f, 0.28125f, 0.5f, 0.61f, 0.875f, 0.999f, 1.0f};
  const float widths[] = {1.0f / 64, 1.0f / 16, 0.04f, 0.09f, 0.25f, 0.3f, 0.5f, 0.7f, 1.0f};
  for (const auto& [name, data] : textures) {
    const int faces = static_cast<int>(data.faces.size());
    std::mt19937 random(21);
    std::vector<PtexFilterQuery> queries;
    for (int i = 0; i < 1200; ++i) {
      PtexFilterQuery q{};
      q.face = i % 97 == 0 ? faces : static_cast<int>(random() % static_cast<unsigned>(faces));
      q.filter = i % 9 == 0 ? SEAMCL_PTEX_GAUSSIAN : i % 2 == 0 ? SEAMCL_PTEX_BOX : SEAMCL_PTEX_BILINEAR;
      q.u = coordinates[random() % 9];
      q.v = coordinates[random() % 9];
      q.uw = widths[random() % 9];
      q.vw = i % 3 == 0 ? q.uw : widths[random() % 9];
      queries.push_back(q);
    }
    PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
    launcher.load(data);
    std::vector<float> whole = launcher.run(queries);
    size_t from = 0;
    int inside = 0;
    for (size_t length : {1u, 15u, 17u, 40u, 1127u}) {
      const std::vector<PtexFilterQuery> batch(queries.begin() + static_cast<long>(from),
                                               queries.begin() + static_cast<long>(from + length));
      const std::vector<float> device = launcher.run(batch);
      ASSERT_EQ(device.size(), 4 * length);
      for (size_t i = 0; i < length; ++i) {
        const PtexFilterQuery& q = batch[i];
        const std::array<float, 4> twin = ptex_filter_twin(data, q);
        for (int c = 0; c < 4; ++c) {
          ASSERT_NEAR(device[4 * i + c], twin[c], 2e-6f + 2e-6f * std::fabs(twin[c]))
              << name << " batch of " << length << ", lookup " << i << " face " << q.face << " filter " << q.filter
              << " at (" << q.u << ", " << q.v << ") widths " << q.uw << " x " << q.vw << " channel " << c;
          ASSERT_EQ(device[4 * i + c], whole[4 * (from + i) + static_cast<size_t>(c)]) << name << " lookup " << from + i;
        }
        inside += q.face < faces && q.u > 0.1f && q.u < 0.9f && q.v > 0.1f && q.v < 0.9f && q.uw < 0.1f &&
                  q.vw < 0.1f && q.filter != SEAMCL_PTEX_GAUSSIAN;
        if (q.face < faces && q.filter != SEAMCL_PTEX_GAUSSIAN && (q.u == 0.0f) != (q.v == 0.0f)) {
          const PtexFilterFace& f = data.faces[static_cast<size_t>(q.face)];
          const int edge = q.u == 0.0f ? 3 : 0;
          if (f.adj_faces[edge] >= 0) turns.insert((edge - static_cast<int>((f.adj_edges >> (2 * edge)) & 3u) + 6) % 4);
        }
      }
      from += length;
    }
    EXPECT_GT(inside, 50) << name;
  }
  EXPECT_EQ(turns, (std::set<int>{0, 1, 2, 3}));

  // A tap of weight 0 (the point on a texel centre) is no tap: an infinite texel there must not make
  // the value NaN.
  {
    PtexFilterData data = float_face(3, 1);
    const PtexFilterFace& f = data.faces[0];
    const uint32_t level = data.level_offsets[f.level_base + static_cast<uint32_t>(4 * (f.vlog2 + 1) + 4)];
    const float infinity = std::numeric_limits<float>::infinity();
    std::memcpy(&data.texels[4 * (level + 4 * 16 + 5)], &infinity, sizeof infinity);
    PtexFilterQuery q{};
    q.filter = SEAMCL_PTEX_BILINEAR;
    q.u = q.v = 0.28125f;  // texel (4, 4)'s centre at 16 x 16: weights {1, 0} on both axes
    q.uw = q.vw = 1.0f / 16;
    PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
    launcher.load(data);
    const float twin = ptex_filter_twin(data, q)[0];
    ASSERT_TRUE(std::isfinite(twin));
    EXPECT_FLOAT_EQ(launcher.run({q})[0], twin);
  }

  // Across an edge into a constant face, whose one texel every tap there reads.
  const PtexFilterData beside_constant = textured_beside_constant(250);
  std::vector<PtexFilterQuery> across;
  for (const int filter : {SEAMCL_PTEX_BILINEAR, SEAMCL_PTEX_BOX})
    for (const float u : {0.9f, 0.95f, 0.99f})
      for (const float v : {0.3f, 0.5f})
        for (const float width : {1.0f / 8, 1.0f / 16, 0.2f}) {
          PtexFilterQuery q{};
          q.filter = filter;
          q.u = u;
          q.v = v;
          q.uw = q.vw = width;
          across.push_back(q);
        }
  PtexFilterLauncher launcher(seamcl_tests::shared_runtime());
  launcher.load(beside_constant);
  const std::vector<float> device = launcher.run(across);
  // Values past the largest texel of face 0's rows 0 to 5 (141), which the lookups reach: the
  // constant face's 250 in them.
  int above_face = 0;
  for (size_t i = 0; i < across.size(); ++i) {
    const float twin = ptex_filter_twin(beside_constant, across[i])[0];
    ASSERT_NEAR(device[4 * i], twin, 2e-6f) << "lookup " << i << " filter " << across[i].filter << " at ("
                                            << across[i].u << ", " << across[i].v << ") width " << across[i].uw;
    above_face += twin > 141.5f / 255.0f;
  }
  EXPECT_GT(above_face, 0);
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
