#include "scene/displacement_map.h"

#include <algorithm>
#include <cmath>

#include <seamcl/core/input_error.h>

namespace seamcl {

DisplacementMap displacement_level(const DisplacementMap& map, int level) {
  if (map.empty() || level <= 0) return map;
  auto reduced = [&](int side) { return side <= 1 ? side : std::max(((side - 1) >> std::min(level, 30)) + 1, 2); };
  DisplacementMap out;
  out.columns = reduced(map.columns);
  out.rows = reduced(map.rows);
  out.samples.resize(static_cast<size_t>(out.columns) * out.rows);
  // Index i of the level stands for sample i * (side - 1) / (level side - 1) of level 0: the
  // same as i << level on 2^k + 1 grids, and the corners stay the corners on any grid.
  auto source = [](int i, int side, int reduced_side) {
    return reduced_side <= 1 ? 0 : static_cast<int>(static_cast<long long>(i) * (side - 1) / (reduced_side - 1));
  };
  for (int j = 0; j < out.rows; ++j)
    for (int i = 0; i < out.columns; ++i)
      out.at(i, j) = map.at(source(i, map.columns, out.columns), source(j, map.rows, out.rows));
  return out;
}

void validate_displacement(const Displacement& displacement, size_t face_count) {
  const std::string where = displacement.source.empty() ? "" : " (" + displacement.source + ")";
  if (displacement.maps.size() != face_count) {
    throw InputError("displacement", "has " + std::to_string(displacement.maps.size()) + " maps for " +
                                         std::to_string(face_count) + " faces" + where);
  }
  if (!std::isfinite(displacement.scale) || std::fabs(displacement.scale) > kMaxDisplacementScale) {
    throw InputError("displacement", "scale must be finite and within +-1e6" + where);
  }
  for (size_t f = 0; f < displacement.maps.size(); ++f) {
    const DisplacementMap& m = displacement.maps[f];
    const bool empty = m.columns == 0 && m.rows == 0 && m.samples.empty();
    const bool sized = m.columns >= 1 && m.rows >= 1 && m.columns <= kMaxDisplacementSamplesPerSide &&
                       m.rows <= kMaxDisplacementSamplesPerSide &&
                       m.samples.size() == static_cast<size_t>(m.columns) * m.rows;
    if (!empty && !sized) {
      throw InputError("displacement", "map of face " + std::to_string(f) + " is " + std::to_string(m.columns) + "x" +
                                           std::to_string(m.rows) + " with " + std::to_string(m.samples.size()) +
                                           " samples (sides must be 1.." +
                                           std::to_string(kMaxDisplacementSamplesPerSide) + ")" + where);
    }
  }
}

}  // namespace seamcl
