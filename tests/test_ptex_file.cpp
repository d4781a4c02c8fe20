// The Ptex reader: the sample files against the values the Ptex library itself read from them
// (tests/assets/ptex/golden), and small files written by tests/ptex_test_writer.h for what the
// samples lack (float32, alpha, constant faces and tiles, metadata, a mesh) or get wrong on purpose.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <set>
#include <nlohmann/json.hpp>
#include <sys/stat.h>
#include <unistd.h>

#include <seamcl/assets/obj_mesh.h>
#include <seamcl/assets/ptex_file.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/regular_file.h>
#include <seamcl/scene/scene.h>

#include "ptex_test_writer.h"

namespace seamcl {
namespace {

using nlohmann::json;
using namespace seamcl_tests;

// uint8 values become v * (1 / 255), exactly as Ptex converts them.
constexpr float kByte = 1.0f / 255.0f;


// The samples are read once: cube_text alone is 25 M texels.
const PtexFile& sample(const std::string& name) {
  static std::map<std::string, PtexFile> files;
  auto it = files.find(name);
  if (it == files.end()) it = files.emplace(name, read_ptex_file(ptex_assets_dir() + "/" + name + ".ptx")).first;
  return it->second;
}

// One quantum of the file's type: Ptex's reductions and averages round to it.
float quantum(PtexDataType type) {
  switch (type) {
    case PtexDataType::Uint8: return 1.0f / 255.0f;
    case PtexDataType::Uint16: return 1.0f / 65535.0f;
    case PtexDataType::Float16: return 1.0f / 1024.0f;  // relative, values below 1
    case PtexDataType::Float32: return 1e-6f;
  }
  return 0.0f;
}

// The file's channels as seamcl shows them: grey in R, G and B.
void expect_channels(glm::vec4 texel, const json& expected, float tolerance, const std::string& where) {
  ASSERT_GE(expected.size(), 1u) << where;
  for (int o = 0; o < 3; ++o) {
    const float want = expected.size() == 1 ? expected[0].get<float>() : expected[o].get<float>();
    EXPECT_NEAR(texel[o], want, tolerance) << where << " channel " << o;
  }
  EXPECT_EQ(texel.a, 1.0f) << where;
}

std::string expect_input_error(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), "texture") << error.what();
    return error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected InputError, got: " << error.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing thrown";
  return {};
}

std::string parse_error(const std::vector<uint8_t>& bytes, const PtexLimits& limits = {}) {
  return expect_input_error([&] { parse_ptex(bytes, limits); });
}

TEST(Ptex, ReadsGoldenFaceFacts) {
  for (const char* name : kPtexSamples) {
    SCOPED_TRACE(name);
    const PtexFile& file = sample(name);
    const json g = ptex_golden(name);
    EXPECT_EQ(static_cast<int>(file.data_type), g["data_type"].get<int>());
    EXPECT_EQ(file.channels, g["channels"].get<int>());
    EXPECT_EQ(file.alpha_channel, g["alpha_channel"].get<int>());
    ASSERT_EQ(file.faces.size(), g["faces"].get<size_t>());
    ASSERT_EQ(file.textures.size(), file.faces.size());
    ASSERT_EQ(g["face_info"].size(), file.faces.size());
    for (size_t f = 0; f < file.faces.size(); ++f) {
      const json& want = g["face_info"][f];
      const PtexFaceInfo& info = file.faces[f];
      EXPECT_EQ(info.ulog2, want["ulog2"].get<int>()) << "face " << f;
      EXPECT_EQ(info.vlog2, want["vlog2"].get<int>()) << "face " << f;
      EXPECT_EQ(info.constant, want["constant"].get<bool>()) << "face " << f;
      for (int e = 0; e < 4; ++e) {
        EXPECT_EQ(info.adjacent_faces[e], want["adjfaces"][e].get<int>()) << "face " << f << " edge " << e;
        EXPECT_EQ(info.adjacent_edges[e], want["adjedges"][e].get<int>()) << "face " << f << " edge " << e;
      }
      EXPECT_EQ(file.textures[f].width(), 1 << info.ulog2) << "face " << f;
      EXPECT_EQ(file.textures[f].height(), 1 << info.vlog2) << "face " << f;
    }
    EXPECT_TRUE(file.metadata.empty());
    EXPECT_FALSE(file.mesh.has_value());
  }
}

