// A small Ptex writer for the reader's tests: files with what the sample files lack (float32,
// alpha, constant faces and tiles, metadata, a mesh, large metadata) and files made wrong on
// purpose. It lays the sections out as the Ptex library does (docs/ptex-format.md) but decides
// nothing itself: the test gives every face's blocks, level by level.
#pragma once
#include <zlib.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace seamcl_tests {

inline std::string ptex_assets_dir() { return std::string(SEAMCL_TEST_ASSETS_DIR) + "/ptex"; }

// The sample files of tests/assets/ptex/, each with values the Ptex library wrote (golden/).
inline constexpr const char* kPtexSamples[] = {"black", "cellnoise", "cube_text", "rand_lo", "wave_lo"};

// tests/assets/ptex/golden/<name>.json: what the Ptex library read from the sample <name>.ptx.
inline nlohmann::json ptex_golden(const std::string& name) {
  std::ifstream in(ptex_assets_dir() + "/golden/" + name + ".json");
  return nlohmann::json::parse(in);
}

inline std::vector<uint8_t> read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}

inline void put_u16(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(static_cast<uint8_t>(v));
  out.push_back(static_cast<uint8_t>(v >> 8));
}
inline void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
inline void put_u64(std::vector<uint8_t>& out, uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}
inline void put_f32(std::vector<uint8_t>& out, float f) {
  uint32_t bits;
  std::memcpy(&bits, &f, sizeof bits);
  put_u32(out, bits);
}
inline void append(std::vector<uint8_t>& out, const std::vector<uint8_t>& more) {
  out.insert(out.end(), more.begin(), more.end());
}

inline std::vector<uint8_t> zip(const std::vector<uint8_t>& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::vector<uint8_t> out(size);
  if (compress2(out.data(), &size, raw.data(), static_cast<uLong>(raw.size()), 6) != Z_OK)
    throw std::runtime_error("compress2 failed");
  out.resize(size);
  return out;
}

enum : uint32_t { kEncConstant = 0, kEncZipped = 1, kEncDiffZipped = 2, kEncTiled = 3 };

// A face's (or a tile's) block as stored: its encoding and its bytes.
struct PtexBlock {
  uint32_t encoding = kEncZipped;
  std::vector<uint8_t> bytes;
};

// Stored values, interleaved (texel by texel, channel by channel), each `element_bytes` long.
// Zipped: channels made planar; diffzipped: also differenced (integer types, as Ptex does).
inline PtexBlock data_block(const std::vector<uint8_t>& interleaved, int texels, int channels, int element_bytes,
                            bool difference = false) {
  std::vector<uint8_t> planar(interleaved.size());
  for (int t = 0; t < texels; ++t)
    for (int c = 0; c < channels; ++c)
      std::memcpy(&planar[(size_t(c) * texels + t) * element_bytes],
                  &interleaved[(size_t(t) * channels + c) * element_bytes], element_bytes);
  if (difference && element_bytes == 1) {
    uint8_t previous = 0;
    for (uint8_t& v : planar) {
      const uint8_t value = v;
      v = static_cast<uint8_t>(value - previous);
      previous = value;
    }
  } else if (difference && element_bytes == 2) {
    uint16_t previous = 0;
    for (size_t i = 0; i < planar.size(); i += 2) {
      const uint16_t value = static_cast<uint16_t>(planar[i] | (planar[i + 1] << 8));
      const uint16_t delta = static_cast<uint16_t>(value - previous);
      planar[i] = static_cast<uint8_t>(delta);
      planar[i + 1] = static_cast<uint8_t>(delta >> 8);
      previous = value;
    }
  }
  return {difference ? kEncDiffZipped : kEncZipped, zip(planar)};
}

inline PtexBlock constant_block(const std::vector<uint8_t>& pixel) { return {kEncConstant, pixel}; }

// Tiles in row order, each 2^tile_ulog2 x 2^tile_vlog2 texels.
inline PtexBlock tiled_block(int tile_ulog2, int tile_vlog2, const std::vector<PtexBlock>& tiles) {
  std::vector<uint8_t> headers;
  for (const PtexBlock& tile : tiles) put_u32(headers, static_cast<uint32_t>(tile.bytes.size()) | (tile.encoding << 30));
  const std::vector<uint8_t> zipped = zip(headers);
  PtexBlock block{kEncTiled, {static_cast<uint8_t>(tile_ulog2), static_cast<uint8_t>(tile_vlog2)}};
  put_u32(block.bytes, static_cast<uint32_t>(zipped.size()));
  append(block.bytes, zipped);
  for (const PtexBlock& tile : tiles) append(block.bytes, tile.bytes);
  return block;
}

struct PtexTestFace {
  int8_t ulog2 = 0;
  int8_t vlog2 = 0;
  uint8_t flags = 0;  // 1 constant, 2 edits, 8 subface
  std::array<int32_t, 4> adjacent_faces{-1, -1, -1, -1};
  uint8_t adjacent_edges = 0;     // 2 bits per edge
  std::vector<uint8_t> constant;  // one texel: the face's constant data
};

// One metadata entry as stored: key size (with the NUL), key, type, value size, value.
inline void put_key(std::vector<uint8_t>& out, const std::string& key) {
  out.push_back(static_cast<uint8_t>(key.size() + 1));
  for (char c : key) out.push_back(static_cast<uint8_t>(c));
  out.push_back(0);
}

inline std::vector<uint8_t> metadata_entry(const std::string& key, uint8_t type, const std::vector<uint8_t>& value) {
  std::vector<uint8_t> out;
  put_key(out, key);
  out.push_back(type);
  put_u32(out, static_cast<uint32_t>(value.size()));
  append(out, value);
  return out;
}

