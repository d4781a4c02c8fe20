// Per-face displacement maps: what a tessellated patch reads to move its vertices along the
// surface normal (kernels/tessellate.cl). Kept beside the scene, not inside its colour textures,
// because displacement is sampled at vertices, from one explicit level, with its own seam rules.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace seamcl {

// A grid of columns x rows samples spanning its face from corner to corner: sample (0, 0) lies at
// uv (0, 0) and sample (columns-1, rows-1) at uv (1, 1), so a face's edge samples lie exactly on
// its edges. Values are unsigned 16-bit, read as value / 65535 in [0, 1]. Row 0 is at v = 0.
// An empty map (0 x 0) means the face is not displaced.
struct DisplacementMap {
  int columns = 0;
  int rows = 0;
  std::vector<uint16_t> samples;

  bool empty() const { return columns == 0; }
  uint16_t at(int i, int j) const { return samples[static_cast<size_t>(j) * columns + i]; }
  uint16_t& at(int i, int j) { return samples[static_cast<size_t>(j) * columns + i]; }
};

// Level `level` of a map: every 2^level-th sample along each axis, the last one always kept (so
// the corners stay the corners), down to 2 samples a side (1 for a side that has 1).
DisplacementMap displacement_level(const DisplacementMap& map, int level);

inline constexpr int kMaxDisplacementSamplesPerSide = 4097;
inline constexpr float kMaxDisplacementScale = 1e6f;

struct Displacement {
  std::vector<DisplacementMap> maps;  // one per face of the scene, in face order
  float scale = 0.1f;                 // world units of one unit of displacement
  std::string source;                 // where the maps came from (a generator or a file), for messages
};

// Throws InputError (field "displacement") unless there is one map per face (face_count), each
// empty or 1..kMaxDisplacementSamplesPerSide samples a side with columns * rows samples, and the
// scale is finite and within +-kMaxDisplacementScale.
void validate_displacement(const Displacement& displacement, size_t face_count);

}  // namespace seamcl