TEST(Ptex, ReadsGoldenValues) {
  for (const char* name : kPtexSamples) {
    SCOPED_TRACE(name);
    const PtexFile& file = sample(name);
    const json g = ptex_golden(name);
    ASSERT_EQ(g["texels"].size(), 64u);
    for (const json& t : g["texels"]) {
      const int face = t["face"].get<int>();
      const TextureLevel& level0 = file.textures.at(face).levels.at(0);
      const glm::vec4 texel = level0.at(t["u"].get<int>(), t["v"].get<int>());
      expect_channels(texel, t["value"], 2e-6f, "face " + std::to_string(face) + " texel " + t["u"].dump() + "," + t["v"].dump());
    }
  }
}

// Ptex's 1x1 level is the constant data its writer stored (the mean of the last stored reduction,
// rounded down to the type): seamcl takes it as is for the 1x1 level.
TEST(Ptex, OneByOneLevelIsTheFilesFaceAverage) {
  for (const char* name : kPtexSamples) {
    SCOPED_TRACE(name);
    const PtexFile& file = sample(name);
    const json g = ptex_golden(name);
    ASSERT_FALSE(g["face_average"].empty());
    for (size_t f = 0; f < g["face_average"].size(); ++f) {
      const TextureLevel& last = file.textures.at(f).levels.back();
      ASSERT_EQ(last.width, 1);
      ASSERT_EQ(last.height, 1);
      expect_channels(last.texels.at(0), g["face_average"][f], 2e-6f, "face " + std::to_string(f));
    }
  }
}

// Every chain has the shape of seamcl's MipChain (non-square faces included) and a scene made of
// them passes validate_scene.
TEST(Ptex, ChainsHaveSeamclShapesAndPassValidateScene) {
  for (const char* name : kPtexSamples) {
    SCOPED_TRACE(name);
    const PtexFile& file = sample(name);
    Scene scene;
    scene.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    std::set<std::pair<int, int>> sizes;  // validate_scene sees one face of each size: cheaper, as strong
    for (size_t f = 0; f < file.faces.size(); ++f) {
      const MipChain& chain = file.textures[f];
      const int width = 1 << file.faces[f].ulog2;
      const int height = 1 << file.faces[f].vlog2;
      ASSERT_EQ(chain.levels.size(), static_cast<size_t>(1 + std::max(file.faces[f].ulog2, file.faces[f].vlog2)));
      for (size_t k = 0; k < chain.levels.size(); ++k) {
        EXPECT_EQ(chain.levels[k].width, std::max(1, width >> k)) << "face " << f << " level " << k;
        EXPECT_EQ(chain.levels[k].height, std::max(1, height >> k)) << "face " << f << " level " << k;
      }
      if (sizes.insert({file.faces[f].ulog2, file.faces[f].vlog2}).second) scene.faces.push_back(Face{{0, 1, 2, 3}, chain});
    }
    EXPECT_NO_THROW(validate_scene(scene));
  }
  // rand_lo's face 2 is 8x16: stored 4x8, then 2x4, 1x2, 1x1 made here.
  const MipChain& tall = sample("rand_lo").textures[2];
  ASSERT_EQ(tall.levels.size(), 5u);
  EXPECT_EQ(tall.levels[2].width, 2);
  EXPECT_EQ(tall.levels[2].height, 4);
  EXPECT_EQ(tall.levels[3].width, 1);
  EXPECT_EQ(tall.levels[3].height, 2);
  const MipChain& wide = sample("wave_lo").textures[4];
  EXPECT_EQ(wide.levels[3].width, 2);
  EXPECT_EQ(wide.levels[3].height, 1);
}

