// Ptex (.ptx) files: per-face textures of a quad mesh, as written by the Ptex library. The format's
// facts are in docs/ptex-format.md; every size, offset and count is checked against the file
// before it is used, so a truncated or hostile file is an InputError, never a crash or an
// allocation the file cannot justify.
#pragma once
#include <array>
#include <cstdint>
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
  bool constant = false;
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
  // maximum, grey copied to RGB, alpha 1 when the file has none. Stored reductions are used as
  // they are; missing ones are 2x2 (2x1, 1x2) box filters of the level above.
  std::vector<MipChain> textures;
  std::map<std::string, std::string> metadata;  // values rendered as text, for display
  std::optional<PtexMesh> mesh;
};

// Limits that bound what a file may make the reader allocate, beyond what the file's own size
// justifies.
struct PtexLimits {
  uint64_t max_texels = uint64_t(1) << 28;  // all levels of all faces, after decoding
  int max_faces = 1 << 20;
};

// Parses a whole file held in memory. Throws InputError(field, message) with field naming the
// part at fault ("ptex.header.nchannels", "ptex.faces[12].level 1", ...), for every malformed,
// truncated or unsupported input (triangle meshes, edits).
PtexFile parse_ptex(std::span<const uint8_t> bytes, const PtexLimits& limits = {});

// Reads and parses a file; an unreadable file is InputError("texture", ...) naming the path.
PtexFile read_ptex_file(const std::string& path, const PtexLimits& limits = {});

}  // namespace seamcl
