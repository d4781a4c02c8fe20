// The scalar twin of kernels/downsample.cl, and the taps both use: what the tests hold the kernel
// to, bit for bit.
#pragma once
#include <functional>
#include <vector>

#include <glm/glm.hpp>

namespace seamcl {

// One axis's filter for an integer factor: output pixel o reads source pixels o * factor + first + k
// (k < weights.size(), clamped into the image) with these weights, which sum to 1.
struct DownsampleTaps {
  int factor = 1;
  int first = 0;
  std::vector<float> weights;
};

// The taps of `filter` (a function of the distance in output pixels, zero at and beyond
// radius) centred on each output pixel's centre: every source pixel whose centre lies strictly
// within `radius` output pixels, weighted by filter(distance) in double, normalised to sum 1,
// then rounded to float. std::invalid_argument for factor < 1, radius <= 0 or more than 64 taps.
DownsampleTaps separable_taps(int factor, double radius, const std::function<double(double)>& filter);

// width x height linear RGBA reduced by taps.factor on both axes (sizes multiples of it): rows
// first into a width / factor x height image, then columns, in the kernel's order of operations.
// std::invalid_argument for sizes that are not multiples or pixels of the wrong count.
std::vector<glm::vec4> downsample_twin(const std::vector<glm::vec4>& pixels, int width, int height,
                                       const DownsampleTaps& taps);

}  // namespace seamcl