// Each level is the 2x2 mean of the one above within one quantum of the file's type: stored
// reductions are Ptex's rounded ones, the rest are made here exactly.
TEST(Ptex, LevelsAreBoxFiltersOfTheLevelAbove) {
  for (const char* name : kPtexSamples) {
    SCOPED_TRACE(name);
    const PtexFile& file = sample(name);
    const float tolerance = quantum(file.data_type) * 1.01f;
    for (size_t f = 0; f < file.textures.size(); ++f) {
      const MipChain& chain = file.textures[f];
      for (size_t k = 1; k < chain.levels.size(); ++k) {
        const TextureLevel& fine = chain.levels[k - 1];
        const TextureLevel& coarse = chain.levels[k];
        const int sx = fine.width / coarse.width;
        const int sy = fine.height / coarse.height;
        float worst = 0.0f;
        for (int j = 0; j < coarse.height; ++j)
          for (int i = 0; i < coarse.width; ++i) {
            glm::vec4 sum(0.0f);
            for (int dy = 0; dy < sy; ++dy)
              for (int dx = 0; dx < sx; ++dx) sum += fine.at(i * sx + dx, j * sy + dy);
            const glm::vec4 d = glm::abs(coarse.at(i, j) - sum / float(sx * sy));
            worst = std::max({worst, d.r, d.g, d.b, d.a});
          }
        ASSERT_LE(worst, tolerance) << "face " << f << " level " << k;
      }
    }
  }
}

// --- Files written by the tests -------------------------------------------------------------

std::vector<uint8_t> f32_bytes(std::initializer_list<float> values) {
  std::vector<uint8_t> out;
  for (float v : values) put_f32(out, v);
  return out;
}

// A one-face float32 RGBA file (alpha channel 3) of 8x8 texels with a stored 4x4 reduction
// (premultiplied, as Ptex stores it), 2x2 made here, 1x1 from the constant data.
PtexTestFile float_rgba_file() {
  PtexTestFile file;
  file.data_type = 3;
  file.channels = 4;
  file.alpha_channel = 3;
  std::vector<uint8_t> level0;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < 8; ++i) append(level0, f32_bytes({i * 0.1f, j * 0.1f, -1.5f, 0.5f}));
  std::vector<uint8_t> level1;
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 4; ++i) append(level1, f32_bytes({0.25f * 0.5f, 0.75f * 0.5f, 2.0f * 0.5f, 0.5f}));
  file.faces = {{3, 3, 0, {-1, -1, -1, -1}, 0, f32_bytes({0.3f, 0.4f, 0.5f, 0.5f})}};
  file.levels = {{data_block(level0, 64, 4, 4)}, {data_block(level1, 16, 4, 4)}};
  return file;
}

TEST(Ptex, ReadsFloat32WithAlphaAndStraightensStoredReductions) {
  const PtexFile file = parse_ptex(write_ptex(float_rgba_file()));
  EXPECT_EQ(file.data_type, PtexDataType::Float32);
  EXPECT_EQ(file.alpha_channel, 3);
  const MipChain& chain = file.textures.at(0);
  ASSERT_EQ(chain.levels.size(), 4u);
  EXPECT_EQ(chain.levels[0].at(5, 2), glm::vec4(0.5f, 0.2f, -1.5f, 0.5f));
  EXPECT_EQ(chain.levels[1].at(3, 1), glm::vec4(0.25f, 0.75f, 2.0f, 0.5f));  // divided by alpha
  EXPECT_EQ(chain.levels[2].at(1, 1), glm::vec4(0.25f, 0.75f, 2.0f, 0.5f));  // a box of level 1
  EXPECT_EQ(chain.levels[3].at(0, 0), glm::vec4(0.3f, 0.4f, 0.5f, 0.5f));    // the constant data
}

