#include <seamcl/eval/metrics.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/renderer.h>

namespace seamcl {

std::vector<double> error_curve_thresholds() {
  std::vector<double> x(kCurveSteps);
  for (int i = 0; i < kCurveSteps; ++i) x[static_cast<size_t>(i)] = std::pow(10.0, -4.0 + i / 10.0);
  return x;
}

FaceMap face_map_from_winners(const std::vector<uint32_t>& winners, const std::vector<uint32_t>& slot_faces, int width,
                              int height, int samples) {
  if (width < 1 || height < 1 || samples < 1) throw std::invalid_argument("face_map_from_winners: empty frame");
  const size_t pixels = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (winners.size() != pixels * static_cast<size_t>(samples)) {
    throw std::invalid_argument("face_map_from_winners: " + std::to_string(winners.size()) + " winners for " +
                                std::to_string(pixels) + " pixels x " + std::to_string(samples) + " samples");
  }
  auto face_of = [&](uint32_t slot) -> int32_t {
    if (slot == SEAMCL_NO_TRIANGLE) return -1;
    if (slot >= slot_faces.size()) throw std::invalid_argument("face_map_from_winners: slot out of range");
    return static_cast<int32_t>(slot_faces[slot]);
  };
  FaceMap map;
  map.width = width;
  map.height = height;
  map.face.assign(pixels, -1);
  if (samples > 1) map.mixed.assign(pixels, 0);
  for (size_t p = 0; p < pixels; ++p) {
    const uint32_t* s = winners.data() + p * static_cast<size_t>(samples);
    int32_t first = -1;
    bool mixed = false;
    const int32_t face0 = face_of(s[0]);
    for (int i = 0; i < samples; ++i) {
      const int32_t f = face_of(s[i]);
      if (first < 0) first = f;
      if (f != face0) mixed = true;
    }
    map.face[p] = first;
    if (samples > 1) map.mixed[p] = mixed ? 1 : 0;
  }
  return map;
}

FaceMap render_face_map(Renderer& renderer, const Camera& camera, RenderOptions options) {
  options.msaa = 1;
  options.shading = ShadingMode::Pixel;
  const RenderResult result = renderer.render(camera, options);
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  std::vector<uint32_t> slot_faces(setups.size());
  for (size_t i = 0; i < setups.size(); ++i) slot_faces[i] = setups[i].face;
  return face_map_from_winners(winners, slot_faces, result.width, result.height, 1);
}

std::vector<uint8_t> seam_mask(const FaceMap& faces, int radius) {
  const int w = faces.width, h = faces.height;
  const size_t n = static_cast<size_t>(w) * static_cast<size_t>(h);
  if (faces.face.size() != n || (!faces.mixed.empty() && faces.mixed.size() != n)) {
    throw std::invalid_argument("seam_mask: face map size does not match its width x height");
  }
  auto at = [&](int x, int y) { return faces.face[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)]; };
  std::vector<uint8_t> seam(n, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x);
      if (!faces.mixed.empty() && faces.mixed[i]) {
        seam[i] = 1;
        continue;
      }
      const int32_t f = at(x, y);
      if (f < 0) continue;
      const int dx[4] = {1, -1, 0, 0}, dy[4] = {0, 0, 1, -1};
      for (int k = 0; k < 4; ++k) {
        const int nx = x + dx[k], ny = y + dy[k];
        if (nx < 0 || ny < 0 || nx >= w || ny >= h) continue;
        const int32_t g = at(nx, ny);
        if (g >= 0 && g != f) seam[i] = 1;
      }
    }
  }
  // Dilate by `radius` in the Chebyshev metric: separable max over rows, then columns.
  std::vector<uint8_t> rows(n, 0), mask(n, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      uint8_t v = 0;
      for (int k = std::max(0, x - radius); k <= std::min(w - 1, x + radius) && !v; ++k) {
        v = seam[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(k)];
      }
      rows[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)] = v;
    }
  }
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      uint8_t v = 0;
      for (int k = std::max(0, y - radius); k <= std::min(h - 1, y + radius) && !v; ++k) {
        v = rows[static_cast<size_t>(k) * static_cast<size_t>(w) + static_cast<size_t>(x)];
      }
      mask[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)] = v;
    }
  }
  return mask;
}

