#include <seamcl/scene/environment.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <seamcl/core/input_error.h>
#include <seamcl/scene/cube_map.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

glm::vec4 environment_radiance(const AnalyticEnvironment& e, glm::vec3 d) {
  glm::vec3 base;
  if (d.y >= 0.0f) {
    // The gradient: towards the zenith with height, warmer towards +x and cooler towards -x.
    const float height = std::sqrt(d.y);
    base = e.horizon + (e.zenith - e.horizon) * height + glm::vec3(0.12f, 0.0f, -0.12f) * (d.x * (1.0f - height));
  } else {
    base = e.ground * (0.75f + 0.25f * d.z);
  }
  // The spot: a Gaussian in the angle to the sun (1 - cos is half the squared angle).
  const float one_minus_cos = 1.0f - glm::dot(d, e.sun_direction);
  const float spot = std::exp(-2.0f * one_minus_cos / (e.sun_radius * e.sun_radius));
  const glm::vec3 color = glm::clamp(base * (1.0f - spot) + e.sun_color * spot, 0.0f, 1.0f);
  return {color, 1.0f};
}

namespace {

constexpr std::array<std::string_view, 3> kLayoutNames{"equirect", "cross", "faces"};  // enum order

std::string image_size_text(int width, int height) { return std::to_string(width) + " x " + std::to_string(height); }

// Bilinear at continuous texel coordinates (x, y), texel centres at integers, in a width x height
// block of `texels` starting at `first`; x wraps when `wrap_x`, else clamps; y clamps.
glm::vec3 bilinear(const std::vector<glm::vec3>& texels, size_t first, int width, int height, float x, float y,
                   bool wrap_x) {
  if (!std::isfinite(x)) x = 0;
  if (!std::isfinite(y)) y = 0;
  y = std::clamp(y, 0.0f, static_cast<float>(height - 1));
  if (!wrap_x) x = std::clamp(x, 0.0f, static_cast<float>(width - 1));
  const float fx = std::floor(x), fy = std::floor(y);
  const float ax = x - fx, ay = y - fy;
  auto column = [width, wrap_x](long i) -> long {
    if (wrap_x) return ((i % width) + width) % width;
    return std::clamp(i, 0L, static_cast<long>(width - 1));
  };
  const long i0 = column(static_cast<long>(fx)), i1 = column(static_cast<long>(fx) + 1);
  const long j0 = static_cast<long>(fy), j1 = std::min(j0 + 1, static_cast<long>(height - 1));
  auto at = [&](long i, long j) { return texels[first + static_cast<size_t>(j) * width + static_cast<size_t>(i)]; };
  return (at(i0, j0) * (1 - ax) + at(i1, j0) * ax) * (1 - ay) + (at(i0, j1) * (1 - ax) + at(i1, j1) * ax) * ay;
}

// The cells of the faces +X, -X, +Y, -Y, +Z, -Z in a horizontal and a vertical cross.
constexpr std::array<glm::ivec2, 6> kHorizontalCells{{{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}}};
constexpr std::array<glm::ivec2, 6> kVerticalCells{{{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {1, 3}}};

}  // namespace

std::optional<EnvironmentLayout> parse_environment_layout(std::string_view name) {
  for (size_t i = 0; i < kLayoutNames.size(); ++i)
    if (kLayoutNames[i] == name) return static_cast<EnvironmentLayout>(i);
  return std::nullopt;
}

std::string to_string(EnvironmentLayout layout) { return std::string(kLayoutNames[static_cast<size_t>(layout)]); }

std::vector<std::string> environment_layout_names() { return {kLayoutNames.begin(), kLayoutNames.end()}; }

EnvironmentImage environment_image_from_pixels(EnvironmentLayout layout, const std::vector<DecodedImage>& images,
                                               const std::vector<std::string>& fields) {
  const size_t expected = layout == EnvironmentLayout::Faces ? 6 : 1;
  if (images.size() != expected || fields.size() != expected)
    throw InputError(fields.empty() ? "environment" : fields[0],
                     "layout '" + to_string(layout) + "' needs " + std::to_string(expected) + " image(s)");
  size_t total = 0;
  for (size_t k = 0; k < images.size(); ++k) {
    const DecodedImage& image = images[k];
    if (image.width < 1 || image.height < 1 || image.width > kMaxEnvironmentImageSide ||
        image.height > kMaxEnvironmentImageSide)
      throw InputError(fields[k], "is " + image_size_text(image.width, image.height) + "; each side must be in 1.." +
                                      std::to_string(kMaxEnvironmentImageSide));
    if (image.pixels.size() != static_cast<size_t>(image.width) * image.height)
      throw InputError(fields[k], "holds " + std::to_string(image.pixels.size()) + " pixels for " +
                                      image_size_text(image.width, image.height));
    total += image.pixels.size();
    if (total > kMaxEnvironmentTexels)
      throw InputError(fields[k], "the environment's images hold more than " + std::to_string(kMaxEnvironmentTexels) +
                                      " texels");
    for (size_t p = 0; p < image.pixels.size(); ++p) {
      const glm::vec4& v = image.pixels[p];
      if (!std::isfinite(v.r) || !std::isfinite(v.g) || !std::isfinite(v.b))
        throw InputError(fields[k], "texel (" + std::to_string(p % image.width) + ", " +
                                        std::to_string(p / image.width) + ") is not finite");
      if (std::fabs(v.r) > kMaxColorMagnitude || std::fabs(v.g) > kMaxColorMagnitude || std::fabs(v.b) > kMaxColorMagnitude)
        throw InputError(fields[k], "texel (" + std::to_string(p % image.width) + ", " +
                                        std::to_string(p / image.width) + ") has a magnitude over 1e9");
    }
  }
  EnvironmentImage out;
  if (layout == EnvironmentLayout::Equirect) {
    const DecodedImage& image = images[0];
    if (image.width != 2 * image.height)
      throw InputError(fields[0], "is " + image_size_text(image.width, image.height) +
                                      "; layout 'equirect' needs width = 2 x height");
    out.width = image.width;
    out.height = image.height;
    out.texels.reserve(image.pixels.size());
    for (const glm::vec4& v : image.pixels) out.texels.emplace_back(v);
    return out;
  }
  out.cube = true;
  if (layout == EnvironmentLayout::Faces) {
    const int n = images[0].width;
    for (size_t k = 0; k < 6; ++k)
      if (images[k].width != images[k].height || images[k].width != n)
        throw InputError(fields[k], "is " + image_size_text(images[k].width, images[k].height) +
                                        "; the six faces must be square and of one size (" + image_size_text(n, n) + ")");
    out.width = n;
    out.height = 6 * n;
    for (const DecodedImage& image : images)
      for (const glm::vec4& v : image.pixels) out.texels.emplace_back(v);
    return out;
  }
  // A cross: 4 x 3 or 3 x 4 cells of n x n.
  const DecodedImage& image = images[0];
  const bool horizontal = image.width * 3 == image.height * 4 && image.width % 4 == 0;
  const bool vertical = image.width * 4 == image.height * 3 && image.width % 3 == 0;
  if (!horizontal && !vertical)
    throw InputError(fields[0], "is " + image_size_text(image.width, image.height) +
                                    "; layout 'cross' needs 4 x 3 or 3 x 4 square faces (width : height = 4 : 3 or "
                                    "3 : 4, a whole number of texels per face)");
  const int n = horizontal ? image.width / 4 : image.width / 3;
  out.width = n;
  out.height = 6 * n;
  out.texels.resize(static_cast<size_t>(6) * n * n);
  for (int face = 0; face < 6; ++face) {
    const glm::ivec2 cell = (horizontal ? kHorizontalCells : kVerticalCells)[static_cast<size_t>(face)];
    const bool turned = !horizontal && face == 5;  // the vertical cross's -Z hangs below -Y
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const int si = turned ? n - 1 - i : i, sj = turned ? n - 1 - j : j;
        const size_t source = static_cast<size_t>(cell.y * n + sj) * image.width + static_cast<size_t>(cell.x * n + si);
        out.texels[(static_cast<size_t>(face) * n + j) * n + i] = glm::vec3(image.pixels[source]);
      }
  }
  return out;
}

