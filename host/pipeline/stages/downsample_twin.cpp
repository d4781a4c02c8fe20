#include "pipeline/stages/downsample_twin.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace seamcl {

namespace {
constexpr int kMaxTaps = 64;  // SEAMCL_MAX_DOWNSAMPLE_TAPS
}

DownsampleTaps separable_taps(int factor, double radius, const std::function<double(double)>& filter) {
  if (factor < 1 || !(radius > 0.0)) throw std::invalid_argument("separable_taps: factor must be >= 1 and radius > 0");
  DownsampleTaps taps;
  taps.factor = factor;
  // Output pixel 0's centre lies at source coordinate factor / 2; source pixel i's at i + 0.5.
  const double centre = factor / 2.0;
  const double reach = radius * factor;
  const int first = static_cast<int>(std::floor(centre - reach - 0.5)) + 1;
  std::vector<double> weights;
  double sum = 0.0;
  for (int i = first; i + 0.5 < centre + reach; ++i) {
    const double distance = (i + 0.5 - centre) / factor;
    if (std::fabs(distance) >= radius) continue;  // only at the very first tap, by rounding
    if (weights.empty()) taps.first = i;
    weights.push_back(filter(distance));
    sum += weights.back();
  }
  if (weights.empty() || weights.size() > kMaxTaps || !(sum != 0.0)) {
    throw std::invalid_argument("separable_taps: " + std::to_string(weights.size()) + " taps (1.." +
                                std::to_string(kMaxTaps) + " with a non-zero sum)");
  }
  for (double w : weights) taps.weights.push_back(static_cast<float>(w / sum));
  return taps;
}

std::vector<glm::vec4> downsample_twin(const std::vector<glm::vec4>& pixels, int width, int height,
                                       const DownsampleTaps& taps) {
  const int f = taps.factor;
  if (f < 1 || width < f || height < f || width % f != 0 || height % f != 0 ||
      pixels.size() != static_cast<size_t>(width) * static_cast<size_t>(height) || taps.weights.empty()) {
    throw std::invalid_argument("downsample_twin: " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not a multiple of " + std::to_string(f));
  }
  const int out_w = width / f, out_h = height / f, n = static_cast<int>(taps.weights.size());
  auto clamp = [](int v, int hi) { return v < 0 ? 0 : (v > hi ? hi : v); };
  std::vector<glm::vec4> mid(static_cast<size_t>(out_w) * static_cast<size_t>(height));
  for (int y = 0; y < height; ++y) {
    for (int ox = 0; ox < out_w; ++ox) {
      float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;
      for (int k = 0; k < n; ++k) {
        const glm::vec4& p = pixels[static_cast<size_t>(y) * width + clamp(ox * f + taps.first + k, width - 1)];
        const float w = taps.weights[static_cast<size_t>(k)];
        r = r + w * p.x;
        g = g + w * p.y;
        b = b + w * p.z;
        a = a + w * p.w;
      }
      mid[static_cast<size_t>(y) * out_w + ox] = glm::vec4(r, g, b, a);
    }
  }
  std::vector<glm::vec4> out(static_cast<size_t>(out_w) * static_cast<size_t>(out_h));
  for (int oy = 0; oy < out_h; ++oy) {
    for (int ox = 0; ox < out_w; ++ox) {
      float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;
      for (int k = 0; k < n; ++k) {
        const glm::vec4& p = mid[static_cast<size_t>(clamp(oy * f + taps.first + k, height - 1)) * out_w + ox];
        const float w = taps.weights[static_cast<size_t>(k)];
        r = r + w * p.x;
        g = g + w * p.y;
        b = b + w * p.z;
        a = a + w * p.w;
      }
      out[static_cast<size_t>(oy) * out_w + ox] = glm::vec4(r, g, b, a);
    }
  }
  return out;
}

}  // namespace seamcl