struct PtexTestFile {
  uint32_t mesh_type = 1;
  uint32_t data_type = 0;
  int32_t alpha_channel = -1;
  uint16_t channels = 1;
  std::vector<PtexTestFace> faces;
  std::vector<std::vector<PtexBlock>> levels;  // level 0 in face order, then reductions in rfaceid order
  std::vector<uint8_t> metadata;               // entries, uncompressed; empty for none
  std::vector<uint8_t> large_metadata_headers; // entries: key size, key, type, value size, zip size
  std::vector<uint8_t> large_metadata_data;    // their zlib blocks, in order

  void add_large_metadata(const std::string& key, uint8_t type, const std::vector<uint8_t>& value) {
    const std::vector<uint8_t> zipped = zip(value);
    put_key(large_metadata_headers, key);
    large_metadata_headers.push_back(type);
    put_u32(large_metadata_headers, static_cast<uint32_t>(value.size()));
    put_u32(large_metadata_headers, static_cast<uint32_t>(zipped.size()));
    append(large_metadata_data, zipped);
  }
};

// Where each section of a written file starts, for tests that damage one.
struct PtexLayout {
  size_t face_info = 0, const_data = 0, level_info = 0, level_data = 0, metadata = 0, barrier = 0,
         large_metadata = 0, end = 0;
};

inline std::vector<uint8_t> write_ptex(const PtexTestFile& file, PtexLayout* layout = nullptr) {
  std::vector<uint8_t> face_info;
  std::vector<uint8_t> constants;
  for (const PtexTestFace& face : file.faces) {
    face_info.push_back(static_cast<uint8_t>(face.ulog2));
    face_info.push_back(static_cast<uint8_t>(face.vlog2));
    face_info.push_back(face.adjacent_edges);
    face_info.push_back(face.flags);
    for (int32_t neighbour : face.adjacent_faces) put_u32(face_info, static_cast<uint32_t>(neighbour));
    append(constants, face.constant);
  }
  std::vector<uint8_t> level_info;
  std::vector<uint8_t> level_data;
  for (const std::vector<PtexBlock>& level : file.levels) {
    std::vector<uint8_t> headers;
    for (const PtexBlock& block : level) put_u32(headers, static_cast<uint32_t>(block.bytes.size()) | (block.encoding << 30));
    std::vector<uint8_t> data = zip(headers);
    const uint32_t header_bytes = static_cast<uint32_t>(data.size());
    for (const PtexBlock& block : level) append(data, block.bytes);
    put_u64(level_info, data.size());
    put_u32(level_info, header_bytes);
    put_u32(level_info, static_cast<uint32_t>(level.size()));
    append(level_data, data);
  }
  const std::vector<uint8_t> metadata = file.metadata.empty() ? std::vector<uint8_t>{} : zip(file.metadata);
  const std::vector<uint8_t> large_headers =
      file.large_metadata_headers.empty() ? std::vector<uint8_t>{} : zip(file.large_metadata_headers);
  const std::vector<uint8_t> zipped_face_info = zip(face_info);
  const std::vector<uint8_t> zipped_constants = zip(constants);

  std::vector<uint8_t> out;
  put_u32(out, 'P' | ('t' << 8) | ('e' << 16) | (uint32_t('x') << 24));
  put_u32(out, 1);
  put_u32(out, file.mesh_type);
  put_u32(out, file.data_type);
  put_u32(out, static_cast<uint32_t>(file.alpha_channel));
  put_u16(out, file.channels);
  put_u16(out, static_cast<uint16_t>(file.levels.size()));
  put_u32(out, static_cast<uint32_t>(file.faces.size()));
  put_u32(out, 40);  // extended header
  put_u32(out, static_cast<uint32_t>(zipped_face_info.size()));
  put_u32(out, static_cast<uint32_t>(zipped_constants.size()));
  put_u32(out, static_cast<uint32_t>(level_info.size()));
  put_u32(out, 0);  // minor version
  put_u64(out, level_data.size());
  put_u32(out, static_cast<uint32_t>(metadata.size()));
  put_u32(out, static_cast<uint32_t>(file.metadata.size()));
  const size_t body = 64 + 40 + zipped_face_info.size() + zipped_constants.size() + level_info.size() +
                      level_data.size() + metadata.size() + 8 + large_headers.size() + file.large_metadata_data.size();
  put_u16(out, 0);  // u border mode: clamp
  put_u16(out, 0);
  put_u16(out, 0);  // v border mode
  put_u16(out, 0);  // edge filter mode
  put_u32(out, static_cast<uint32_t>(large_headers.size()));
  put_u32(out, static_cast<uint32_t>(file.large_metadata_headers.size()));
  put_u64(out, file.large_metadata_data.size());
  put_u64(out, 0);     // edit data size
  put_u64(out, body);  // edit data position: the end
  PtexLayout at;
  at.face_info = out.size();
  append(out, zipped_face_info);
  at.const_data = out.size();
  append(out, zipped_constants);
  at.level_info = out.size();
  append(out, level_info);
  at.level_data = out.size();
  append(out, level_data);
  at.metadata = out.size();
  append(out, metadata);
  at.barrier = out.size();
  out.insert(out.end(), 8, 0);
  at.large_metadata = out.size();
  append(out, large_headers);
  append(out, file.large_metadata_data);
  at.end = out.size();
  if (layout) *layout = at;
  return out;
}

}  // namespace seamcl_tests