glm::vec4 environment_image_radiance(const EnvironmentImage& image, glm::vec3 d) {
  if (image.texels.empty()) return {0, 0, 0, 1};
  if (!image.cube) {
    constexpr float kPi = 3.14159265358979f;
    const float length = glm::length(d);
    const glm::vec3 u = length > 0 && std::isfinite(length) ? d / length : glm::vec3(0, 1, 0);
    const float s = 0.5f + std::atan2(u.x, -u.z) / (2 * kPi);
    const float t = std::acos(std::clamp(u.y, -1.0f, 1.0f)) / kPi;
    return {bilinear(image.texels, 0, image.width, image.height, s * static_cast<float>(image.width) - 0.5f,
                     t * static_cast<float>(image.height) - 0.5f, true),
            1.0f};
  }
  const CubeCoords c = cube_coords(d);
  const int n = image.width;
  const float side = static_cast<float>(n);
  const float x = (c.sc + 1) * 0.5f * side - 0.5f, y = (c.tc + 1) * 0.5f * side - 0.5f;
  return {bilinear(image.texels, static_cast<size_t>(c.face) * n * n, n, n, x, y, false), 1.0f};
}

DirectionFunction environment_function(const Environment& environment) {
  if (environment.image) {
    const std::shared_ptr<const EnvironmentImage> image = environment.image;
    return [image](glm::vec3 d) { return environment_image_radiance(*image, d); };
  }
  if (environment.files)
    throw InputError(environment.files->field + (environment.files->layout == EnvironmentLayout::Faces ? ".faces" : ".file"),
                     "names image files that were not read: only scenes loaded through seamcl's scene files "
                     "(load_scene_source) may name files");
  if (environment.constant) {
    const glm::vec4 c(*environment.constant, 1.0f);
    return [c](glm::vec3) { return c; };
  }
  const AnalyticEnvironment analytic = environment.analytic;
  return [analytic](glm::vec3 d) { return environment_radiance(analytic, d); };
}