TEST(Ptex, MapsChannelsToRgba) {
  struct Case {
    uint16_t channels;
    int32_t alpha;
    glm::vec4 expected;  // from stored values 10, 20, 30, 40 (uint8)
  };
  const Case cases[] = {
      {1, -1, glm::vec4(10, 10, 10, 255) / 255.0f}, {2, -1, glm::vec4(10, 20, 0, 255) / 255.0f},
      {2, 1, glm::vec4(10, 10, 10, 20) / 255.0f},   {3, -1, glm::vec4(10, 20, 30, 255) / 255.0f},
      {4, -1, glm::vec4(10, 20, 30, 255) / 255.0f}, {4, 0, glm::vec4(20, 30, 40, 10) / 255.0f},
      {4, 3, glm::vec4(10, 20, 30, 40) / 255.0f},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE("channels " + std::to_string(c.channels) + " alpha " + std::to_string(c.alpha));
    PtexTestFile spec;
    spec.channels = c.channels;
    spec.alpha_channel = c.alpha;
    std::vector<uint8_t> pixel;
    for (int ch = 0; ch < c.channels; ++ch) pixel.push_back(static_cast<uint8_t>(10 * (ch + 1)));
    std::vector<uint8_t> texels;
    for (int t = 0; t < 4; ++t) append(texels, pixel);
    spec.faces = {{1, 1, 0, {-1, -1, -1, -1}, 0, pixel}};
    spec.levels = {{data_block(texels, 4, c.channels, 1, true)}};
    const PtexFile file = parse_ptex(write_ptex(spec));
    for (const TextureLevel& level : file.textures.at(0).levels)
      for (const glm::vec4& t : level.texels)
        for (int o = 0; o < 4; ++o) EXPECT_NEAR(t[o], c.expected[o], 1e-6f) << "component " << o;
  }
}

// Half floats: zero, subnormals, the largest half, negative values; integer types exact.
TEST(Ptex, DecodesFloat16AndUint16) {
  const uint16_t halves[4] = {0x0001, 0x83ff, 0x7bff, 0x3c01};
  const float expected[4] = {std::ldexp(1.0f, -24), -1023.0f * std::ldexp(1.0f, -24), 65504.0f, 1.0f + 1.0f / 1024.0f};
  PtexTestFile spec;
  spec.data_type = 2;
  std::vector<uint8_t> texels;
  for (uint16_t h : halves) put_u16(texels, h);
  spec.faces = {{1, 1, 0, {-1, -1, -1, -1}, 0, {0, 0x3c}}};  // constant 1.0
  spec.levels = {{data_block(texels, 4, 1, 2)}};
  const PtexFile file = parse_ptex(write_ptex(spec));
  for (int t = 0; t < 4; ++t) EXPECT_EQ(file.textures[0].levels[0].texels[t].r, expected[t]) << "texel " << t;
  EXPECT_EQ(file.textures[0].levels[1].texels[0], glm::vec4(1, 1, 1, 1));

  spec.data_type = 1;
  texels.clear();
  for (uint16_t v : {uint16_t(0), uint16_t(65535), uint16_t(1), uint16_t(40000)}) put_u16(texels, v);
  spec.levels = {{data_block(texels, 4, 1, 2, true)}};
  const PtexFile ints = parse_ptex(write_ptex(spec));
  EXPECT_EQ(ints.textures[0].levels[0].texels[1].g, 1.0f);
  EXPECT_EQ(ints.textures[0].levels[0].texels[3].g, 40000.0f / 65535.0f);
}

// NaN, infinities and huge values would reach a render as NaN: refused, naming face and texel.
TEST(Ptex, RefusesNonFiniteTexelsNamingFaceAndTexel) {
  PtexTestFile spec;
  spec.data_type = 2;
  spec.faces = {{1, 1, 0, {-1, -1, -1, -1}, 0, {0, 0x3c}}, {1, 1, 0, {-1, -1, -1, -1}, 0, {0, 0x3c}}};
  for (uint16_t bad : {uint16_t(0x7e00), uint16_t(0x7c00), uint16_t(0xfc00)}) {
    std::vector<uint8_t> good, broken;
    for (int t = 0; t < 4; ++t) put_u16(good, 0x3800);
    for (int t = 0; t < 4; ++t) put_u16(broken, t == 3 ? bad : uint16_t(0x3800));
    spec.levels = {{data_block(good, 4, 1, 2), data_block(broken, 4, 1, 2)}};
    const std::string message = parse_error(write_ptex(spec));
    EXPECT_NE(message.find("face 1, level 0: texel (1, 1) channel 0 is "), std::string::npos) << message;
    EXPECT_NE(message.find(bad == 0x7e00 ? "nan" : "inf"), std::string::npos) << message;
  }
  PtexTestFile huge = float_rgba_file();
  huge.faces[0].constant = f32_bytes({1e30f, 0, 0, 1});
  EXPECT_NE(parse_error(write_ptex(huge)).find("face 0: constant value: channel 0 is 1e+30, beyond the limit"),
            std::string::npos);
}

