// The D3D11 standard multisample patterns (what the raster stage uses), and where a sample lies.
#pragma once
#include <cstdint>
#include <vector>

namespace seamcl {

struct SampleOffset {
  int x;  // 1/16 pixel from the pixel centre, y down, in [-8, 7]
  int y;
};

// The pattern for 1, 2, 4, 8 or 16 samples; throws std::invalid_argument otherwise.
const std::vector<SampleOffset>& sample_pattern(int sample_count);

// Fixed-point (8 sub-pixel bits) position of sample s of pixel (x, y).
inline int64_t sample_fixed_x(int x, const SampleOffset& o) { return int64_t{x} * 256 + 128 + o.x * 16; }
inline int64_t sample_fixed_y(int y, const SampleOffset& o) { return int64_t{y} * 256 + 128 + o.y * 16; }

}  // namespace seamcl