std::vector<uint8_t> footprint_seam_mask(Renderer& renderer, const Camera& camera, RenderOptions options) {
  options.method = Method::Black;
  return renderer.render_seam_mask(camera, options);
}

namespace {
constexpr SeamMaskKind kSeamMaskKinds[] = {SeamMaskKind::Footprint, SeamMaskKind::Band};
}  // namespace

std::string to_string(SeamMaskKind kind) {
  switch (kind) {
    case SeamMaskKind::Footprint: return "footprint";
    case SeamMaskKind::Band: return "band";
  }
  return "?";
}

std::optional<SeamMaskKind> parse_seam_mask_kind(std::string_view name) {
  for (SeamMaskKind kind : kSeamMaskKinds) {
    if (to_string(kind) == name) return kind;
  }
  return std::nullopt;
}

std::vector<std::string> seam_mask_kind_names() {
  std::vector<std::string> names;
  for (SeamMaskKind kind : kSeamMaskKinds) names.push_back(to_string(kind));
  return names;
}

std::vector<uint8_t> seam_pixels_only(const std::vector<uint8_t>& mask) {
  std::vector<uint8_t> seam(mask.size());
  for (size_t i = 0; i < mask.size(); ++i) seam[i] = mask[i] == SEAMCL_MASK_SEAM ? 1 : 0;
  return seam;
}

std::vector<uint8_t> off_seam_pixels_only(const std::vector<uint8_t>& mask) {
  std::vector<uint8_t> off(mask.size());
  for (size_t i = 0; i < mask.size(); ++i) off[i] = mask[i] == SEAMCL_MASK_NONE ? 1 : 0;
  return off;
}

std::vector<glm::vec4> seam_mask_image(const std::vector<uint8_t>& mask) {
  std::vector<glm::vec4> image(mask.size());
  for (size_t i = 0; i < mask.size(); ++i)
    image[i] = mask[i] == SEAMCL_MASK_SEAM       ? glm::vec4(1)
               : mask[i] == SEAMCL_MASK_BOUNDARY ? glm::vec4(0.2f, 0.2f, 0.2f, 1.0f)
                                                 : glm::vec4(0, 0, 0, 1);
  return image;
}

std::vector<float> pixel_distances(const std::vector<glm::vec4>& test, const std::vector<glm::vec4>& reference) {
  if (test.size() != reference.size()) {
    throw std::invalid_argument("pixel_distances: " + std::to_string(test.size()) + " test pixels vs " +
                                std::to_string(reference.size()) + " reference pixels");
  }
  std::vector<float> d(test.size());
  for (size_t i = 0; i < test.size(); ++i) {
    const glm::vec3 a(test[i]), b(reference[i]);
    bool finite = true;
    for (int c = 0; c < 3; ++c) finite = finite && std::isfinite(a[c]) && std::isfinite(b[c]);
    if (!finite) {
      d[i] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    // In double, so a distance is exact to float rounding of the result.
    const double dr = double(a.r) - double(b.r), dg = double(a.g) - double(b.g), db = double(a.b) - double(b.b);
    d[i] = static_cast<float>(std::sqrt(dr * dr + dg * dg + db * db));
  }
  return d;
}

ErrorStats error_stats(const std::vector<float>& distance, const std::vector<uint8_t>* mask) {
  if (mask && mask->size() != distance.size()) throw std::invalid_argument("error_stats: mask size differs");
  // The finite distances the mask keeps, gathered without a branch per pixel (a mask's pixels
  // and a frame's NaNs come in no order a branch predictor could learn).
  std::vector<float> values(distance.size());
  size_t n = 0;
  for (size_t i = 0; i < distance.size(); ++i) {
    values[n] = distance[i];
    n += static_cast<size_t>(std::isfinite(distance[i]) && (!mask || (*mask)[i]));
  }
  values.resize(n);
  ErrorStats s;
  s.pixels = n;
  const std::vector<double> x = error_curve_thresholds();
  s.curve.assign(x.size(), 0.0);
  if (values.empty()) return s;
  // No sort: a compare takes three of these per entry and rate, and sorting was most of their time.
  // Distances are floats: thresholds compare in float, so a distance equal to x (as float) counts.
  // The thresholds padded with +inf to 64, so that those a distance reaches are counted by six
  // halvings without a branch (no finite distance reaches the padding): with the gathering above,
  // 3.5x faster than std::upper_bound and a branch per pixel on a 480x540 frame's distances.
  constexpr size_t kPadded = 64;
  static_assert(kCurveSteps < kPadded);
  std::array<float, kPadded> thresholds;
  thresholds.fill(std::numeric_limits<float>::infinity());
  for (size_t i = 0; i < x.size(); ++i) thresholds[i] = static_cast<float>(x[i]);
  // passing[k]: the distances that reach exactly k thresholds (threshold <= distance).
  std::vector<size_t> passing(x.size() + 1, 0);
  double sum = 0;
  float max = values.front();
  for (float v : values) {
    sum += v;
    max = std::max(max, v);
    size_t reached = 0;
    for (size_t step = kPadded / 2; step > 0; step /= 2)
      reached += step * static_cast<size_t>(thresholds[reached + step - 1] <= v);
    ++passing[reached];
  }
  s.mean = sum / static_cast<double>(n);
  s.max = max;
  const size_t rank = std::clamp<size_t>(static_cast<size_t>(std::ceil(0.99 * static_cast<double>(n))), 1, n);  // 1-based
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(rank - 1), values.end());
  s.p99 = values[rank - 1];
  // curve[i]: the share at or above threshold i, the distances that reach more than i thresholds.
  size_t above = 0;
  for (size_t i = x.size(); i-- > 0;) {
    above += passing[i + 1];
    s.curve[i] = static_cast<double>(above) / static_cast<double>(n);
  }
  return s;
}

