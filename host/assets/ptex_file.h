// Ptex (.ptx) files: per-face textures of a quad mesh, as written by the Ptex library. What is read
// and what is refused is in docs/ptex-format.md; every size, offset and count is checked against
// the file before it is used, so a truncated or hostile file is an InputError, never a crash or an
// allocation the file cannot justify.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/scene/scene.h>

namespace seamcl {

enum class PtexDataType { Uint8 = 0, Uint16 = 1, Float16 = 2, Float32 = 3 };

// One face as the file describes it. Edges are bottom, right, top, left (counter-clockwise, as
// seamcl's Face vertices 0-1, 1-2, 2-3, 3-0); adjacent_faces[e] < 0 means a mesh boundary;
// adjacent_edges[e] is the neighbour's edge id (0-3) that meets edge e.
struct PtexFaceInfo {
  int ulog2 = 0;
  int vlog2 = 0;
  bool constant = false;  // one value over the whole face (its chain is still full-size)
  bool subface = false;   // a quad of a split non-quad face (Ptex's flag; kept for display)
  std::array<int32_t, 4> adjacent_faces{-1, -1, -1, -1};
  std::array<uint8_t, 4> adjacent_edges{};
};

// The mesh a file may carry in its metadata (PtexFaceVertCounts, PtexFaceVertIndices,
// PtexVertPositions); quads only.
struct PtexMesh {
  std::vector<glm::vec3> positions;
  std::vector<std::array<uint32_t, 4>> faces;
};

struct PtexFile {
  PtexDataType data_type = PtexDataType::Uint8;
  int channels = 0;       // 1 to 4 as stored
  int alpha_channel = -1; // -1: none
  std::vector<PtexFaceInfo> faces;
  // Per face, the full chain down to 1x1 in linear RGBA float: integer types divided by their
  // maximum, grey copied to RGB, alpha 1 when the file has none (straight, not premultiplied, at
  // every level). Stored reductions are used as they are; missing ones are 2x2 (2x1, 1x2) box
  // filters of the level above; the 1x1 level is the file's constant data (Ptex's own 1x1 level).
  // Every chain passes validate_scene's checks.
  // With defer_textures (parse_ptex, read_ptex_file) the chains hold their sizes only
  // (deferred_mip_chain) and texture_source makes face f's chain, exactly what an eager read
  // stores, from the file's bytes (kept, compressed as they are, by the source): so no float copy
  // of every face exists (Scene::texture_source). Every face is still decoded once while parsing
  // and dropped, so a malformed file is refused there as it is without deferral. Thread-safe.
  std::vector<MipChain> textures;
  std::function<MipChain(size_t face)> texture_source;  // empty unless deferred
  uint64_t texture_source_bytes = 0;                     // what it keeps: the file's bytes (0 unless deferred)
  std::map<std::string, std::string> metadata;  // values rendered as text, for display
                                                // (long arrays shortened)
  std::optional<PtexMesh> mesh;
};

// Limits on what a file may make the reader allocate. Every block of the file must inflate to
// exactly the size its headers give, so decoded data is bounded by the file's size (zlib's best
// ratio is about 1000:1); a constant face, though, becomes a full-size chain from one texel, and
// these bound that too. Checked before anything is allocated.
struct PtexLimits {
  uint64_t max_texels = uint64_t(1) << 26;  // all levels of all faces: 64 Mi texels, 1 GiB as float RGBA
  int max_faces = 1 << 20;
  int max_side_log2 = 12;                   // faces up to 4096 texels a side, as validate_scene accepts
  uint64_t max_metadata_bytes = uint64_t(1) << 28;  // all metadata values, inflated
  uint64_t max_file_bytes = uint64_t(1) << 31;      // read_ptex_file only
  float max_texel_magnitude = 1e9f;  // |value| of a float texel; larger, inf or nan is refused,
                                     // so that no filter sum overflows to inf in a render
};

// Parses a whole file held in memory. Throws InputError with field "texture" and a message that
// names the part at fault ("header: nchannels 1000 is not 1 to 4", "face 12, level 1: block of
// 4000 bytes runs past the 300 bytes left in the level"), for every malformed, truncated or
// unsupported input (triangle meshes, edits, more than 4 channels).
PtexFile parse_ptex(std::span<const uint8_t> bytes, const PtexLimits& limits = {}, bool defer_textures = false);

// Reads and parses a file; every error is InputError("texture", ...) whose message starts with
// the path.
PtexFile read_ptex_file(const std::string& path, const PtexLimits& limits = {}, bool defer_textures = false);

// What the Ptex library's own filters read (host/ptexfilter/): the values as the file stores them,
// in the file's units (integers as integers, not divided by their maximum), in the file's channel
// order (no RGBA mapping, no unpremultiplying), and only the levels the file holds; the header
// fields a filter or an inspector needs besides.
struct PtexStoredFace {
  uint8_t flags = 0;             // the file's face flags: 1 constant, 2 edits, 4 neighbourhood constant, 8 subface
  std::vector<float> constant;   // the constant data (the face's 1x1 level), one value per channel
  // levels[k]: level k (2^(ulog2-k) x 2^(vlog2-k) texels, rows of texels with channels
  // interleaved) for every k the file stores for the face; empty for a constant face.
  std::vector<std::vector<float>> levels;
};

struct PtexStored {
  PtexFile file;  // faces, data type, channels, alpha, metadata, mesh; no textures
  uint32_t version = 0, minor_version = 0, mesh_type = 0;
  int levels = 0;                  // levels the file holds
  int u_border_mode = 0, v_border_mode = 0;  // 0 clamp, 1 black, 2 periodic
  int edge_filter_mode = 0;        // 0 none, 1 tanvec
  uint32_t metadata_bytes = 0;     // inflated metadata size
  std::vector<PtexStoredFace> faces;
};

// As parse_ptex and read_ptex_file (the same checks, the same errors), keeping stored values.
PtexStored parse_ptex_stored(std::span<const uint8_t> bytes, const PtexLimits& limits = {});
PtexStored read_ptex_stored(const std::string& path, const PtexLimits& limits = {});

// Texels of all levels of all faces of a file's textures (16 bytes each as float RGBA), deferred
// ones included.
uint64_t ptex_texel_count(const PtexFile& file);

}  // namespace seamcl
