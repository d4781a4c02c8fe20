// Damaged and hostile Ptex files: truncations at every section boundary and elsewhere, byte flips
// in every section, absurd header, face, level and tile values, for each sample file and for
// written files with alpha, constant faces, tiles and metadata. Each case must either parse to a
// file that keeps every invariant the renderer relies on (validate_scene included) or be refused
// with InputError: no crash, no other exception, no hang, no allocation past the limits (the
// sanitizer build, Ptex.FuzzUnderSanitizers, also caps any single allocation through ASan).
// Deterministic: fixed seeds, no std distributions.
#include <gtest/gtest.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/core/input_error.h>
#include <seamcl/scene/scene.h>

#include "ptex_test_writer.h"

namespace seamcl {
namespace {

using namespace seamcl_tests;

uint64_t get_le(const std::vector<uint8_t>& b, size_t at, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v |= uint64_t(b[at + i]) << (8 * i);
  return v;
}
void set_le(std::vector<uint8_t>& b, size_t at, int bytes, uint64_t v) {
  for (int i = 0; i < bytes; ++i) b[at + i] = static_cast<uint8_t>(v >> (8 * i));
}
void set_le_ptr(uint8_t* p, uint32_t v) {
  for (int i = 0; i < 4; ++i) p[i] = static_cast<uint8_t>(v >> (8 * i));
}

std::vector<uint8_t> unzip(const std::vector<uint8_t>& file, size_t at, size_t size, size_t raw_size) {
  std::vector<uint8_t> raw(raw_size);
  uLongf out = static_cast<uLongf>(raw_size);
  if (uncompress(raw.data(), &out, file.data() + at, static_cast<uLong>(size)) != Z_OK || out != raw_size)
    throw std::runtime_error("seed file: a zlib block does not inflate");
  return raw;
}

// Where the sections of a (well-formed) seed file lie, read with the format's own arithmetic.
struct Sections {
  uint32_t faces = 0, ext_bytes = 0, face_info_bytes = 0, const_bytes = 0;
  uint16_t levels = 0, channels = 0;
  size_t face_info = 0, const_data = 0, level_info = 0, level_data = 0, metadata = 0, pixel_bytes = 0;
  std::vector<size_t> level_start, level_bytes, level_header_bytes, level_faces;
};

Sections sections_of(const std::vector<uint8_t>& b) {
  Sections s;
  s.channels = static_cast<uint16_t>(get_le(b, 20, 2));
  s.levels = static_cast<uint16_t>(get_le(b, 22, 2));
  s.faces = static_cast<uint32_t>(get_le(b, 24, 4));
  s.ext_bytes = static_cast<uint32_t>(get_le(b, 28, 4));
  s.face_info_bytes = static_cast<uint32_t>(get_le(b, 32, 4));
  s.const_bytes = static_cast<uint32_t>(get_le(b, 36, 4));
  const int element = std::array<int, 4>{1, 2, 2, 4}[get_le(b, 12, 4) & 3];
  s.pixel_bytes = size_t(element) * s.channels;
  s.face_info = 64 + s.ext_bytes;
  s.const_data = s.face_info + s.face_info_bytes;
  s.level_info = s.const_data + s.const_bytes;
  s.level_data = s.level_info + get_le(b, 40, 4);
  size_t at = s.level_data;
  for (int k = 0; k < s.levels; ++k) {
    s.level_start.push_back(at);
    s.level_bytes.push_back(get_le(b, s.level_info + 16 * k, 8));
    s.level_header_bytes.push_back(get_le(b, s.level_info + 16 * k + 8, 4));
    s.level_faces.push_back(get_le(b, s.level_info + 16 * k + 12, 4));
    at += s.level_bytes.back();
  }
  s.metadata = at;
  return s;
}

// The file with the zlib block [at, at + size) replaced by `replacement`; the caller fixes sizes.
std::vector<uint8_t> splice(const std::vector<uint8_t>& b, size_t at, size_t size, const std::vector<uint8_t>& replacement) {
  std::vector<uint8_t> out(b.begin(), b.begin() + static_cast<ptrdiff_t>(at));
  append(out, replacement);
  out.insert(out.end(), b.begin() + static_cast<ptrdiff_t>(at + size), b.end());
  return out;
}

// Face info changed through `edit` (20 bytes of face `face`), re-zipped, sizes fixed.
std::vector<uint8_t> with_face_info(const std::vector<uint8_t>& b, uint32_t face,
                                    const std::function<void(uint8_t*)>& edit) {
  const Sections s = sections_of(b);
  std::vector<uint8_t> raw = unzip(b, s.face_info, s.face_info_bytes, size_t(s.faces) * 20);
  edit(&raw[size_t(face) * 20]);
  const std::vector<uint8_t> zipped = zip(raw);
  std::vector<uint8_t> out = splice(b, s.face_info, s.face_info_bytes, zipped);
  set_le(out, 32, 4, zipped.size());
  return out;
}

// The constant data replaced by `raw` (any size), re-zipped.
std::vector<uint8_t> with_constant_data(const std::vector<uint8_t>& b, const std::vector<uint8_t>& raw) {
  const Sections s = sections_of(b);
  const std::vector<uint8_t> zipped = zip(raw);
  std::vector<uint8_t> out = splice(b, s.const_data, s.const_bytes, zipped);
  set_le(out, 36, 4, zipped.size());
  return out;
}

// Level k's block header of rank r set to `header`, the level header re-zipped, sizes fixed.
std::vector<uint8_t> with_block_header(const std::vector<uint8_t>& b, int k, size_t r, uint32_t header) {
  const Sections s = sections_of(b);
  std::vector<uint8_t> raw = unzip(b, s.level_start[k], s.level_header_bytes[k], s.level_faces[k] * 4);
  set_le(raw, r * 4, 4, header);
  const std::vector<uint8_t> zipped = zip(raw);
  std::vector<uint8_t> out = splice(b, s.level_start[k], s.level_header_bytes[k], zipped);
  const int64_t growth = int64_t(zipped.size()) - int64_t(s.level_header_bytes[k]);
  set_le(out, s.level_info + 16 * k, 8, uint64_t(int64_t(s.level_bytes[k]) + growth));
  set_le(out, s.level_info + 16 * k + 8, 4, zipped.size());
  set_le(out, 48, 8, get_le(b, 48, 8) + uint64_t(growth));
  return out;
}

// --- Seeds -------------------------------------------------------------------------------------

std::vector<uint8_t> u8s(std::initializer_list<int> v) {
  std::vector<uint8_t> out;
  for (int x : v) out.push_back(static_cast<uint8_t>(x));
  return out;
}

// uint8 RGBA (alpha 3), three faces: 8x8 zipped with a stored 4x4 reduction, a constant 16x4, and
// 16x8 in four tiles (one constant, one diffzipped) with a stored 8x4 reduction; a quad mesh in
// the metadata, its positions in the large metadata.
PtexTestFile alpha_tiles_mesh_seed() {
  PtexTestFile f;
  f.channels = 4;
  f.alpha_channel = 3;
  auto texels = [](int n, int salt) {
    std::vector<uint8_t> out;
    for (int t = 0; t < n; ++t)
      for (int c = 0; c < 4; ++c) out.push_back(static_cast<uint8_t>(c == 3 ? 128 + (t + salt) % 100 : (7 * t + 31 * c + salt) % 256));
    return out;
  };
  f.faces = {{3, 3, 0, {1, 2, -1, -1}, 0, u8s({10, 20, 30, 200})},
             {4, 2, 1, {-1, -1, -1, 0}, 0, u8s({40, 50, 60, 255})},
             {4, 3, 8, {-1, -1, -1, 0}, 0, u8s({70, 80, 90, 100})}};
  std::vector<PtexBlock> tiles;
  for (int t = 0; t < 4; ++t) tiles.push_back(t == 1 ? constant_block(u8s({1, 2, 3, 4})) : data_block(texels(32, t), 32, 4, 1, t == 2));
  f.levels = {{data_block(texels(64, 0), 64, 4, 1, true), PtexBlock{kEncConstant, {}}, tiled_block(3, 2, tiles)},
              {data_block(texels(16, 5), 16, 4, 1, true), data_block(texels(32, 9), 32, 4, 1, false)}};
  append(f.metadata, metadata_entry("PtexFaceVertCounts", 3, u8s({4, 0, 0, 0, 4, 0, 0, 0, 4, 0, 0, 0})));
  append(f.metadata, metadata_entry("PtexFaceVertIndices", 3,
                                    u8s({0, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 1, 0, 0, 0, 4, 0, 0, 0,
                                         5, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 2, 0, 0, 0, 6, 0, 0, 0, 7, 0, 0, 0})));
  append(f.metadata, metadata_entry("name", 0, u8s({'s', 'e', 'e', 'd', 0})));
  std::vector<uint8_t> positions;
  for (int v = 0; v < 100; ++v)
    for (int c = 0; c < 3; ++c) put_f32(positions, static_cast<float>((v * 3 + c) % 7) * 0.5f);
  f.add_large_metadata("PtexVertPositions", 4, positions);
  return f;
}

// float32, two channels, two faces of 4x8 and 8x4 texels (zipped), neighbours of each other.
PtexTestFile float_seed() {
  PtexTestFile f;
  f.data_type = 3;
  f.channels = 2;
  auto texels = [](int n, float scale) {
    std::vector<uint8_t> out;
    for (int t = 0; t < 2 * n; ++t) put_f32(out, scale * static_cast<float>(t % 13) - 1.0f);
    return out;
  };
  std::vector<uint8_t> c0, c1;
  put_f32(c0, 0.5f);
  put_f32(c0, -0.5f);
  put_f32(c1, 2.0f);
  put_f32(c1, 3.0f);
  f.faces = {{2, 3, 0, {-1, 1, -1, -1}, 3 << 2, c0}, {3, 2, 0, {-1, -1, -1, 0}, 1 << 6, c1}};
  f.levels = {{data_block(texels(32, 0.25f), 32, 2, 4), data_block(texels(32, 1.5f), 32, 2, 4)}};
  return f;
}

struct Seed {
  std::string name;
  std::vector<uint8_t> bytes;
  bool big = false;  // decoding all of it takes long: fewer cases that can leave it whole
};

std::vector<Seed> seeds() {
  std::vector<Seed> out;
  for (const char* name : {"black", "rand_lo", "wave_lo", "cellnoise", "cube_text"}) {
    std::vector<uint8_t> bytes = read_bytes(ptex_assets_dir() + "/" + name + ".ptx");
    const bool big = bytes.size() > 100000;
    out.push_back({name, std::move(bytes), big});
  }
  out.push_back({"written alpha+tiles+mesh", write_ptex(alpha_tiles_mesh_seed()), false});
  out.push_back({"written float32", write_ptex(float_seed()), false});
  return out;
}

// --- Checks ------------------------------------------------------------------------------------

// What the renderer and the scene loader rely on, for a file that parsed.
void expect_invariants(PtexFile file, const PtexLimits& limits, const std::string& what) {
  ASSERT_TRUE(file.channels >= 1 && file.channels <= 4) << what;
  ASSERT_TRUE(file.alpha_channel >= -1 && file.alpha_channel < file.channels) << what;
  ASSERT_FALSE(file.faces.empty()) << what;
  ASSERT_EQ(file.textures.size(), file.faces.size()) << what;
  ASSERT_LE(ptex_texel_count(file), limits.max_texels) << what;
  const int faces = static_cast<int>(file.faces.size());
  Scene scene;
  scene.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (int f = 0; f < faces; ++f) {
    const PtexFaceInfo& info = file.faces[f];
    ASSERT_TRUE(info.ulog2 >= 0 && info.ulog2 <= limits.max_side_log2 && info.vlog2 >= 0 &&
                info.vlog2 <= limits.max_side_log2)
        << what << " face " << f;
    for (int e = 0; e < 4; ++e) {
      ASSERT_TRUE(info.adjacent_faces[e] >= -1 && info.adjacent_faces[e] < faces) << what << " face " << f;
      ASSERT_LE(info.adjacent_edges[e], 3) << what;
    }
    ASSERT_EQ(file.textures[f].width(), 1 << info.ulog2) << what << " face " << f;
    ASSERT_EQ(file.textures[f].height(), 1 << info.vlog2) << what << " face " << f;
    scene.faces.push_back(Face{{0, 1, 2, 3}, std::move(file.textures[f])});
  }
  try {
    validate_scene(scene);
  } catch (const InputError& e) {
    FAIL() << what << ": parsed, but validate_scene refuses it: " << e.what();
  }
  if (file.mesh) {
    ASSERT_EQ(file.mesh->faces.size(), file.faces.size()) << what;
    for (const auto& quad : file.mesh->faces)
      for (uint32_t v : quad) ASSERT_LT(v, file.mesh->positions.size()) << what;
  }
}

struct Tally {
  int cases = 0;
  int parsed = 0;
  int refused = 0;
  std::set<std::string> refusal_kinds;  // messages up to their second colon, numbers as N
};

void run_case(const std::vector<uint8_t>& bytes, const PtexLimits& limits, const std::string& what, Tally& tally) {
  ++tally.cases;
  try {
    PtexFile file = parse_ptex(bytes, limits);
    ++tally.parsed;
    expect_invariants(std::move(file), limits, what);
  } catch (const InputError& e) {
    ++tally.refused;
    ASSERT_EQ(e.field(), "texture") << what;
    std::string kind;
    for (char c : std::string(e.what()).substr(0, std::string(e.what()).find(':', 9)))
      if (!std::isdigit(static_cast<unsigned char>(c))) kind += c;
      else if (kind.empty() || kind.back() != 'N') kind += 'N';
    tally.refusal_kinds.insert(kind);
  } catch (const std::exception& e) {
    FAIL() << what << ": threw something other than InputError: " << e.what();
  }
}

// --- The cases ---------------------------------------------------------------------------------

void fuzz_seed(const Seed& seed, const PtexLimits& limits, Tally& tally) {
  const std::vector<uint8_t>& good = seed.bytes;
  const Sections s = sections_of(good);
  std::mt19937 rng(static_cast<uint32_t>(good.size()));  // a fixed seed per file
  auto random_below = [&](size_t n) { return n == 0 ? size_t(0) : static_cast<size_t>(rng() % n); };
  auto check = [&](const std::vector<uint8_t>& bytes, const std::string& what) {
    run_case(bytes, limits, seed.name + ": " + what, tally);
  };

  // Truncations at every section boundary (and one byte either side), then at other offsets.
  std::set<size_t> cuts;
  std::vector<size_t> boundaries = {0, 4, 20, 63, 64, 64 + s.ext_bytes, s.face_info, s.const_data, s.level_info,
                                    s.level_data, s.metadata, good.size()};
  for (int k = 0; k < s.levels; ++k) {
    boundaries.push_back(s.level_start[k]);
    boundaries.push_back(s.level_start[k] + s.level_header_bytes[k]);
  }
  for (size_t b : boundaries)
    for (size_t c : {b - 1, b, b + 1})
      if (b > 0 && c < good.size()) cuts.insert(c);
  const size_t others = seed.big ? 100 : std::min<size_t>(good.size(), 800);
  for (size_t i = 0; i < others; ++i) cuts.insert(seed.big ? random_below(good.size()) : i * good.size() / others);
  for (size_t cut : cuts) check(std::vector<uint8_t>(good.begin(), good.begin() + static_cast<ptrdiff_t>(cut)),
                                "truncated to " + std::to_string(cut) + " bytes");

  // Byte flips: anywhere (small files), and in the header, face info, level info and level
  // headers, where one flip changes the most.
  const size_t header_end = seed.big ? s.level_data + s.level_header_bytes[0] : good.size();
  for (int i = 0; i < (seed.big ? 40 : 500); ++i) {
    std::vector<uint8_t> bytes = good;
    const size_t at = i % 2 ? random_below(std::min<size_t>(header_end, s.level_data + 64)) : random_below(header_end);
    const int span = i % 5 == 0 ? 3 : 1;
    for (int j = 0; j < span && at + j < bytes.size(); ++j) bytes[at + j] ^= static_cast<uint8_t>(1 + random_below(255));
    check(bytes, "bytes flipped at " + std::to_string(at));
  }

  // Absurd header values.
  struct Field {
    const char* name;
    size_t at;
    int bytes;
    std::vector<uint64_t> values;
  };
  const uint64_t all = ~uint64_t(0);
  const std::vector<Field> fields = {
      {"version", 4, 4, {0, 2, all}},
      {"meshtype", 8, 4, {0, 2, all}},
      {"datatype", 12, 4, {0, 1, 2, 3, 4, all}},
      {"alphachan", 16, 4, {uint64_t(-2) & 0xffffffff, s.channels, 1000, 0x7fffffff, 0x80000000}},
      {"nchannels", 20, 2, {0, 1, 2, 3, 4, 5, 1000, 0xffff}},
      {"nlevels", 22, 2, {0, 1, uint64_t(s.levels) + 1, 13, 14, 100, 0xffff}},
      {"nfaces", 24, 4, {0, 1, s.faces - 1u, s.faces + 1u, 1u << 20, (1u << 20) + 1, 0x7fffffff, 0xffffffff}},
      {"extheadersize", 28, 4, {0, 1, 8, 24, 40, 41, 1u << 30, 0xffffffff}},
      {"faceinfosize", 32, 4, {0, s.face_info_bytes - 1u, s.face_info_bytes + 1u, 0xffffffff}},
      {"constdatasize", 36, 4, {0, s.const_bytes - 1u, s.const_bytes + 1u, 0xffffffff}},
      {"levelinfosize", 40, 4, {0, 15, uint64_t(16) * s.levels + 16, 0xffffffff}},
      {"leveldatasize", 48, 8, {0, get_le(good, 48, 8) - 1, get_le(good, 48, 8) + 1, uint64_t(1) << 63, all, all - 60}},
      {"metadatazipsize", 56, 4, {0, 1, 0xffffffff}},
      {"metadatamemsize", 60, 4, {0, 1, 1u << 30, 0xffffffff}},
  };
  for (const Field& field : fields)
    for (uint64_t value : field.values) {
      // Values that leave the file as it was (or, for the big files, may: their metadata size
      // while they have none) would only decode it whole again.
      if (value == get_le(good, field.at, field.bytes)) continue;
      if (seed.big && std::string(field.name) == "metadatazipsize") continue;
      std::vector<uint8_t> bytes = good;
      set_le(bytes, field.at, field.bytes, value);
      check(bytes, std::string("header ") + field.name + " = " + std::to_string(value));
    }
  // The extended header's sizes and positions, where the file has them.
  const std::vector<std::pair<size_t, int>> ext_fields = {{8, 4}, {12, 4}, {16, 8}, {24, 8}, {32, 8}};
  for (const auto& [offset, width] : ext_fields) {
    if (offset + width > s.ext_bytes) continue;
    for (uint64_t value : {uint64_t(1), uint64_t(0xffffffff), all, all - 7, uint64_t(good.size())}) {
      std::vector<uint8_t> bytes = good;
      set_le(bytes, 64 + offset, width, value);
      check(bytes, "extended header +" + std::to_string(offset) + " = " + std::to_string(value));
    }
  }

  // Absurd face info: sizes up to 127 and negative, neighbours out of range, every flag.
  struct FaceEdit {
    const char* name;
    std::function<void(uint8_t*)> edit;
    bool may_keep_the_file_whole = false;  // not tried on the big files
  };
  const int32_t faces = static_cast<int32_t>(s.faces);
  const std::vector<FaceEdit> face_edits = {
      {"ulog2 127", [](uint8_t* p) { p[0] = 127; }},
      {"ulog2 -1", [](uint8_t* p) { p[0] = 0xff; }},
      {"vlog2 -128", [](uint8_t* p) { p[1] = 0x80; }},
      {"ulog2 13", [](uint8_t* p) { p[0] = 13; }},
      {"ulog2 + 1", [](uint8_t* p) { p[0] = static_cast<uint8_t>(p[0] + 1); }},
      {"vlog2 - 1", [](uint8_t* p) { p[1] = static_cast<uint8_t>(p[1] - 1); }},
      {"res 0x0", [](uint8_t* p) { p[0] = p[1] = 0; }},
      {"adjedges 0xff", [](uint8_t* p) { p[2] = 0xff; }, true},
      {"constant", [](uint8_t* p) { p[3] = 1; }, true},
      {"not constant", [](uint8_t* p) { p[3] = 0; }, true},
      {"edited", [](uint8_t* p) { p[3] = 2; }},
      {"all flags", [](uint8_t* p) { p[3] = 0xff; }},
      {"adjface -2", [](uint8_t* p) { set_le_ptr(p + 4, uint32_t(-2)); }},
      {"adjface nfaces", [faces](uint8_t* p) { set_le_ptr(p + 8, uint32_t(faces)); }},
      {"adjface INT_MIN", [](uint8_t* p) { set_le_ptr(p + 12, 0x80000000u); }},
      {"adjface INT_MAX", [](uint8_t* p) { set_le_ptr(p + 16, 0x7fffffffu); }},
  };
  for (int n = 0; n < (seed.big ? 1 : 3); ++n) {
    const uint32_t face = n == 0 ? 0 : static_cast<uint32_t>(random_below(s.faces));
    for (const FaceEdit& e : face_edits)
      if (!(seed.big && e.may_keep_the_file_whole)) check(with_face_info(good, face, e.edit), "face " + std::to_string(face) + " " + e.name);
  }

  // Constant data one texel short or long, or all ones (nan for float types).
  std::vector<uint8_t> constants = unzip(good, s.const_data, s.const_bytes, size_t(s.faces) * s.pixel_bytes);
  check(with_constant_data(good, std::vector<uint8_t>(constants.begin(), constants.end() - 1)), "constant data short");
  constants.push_back(0);
  check(with_constant_data(good, constants), "constant data long");
  if (!seed.big) check(with_constant_data(good, std::vector<uint8_t>(constants.size() - 1, 0xff)), "constant data all 0xff");

  // Level info: sizes that overflow, run past the file, or disagree; face counts out of range.
  for (int k = 0; k < s.levels; ++k) {
    const size_t at = s.level_info + 16 * k;
    for (uint64_t v : {uint64_t(0), uint64_t(s.level_bytes[k] - 1), uint64_t(s.level_bytes[k] + 1), uint64_t(1) << 63, all}) {
      std::vector<uint8_t> bytes = good;
      set_le(bytes, at, 8, v);
      check(bytes, "level " + std::to_string(k) + " size " + std::to_string(v));
    }
    for (uint64_t v : {uint64_t(0), uint64_t(s.level_header_bytes[k] + 1), uint64_t(0xffffffff)}) {
      std::vector<uint8_t> bytes = good;
      set_le(bytes, at + 8, 4, v);
      check(bytes, "level " + std::to_string(k) + " header size " + std::to_string(v));
    }
    for (uint64_t v : {uint64_t(0), uint64_t(s.level_faces[k] + 1), uint64_t(s.level_faces[k] - 1), uint64_t(0xffffffff)}) {
      std::vector<uint8_t> bytes = good;
      set_le(bytes, at + 12, 4, v);
      check(bytes, "level " + std::to_string(k) + " faces " + std::to_string(v));
    }
  }

  // Face block headers: sizes past the level and the file, every encoding.
  if (!seed.big) {
    for (int k = 0; k < std::min<int>(s.levels, 2); ++k)
      for (int n = 0; n < 3; ++n) {
        const size_t r = random_below(s.level_faces[k]);
        const std::vector<uint8_t> raw = unzip(good, s.level_start[k], s.level_header_bytes[k], s.level_faces[k] * 4);
        const uint32_t header = static_cast<uint32_t>(get_le(raw, r * 4, 4));
        const uint32_t size = header & 0x3fffffff;
        for (uint32_t v : {0u, size - 1, size + 1, 0x3fffffffu})
          check(with_block_header(good, k, r, (header & 0xc0000000u) | (v & 0x3fffffffu)),
                "level " + std::to_string(k) + " block " + std::to_string(r) + " size " + std::to_string(v));
        for (uint32_t encoding = 0; encoding < 4; ++encoding)
          check(with_block_header(good, k, r, size | (encoding << 30)),
                "level " + std::to_string(k) + " block " + std::to_string(r) + " encoding " + std::to_string(encoding));
      }
  }
}

// Structures only the written seeds have: tiles and metadata made wrong.
void fuzz_written_structures(const PtexLimits& limits, Tally& tally) {
  auto check = [&](const PtexTestFile& f, const std::string& what) {
    run_case(write_ptex(f), limits, "written: " + what, tally);
  };
  const PtexTestFile base = alpha_tiles_mesh_seed();
  // The tiled face (face 2, level 0): tile sizes and the tile header size.
  for (int tu : {-1, 0, 4, 5, 127})
    for (int tv : {-128, 0, 2, 3, 4}) {
      PtexTestFile f = base;
      f.levels[0][2].bytes[0] = static_cast<uint8_t>(tu);
      f.levels[0][2].bytes[1] = static_cast<uint8_t>(tv);
      check(f, "tile size " + std::to_string(tu) + "x" + std::to_string(tv));
    }
  for (uint32_t v : {0u, 1u, 1000u, 0xffffffffu}) {
    PtexTestFile f = base;
    std::vector<uint8_t>& b = f.levels[0][2].bytes;
    for (int i = 0; i < 4; ++i) b[2 + i] = static_cast<uint8_t>(v >> (8 * i));
    check(f, "tile header size " + std::to_string(v));
  }
  {
    PtexTestFile f = base;  // a tile that is itself tiled
    std::vector<PtexBlock> tiles(4, constant_block(u8s({1, 2, 3, 4})));
    tiles[3] = tiled_block(0, 0, {constant_block(u8s({1, 2, 3, 4}))});
    f.levels[0][2] = tiled_block(3, 2, tiles);
    check(f, "nested tiles");
  }
  {
    PtexTestFile f = base;  // a constant block of the wrong size
    f.levels[0][0] = constant_block(u8s({1, 2, 3}));
    check(f, "short constant block");
  }
  // Metadata: key sizes, value sizes and types made wrong; a mesh made wrong.
  const std::vector<std::pair<std::string, std::vector<uint8_t>>> entries = {
      {"key size 0", u8s({0, 0, 1, 0, 0, 0, 7})},
      {"key past the end", u8s({200, 'a', 0})},
      {"value size past the end", u8s({2, 'a', 0, 0, 0xff, 0xff, 0xff, 0x7f})},
      {"type 9", metadata_entry("t", 9, u8s({1, 2}))},
      {"int32 of 3 bytes", metadata_entry("t", 3, u8s({1, 2, 3}))},
      {"cut entry", u8s({2, 'a', 0, 0})},
      {"counts of 5", metadata_entry("PtexFaceVertCounts", 3, u8s({4, 0, 0, 0, 5, 0, 0, 0, 4, 0, 0, 0}))},
      {"counts as floats", metadata_entry("PtexFaceVertCounts", 4, u8s({4, 0, 0, 0, 4, 0, 0, 0, 4, 0, 0, 0}))},
      {"index -1", metadata_entry("PtexFaceVertIndices", 3, std::vector<uint8_t>(48, 0xff))},
      {"index 100", metadata_entry("PtexFaceVertIndices", 3, u8s({100, 0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 1, 0, 0, 0, 4, 0, 0, 0,
                                                                   5, 0, 0, 0, 2, 0, 0, 0, 3, 0, 0, 0, 2, 0, 0, 0, 6, 0, 0, 0, 7, 0, 0, 0}))},
      {"too few indices", metadata_entry("PtexFaceVertIndices", 3, u8s({0, 0, 0, 0}))},
  };
  for (const auto& [name, entry] : entries) {
    PtexTestFile f = base;
    append(f.metadata, entry);  // later entries replace earlier ones of the same key
    check(f, "metadata " + name);
  }
  for (const auto& [name, entry] : entries) {
    PtexTestFile f = base;
    f.metadata = entry;  // alone: the mesh then lacks entries
    check(f, "metadata alone " + name);
  }
  {
    PtexTestFile f = base;  // positions not finite
    std::vector<uint8_t> nan(12 * 8, 0xff);
    f.large_metadata_headers.clear();
    f.large_metadata_data.clear();
    f.add_large_metadata("PtexVertPositions", 4, nan);
    check(f, "nan positions");
  }
  for (size_t at : {size_t(0), size_t(1), size_t(20), size_t(24)}) {
    for (uint32_t v : {0u, 1u, 0xffffffffu}) {
      PtexTestFile f = base;  // large metadata header entries: key size, value size, zip size
      std::vector<uint8_t>& h = f.large_metadata_headers;
      for (int i = 0; i < 4 && at + i < h.size(); ++i) h[at + i] = static_cast<uint8_t>(v >> (8 * i));
      check(f, "large metadata header +" + std::to_string(at) + " = " + std::to_string(v));
    }
  }
}

TEST(Ptex, FuzzNeverCrashes) {
  // Small limits for the written and small seeds keep every case cheap; the big samples need the
  // default texel limit to parse at all.
  PtexLimits small;
  small.max_texels = 1 << 22;
  small.max_metadata_bytes = 1 << 20;
  Tally tally;
  for (const Seed& seed : seeds()) {
    const auto start = std::chrono::steady_clock::now();
    const int before = tally.cases;
    fuzz_seed(seed, seed.big ? PtexLimits{} : small, tally);
    if (HasFatalFailure()) return;
    std::printf("[ fuzz     ] %-26s %5d cases, %6.0f ms\n", seed.name.c_str(), tally.cases - before,
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  fuzz_written_structures(small, tally);
  std::printf("[ fuzz     ] %d cases: %d parsed, %d refused (%zu kinds of refusal)\n", tally.cases, tally.parsed,
              tally.refused, tally.refusal_kinds.size());
  EXPECT_GE(tally.cases, 2000);
  // Both outcomes occur: the cases are neither all harmless nor all rejected at the first check.
  EXPECT_GT(tally.parsed, 20);
  EXPECT_GT(tally.refused, 1000);
  EXPECT_GT(tally.refusal_kinds.size(), 10u);
}

}  // namespace
}  // namespace seamcl