ImageErrors compare_images(const std::vector<glm::vec4>& test, const std::vector<glm::vec4>& reference,
                           const std::vector<uint8_t>* mask) {
  ImageErrors e;
  e.distance = pixel_distances(test, reference);
  if (mask && mask->size() != e.distance.size()) throw std::invalid_argument("compare_images: mask size differs");
  for (size_t i = 0; i < e.distance.size(); ++i) {
    if (std::isfinite(e.distance[i])) continue;
    ++e.nan_pixels;
    if (mask && (*mask)[i] == SEAMCL_MASK_SEAM) ++e.seam_nan_pixels;
  }
  e.all = error_stats(e.distance);
  if (mask) {
    // Seam: value 1; off the seams: value 0; a footprint mask's boundary pixels (2) are neither.
    const std::vector<uint8_t> seam = seam_pixels_only(*mask);
    const std::vector<uint8_t> off = off_seam_pixels_only(*mask);
    e.seam = error_stats(e.distance, &seam);
    e.off_seam = error_stats(e.distance, &off);
    const size_t covered = static_cast<size_t>(std::count(seam.begin(), seam.end(), uint8_t{1}));
    e.seam_coverage = mask->empty() ? 0.0 : static_cast<double>(covered) / static_cast<double>(mask->size());
  } else {
    e.seam.curve.assign(static_cast<size_t>(kCurveSteps), 0.0);
    e.off_seam = e.all;
  }
  return e;
}

std::vector<glm::vec4> error_heatmap(const std::vector<float>& distance) {
  // Control points of the ramp at t = 0, 1/4, 1/2, 3/4, 1 (t = (log10 d + 4) / 4), linear RGB:
  // black, blue, red, yellow, white.
  const glm::vec3 ramp[5] = {{0, 0, 0}, {0.0f, 0.1f, 1.0f}, {1.0f, 0.05f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1, 1, 1}};
  std::vector<glm::vec4> out(distance.size());
  for (size_t i = 0; i < distance.size(); ++i) {
    const float d = distance[i];
    if (!std::isfinite(d)) {
      out[i] = {1.0f, 0.0f, 1.0f, 1.0f};
      continue;
    }
    if (d <= 0.0f) {
      out[i] = {0.0f, 0.0f, 0.0f, 1.0f};
      continue;
    }
    const float t = std::clamp((std::log10(d) + 4.0f) / 4.0f, 0.0f, 1.0f) * 4.0f;
    const int k = std::min(3, static_cast<int>(t));
    const glm::vec3 c = glm::mix(ramp[k], ramp[k + 1], t - static_cast<float>(k));
    out[i] = glm::vec4(c, 1.0f);
  }
  return out;
}

}  // namespace seamcl