TEST(Ptex, ConstantFaceIsAFullSizeChainOfItsValue) {
  PtexTestFile spec;
  spec.channels = 3;
  spec.faces = {{5, 2, 1, {1, -1, -1, -1}, 2 << 0, {255, 0, 51}}, {0, 0, 0, {-1, -1, -1, 0}, 0, {1, 2, 3}}};
  spec.faces[1].adjacent_edges = 0 << 6;
  spec.levels = {{PtexBlock{kEncConstant, {}}, constant_block({1, 2, 3})}};
  const PtexFile file = parse_ptex(write_ptex(spec));
  EXPECT_TRUE(file.faces[0].constant);
  EXPECT_EQ(file.faces[0].adjacent_faces[0], 1);
  EXPECT_EQ(file.faces[0].adjacent_edges[0], 2);
  const MipChain& chain = file.textures[0];
  ASSERT_EQ(chain.levels.size(), 6u);
  EXPECT_EQ(chain.width(), 32);
  EXPECT_EQ(chain.height(), 4);
  for (const TextureLevel& level : chain.levels)
    for (const glm::vec4& t : level.texels) EXPECT_EQ(t, glm::vec4(255, 0, 51, 255) * kByte);
  ASSERT_EQ(file.textures[1].levels.size(), 1u);  // a 1x1 face is its constant data
  EXPECT_EQ(file.textures[1].levels[0].texels[0], glm::vec4(1, 2, 3, 255) * kByte);
}

TEST(Ptex, ReadsTiledFacesWithConstantAndZippedTiles) {
  // 8x4 texels in four 4x2 tiles (row order): tile t's texel (i, j) holds 16 t + 4 j + i; tile 2 constant 99.
  PtexTestFile spec;
  std::vector<PtexBlock> tiles;
  for (int t = 0; t < 4; ++t) {
    std::vector<uint8_t> texels;
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 4; ++i) texels.push_back(static_cast<uint8_t>(16 * t + 4 * j + i));
    tiles.push_back(t == 2 ? constant_block({99}) : data_block(texels, 8, 1, 1, t == 1));
  }
  spec.faces = {{3, 2, 0, {-1, -1, -1, -1}, 0, {7}}};
  spec.levels = {{tiled_block(2, 1, tiles)}};
  const PtexFile file = parse_ptex(write_ptex(spec));
  const TextureLevel& level = file.textures[0].levels[0];
  for (int v = 0; v < 4; ++v)
    for (int u = 0; u < 8; ++u) {
      const int t = (v / 2) * 2 + u / 4;
      const int expected = t == 2 ? 99 : 16 * t + 4 * (v % 2) + u % 4;
      EXPECT_EQ(level.at(u, v).r, static_cast<float>(expected) * kByte) << u << "," << v;
    }
}

std::vector<uint8_t> i32_bytes(const std::vector<int32_t>& values) {
  std::vector<uint8_t> out;
  for (int32_t v : values) put_u32(out, static_cast<uint32_t>(v));
  return out;
}

