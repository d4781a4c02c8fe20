// C++ results handed to numpy without a copy: the vector moves into a holder that a capsule owns,
// the array views the holder's bytes, and the holder is freed with the last array (or view) that
// refers to it. An image of 480x540 floats is 4 MB; a compare's, times its entries.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>
#include <nanobind/nanobind.h>

namespace seamcl::python {

// Linear RGBA pixels (row 0 at the top) as a float32 array of shape (height, width, 4).
nanobind::object rgba_array(std::vector<glm::vec4>&& pixels, int width, int height);
// One float per pixel (error distances, NaN where non-finite) as float32 (height, width).
nanobind::object float_array(std::vector<float>&& values, int width, int height);
// One byte per pixel (seam masks) as uint8 (height, width).
nanobind::object byte_array(std::vector<uint8_t>&& values, int width, int height);

}  // namespace seamcl::python