void validate_environment(const Environment& e) {
  if (e.cube_size < 1 || e.cube_size > kMaxCubeSize || (e.cube_size & (e.cube_size - 1)) != 0) {
    throw InputError("environment.cube_size", "must be a power of two in 1.." + std::to_string(kMaxCubeSize) +
                                                  ", got " + std::to_string(e.cube_size));
  }
  if (e.bake_samples < 1 || e.bake_samples > 8) {
    throw InputError("environment.bake_samples", "must be in 1..8, got " + std::to_string(e.bake_samples));
  }
  auto finite = [](glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (e.constant) check_color(*e.constant, "environment.constant");
  if (e.files) {
    if (e.constant) throw InputError("environment.constant", "cannot go with an image environment (file or faces)");
    const size_t expected = e.files->layout == EnvironmentLayout::Faces ? 6 : 1;
    if (e.files->names.size() != expected)
      throw InputError(e.files->layout == EnvironmentLayout::Faces ? "environment.faces" : "environment.file",
                       "must name " + std::to_string(expected) + " file(s)");
  }
  const AnalyticEnvironment& a = e.analytic;
  if (!finite(a.sun_direction) || glm::length(glm::dvec3(a.sun_direction)) < 1e-6) {
    throw InputError("environment.sun_direction", "must be a finite, non-zero vector");
  }
  if (!(a.sun_radius > 0.0f && a.sun_radius <= 3.2f)) {
    throw InputError("environment.sun_radius", "must be in (0, 3.2] radians");
  }
  if (!finite(a.sun_color) || !finite(a.zenith) || !finite(a.horizon) || !finite(a.ground)) {
    throw InputError("environment", "colours must be finite");
  }
}

}  // namespace seamcl