// Two quads side by side, their mesh in the metadata; the positions in the large metadata when
// `large` (over 1024 bytes: the vertex list is padded with unused vertices).
PtexTestFile mesh_file(bool large, std::vector<int32_t> counts = {4, 4}) {
  PtexTestFile spec;
  spec.faces = {{1, 1, 0, {-1, 1, -1, -1}, 3 << 2, {1}}, {1, 1, 0, {-1, -1, -1, 0}, 1 << 6, {2}}};
  spec.levels = {{data_block({1, 1, 1, 1}, 4, 1, 1), data_block({2, 2, 2, 2}, 4, 1, 1)}};
  std::vector<float> positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0, 0, 2, 1, 0};
  if (large) positions.resize(3 * 100, 0.5f);
  std::vector<uint8_t> position_bytes;
  for (float p : positions) put_f32(position_bytes, p);
  append(spec.metadata, metadata_entry("PtexFaceVertCounts", 3, i32_bytes(counts)));
  append(spec.metadata, metadata_entry("PtexFaceVertIndices", 3, i32_bytes({0, 1, 2, 3, 1, 4, 5, 2})));
  append(spec.metadata, metadata_entry("author", 0, {'s', 'e', 'a', 'm', 0}));
  append(spec.metadata, metadata_entry("scale", 5, {0, 0, 0, 0, 0, 0, 0xf8, 0x3f}));  // 1.5 as double
  if (large) {
    spec.add_large_metadata("PtexVertPositions", 4, position_bytes);
  } else {
    append(spec.metadata, metadata_entry("PtexVertPositions", 4, position_bytes));
  }
  return spec;
}

TEST(Ptex, ReadsMetadataAndTheMeshInIt) {
  for (bool large : {false, true}) {
    SCOPED_TRACE(large ? "positions in large metadata" : "small metadata");
    const PtexFile file = parse_ptex(write_ptex(mesh_file(large)));
    ASSERT_TRUE(file.mesh.has_value());
    EXPECT_EQ(file.mesh->positions.size(), large ? 100u : 6u);
    EXPECT_EQ(file.mesh->positions[4], glm::vec3(2, 0, 0));
    ASSERT_EQ(file.mesh->faces.size(), 2u);
    EXPECT_EQ(file.mesh->faces[1], (std::array<uint32_t, 4>{1, 4, 5, 2}));
    EXPECT_EQ(file.metadata.at("author"), "seam");
    EXPECT_EQ(file.metadata.at("scale"), "1.5");
    EXPECT_EQ(file.metadata.at("PtexFaceVertCounts"), "4 4");
    if (large) EXPECT_EQ(file.metadata.at("PtexVertPositions"), "0 0 0 1 0 0 1 1 ... (300 values)");
    EXPECT_EQ(file.faces[0].adjacent_edges[1], 3);
    EXPECT_EQ(file.faces[1].adjacent_edges[3], 1);
  }
}

TEST(Ptex, RefusesWhatItDoesNotSupport) {
  // A mesh face that is not a quad.
  EXPECT_NE(parse_error(write_ptex(mesh_file(false, {4, 3}))).find("mesh face 1 has 3 vertices; seamcl reads quads only"),
            std::string::npos);
  // Triangle files.
  PtexTestFile triangles = mesh_file(false);
  triangles.mesh_type = 0;
  EXPECT_NE(parse_error(write_ptex(triangles)).find("triangle mesh"), std::string::npos);
  // More than 4 channels.
  PtexTestFile five = mesh_file(false);
  five.channels = 5;
  EXPECT_NE(parse_error(write_ptex(five)).find("5 channels; seamcl reads 1 to 4"), std::string::npos);
  // A face flagged as edited, and an edit appended to a file.
  PtexTestFile edited = mesh_file(false);
  edited.faces[1].flags = 2;
  EXPECT_NE(parse_error(write_ptex(edited)).find("face 1: the face has edits"), std::string::npos);
  std::vector<uint8_t> appended = read_bytes(ptex_assets_dir() + "/rand_lo.ptx");
  appended.insert(appended.end(), 8, 0);  // the barrier a newer writer puts after the metadata
  appended.push_back(0);                  // edit type: face data
  put_u32(appended, 30);
  appended.insert(appended.end(), 30, 0);
  EXPECT_NE(parse_error(appended).find("edits: the file holds edits"), std::string::npos);
}

TEST(Ptex, LimitsBoundWhatAFileMayAllocate) {
  // A constant 2048x2048 face is 5.6 M texels from a few bytes: within the default limit, over a small one.
  PtexTestFile spec;
  spec.faces = {{11, 11, 1, {-1, -1, -1, -1}, 0, {9}}};
  spec.levels = {{PtexBlock{kEncConstant, {}}}};
  const std::vector<uint8_t> bytes = write_ptex(spec);
  EXPECT_EQ(ptex_texel_count(parse_ptex(bytes)), 5592405u);
  PtexLimits small;
  small.max_texels = 1 << 20;
  EXPECT_NE(parse_error(bytes, small).find("5592405 texels (all levels), more than the limit of 1048576"),
            std::string::npos);
  spec.faces[0].ulog2 = 13;
  spec.faces[0].vlog2 = 12;
  EXPECT_NE(parse_error(write_ptex(spec)).find("face 0: size 2^13 x 2^12 is not 1 to 2^12 a side"), std::string::npos);
  PtexLimits few_faces;
  few_faces.max_faces = 8;
  EXPECT_NE(parse_error(read_bytes(ptex_assets_dir() + "/rand_lo.ptx"), few_faces).find("9 faces, more than the limit of 8"),
            std::string::npos);
}

// Damage to a real file: a message that says where.
TEST(Ptex, NamesThePartAtFault) {
  const std::vector<uint8_t> good = read_bytes(ptex_assets_dir() + "/rand_lo.ptx");
  std::vector<uint8_t> cut(good.begin(), good.end() - 100);
  EXPECT_NE(parse_error(cut).find("level 2: 363 bytes at offset 7043 run past the end of the file (7361 bytes)"),
            std::string::npos);
  std::vector<uint8_t> bad_magic = good;
  bad_magic[0] = 'X';
  EXPECT_NE(parse_error(bad_magic).find("header: not a Ptex file"), std::string::npos);
  std::vector<uint8_t> bad_alpha = good;
  bad_alpha[16] = 1;  // alpha channel 1 of a 1-channel file
  bad_alpha[17] = bad_alpha[18] = bad_alpha[19] = 0;
  EXPECT_NE(parse_error(bad_alpha).find("alpha channel 1 is neither -1 (none) nor a channel (0 to 0)"), std::string::npos);
  std::vector<uint8_t> flipped = good;
  flipped[good.size() - 30] ^= 0xff;  // inside level 3's only face
  EXPECT_NE(parse_error(flipped).find("face 5, level 3: its zlib stream"), std::string::npos) << parse_error(flipped);
}

TEST(Ptex, ReadFileNamesThePath) {
  const std::string missing = ptex_assets_dir() + "/no-such-file.ptx";
  EXPECT_NE(expect_input_error([&] { read_ptex_file(missing); }).find(missing + ": no such file"), std::string::npos);
  // A FIFO would block the open until something wrote to it; a directory reads as a huge size.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("seamcl_ptex_special_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "folder.ptx");
  const std::string fifo = (dir / "fifo.ptx").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(expect_input_error([&] { read_ptex_file(fifo); }).find(fifo + ": not a regular file"), std::string::npos);
  const std::string folder = (dir / "folder.ptx").string();
  EXPECT_NE(expect_input_error([&] { read_ptex_file(folder); }).find(folder + ": not a regular file"), std::string::npos);
  try {
    read_obj_file(fifo);
    ADD_FAILURE() << "a FIFO read as a mesh";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "scene");
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
  const std::filesystem::path obj = ptex_assets_dir() + "/plane.obj";
  EXPECT_NE(expect_input_error([&] { read_ptex_file(obj.string()); }).find(obj.string() + ": header: not a Ptex file"),
            std::string::npos);
}

// The readers of users' files (.ptx, .obj, scene JSON, merge's parts) open a path once and check
// the open descriptor: what was checked is what is read, even when the path is swapped for a FIFO
// after the open, and a FIFO named from the start opens without blocking and is refused.
TEST(Ptex, RegularFileChecksAndReadsOneFile) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("seamcl_regular_file_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "folder");
  const std::string fifo = (dir / "fifo").string(), plain = (dir / "plain").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::ofstream(plain, std::ios::binary) << "hello";

  EXPECT_EQ(RegularFile(fifo).refusal(), RegularFile::Refusal::NotRegular);  // with no writer: at once
  EXPECT_EQ(RegularFile((dir / "folder").string()).refusal(), RegularFile::Refusal::NotRegular);
  EXPECT_EQ(RegularFile((dir / "none").string()).refusal(), RegularFile::Refusal::Missing);
  EXPECT_EQ(RegularFile((dir / "none").string()).refusal_text(), "no such file");
  std::string text;
  EXPECT_FALSE(RegularFile(fifo).read_all(text, 100));

  RegularFile file(plain);
  ASSERT_EQ(file.refusal(), RegularFile::Refusal::None);
  EXPECT_EQ(file.size(), 5u);
  // The path now names a FIFO; the file opened is still the one read.
  std::filesystem::rename(fifo, plain);
  ASSERT_TRUE(file.read_all(text, 100));
  EXPECT_EQ(text, "hello");
  // Bounded: one byte past the bound says "too large" without reading on.
  ASSERT_TRUE(file.read_all(text, 3));
  EXPECT_EQ(text, "hell");
  std::filesystem::remove_all(dir);
}

// Deferred (issue 14): the faces hold their sizes only and the source decodes each one to exactly
// the chain an eager read stores; the whole file is still checked while parsing, so a file an
// eager read refuses is refused the same way.
TEST(Ptex, DeferredReadMakesEachFaceAsTheEagerReadAndRefusesTheSameFiles) {
  for (const char* name : {"black", "rand_lo", "wave_lo", "cellnoise", "cube_text"}) {
    SCOPED_TRACE(name);
    const PtexFile& eager = sample(name);
    const PtexFile deferred = read_ptex_file(ptex_assets_dir() + "/" + name + ".ptx", {}, true);
    EXPECT_FALSE(eager.texture_source);
    ASSERT_TRUE(deferred.texture_source);
    ASSERT_EQ(deferred.textures.size(), eager.textures.size());
    EXPECT_EQ(ptex_texel_count(deferred), ptex_texel_count(eager));
    EXPECT_EQ(deferred.metadata, eager.metadata);
    EXPECT_EQ(deferred.mesh.has_value(), eager.mesh.has_value());
    for (size_t f = 0; f < eager.textures.size(); ++f) {
      const MipChain& stored = deferred.textures[f];
      ASSERT_TRUE(is_deferred(stored));
      ASSERT_EQ(stored.levels.size(), eager.textures[f].levels.size());
      const MipChain made = deferred.texture_source(f);
      ASSERT_EQ(made.levels.size(), eager.textures[f].levels.size());
      for (size_t l = 0; l < made.levels.size(); ++l) {
        const TextureLevel& want = eager.textures[f].levels[l];
        EXPECT_TRUE(stored.levels[l].texels.empty());
        ASSERT_EQ(stored.levels[l].width, want.width);
        ASSERT_EQ(stored.levels[l].height, want.height);
        ASSERT_EQ(made.levels[l].width, want.width);
        ASSERT_EQ(made.levels[l].height, want.height);
        ASSERT_EQ(made.levels[l].texels.size(), want.texels.size());
        ASSERT_EQ(std::memcmp(made.levels[l].texels.data(), want.texels.data(), want.texels.size() * sizeof(glm::vec4)), 0)
            << "face " << f << " level " << l;
      }
    }
  }
  // A NaN in face 1's level 0: refused while parsing, deferred or not, with the same message.
  PtexTestFile spec;
  spec.data_type = 2;
  spec.faces = {{1, 1, 0, {-1, -1, -1, -1}, 0, {0, 0x3c}}, {1, 1, 0, {-1, -1, -1, -1}, 0, {0, 0x3c}}};
  std::vector<uint8_t> good, broken;
  for (int t = 0; t < 4; ++t) put_u16(good, 0x3800);
  for (int t = 0; t < 4; ++t) put_u16(broken, t == 3 ? uint16_t(0x7e00) : uint16_t(0x3800));
  spec.levels = {{data_block(good, 4, 1, 2), data_block(broken, 4, 1, 2)}};
  const std::vector<uint8_t> bytes = write_ptex(spec);
  const std::string eager_message = parse_error(bytes);
  const std::string deferred_message = expect_input_error([&] { parse_ptex(bytes, {}, true); });
  EXPECT_NE(eager_message.find("face 1, level 0: texel (1, 1) channel 0 is nan"), std::string::npos) << eager_message;
  EXPECT_EQ(deferred_message, eager_message);
}

}  // namespace
}  // namespace seamcl
