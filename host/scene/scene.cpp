#include <seamcl/scene/scene.h>
#include "scene/budgeted_faces.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

constexpr int kMaxTextureSide = 4096;

bool is_power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

bool is_finite(glm::vec3 v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

bool is_finite(glm::vec4 v) { return is_finite(glm::vec3(v)) && std::isfinite(v.w); }

int log2_of_power_of_two(int n) {
  int log = 0;
  while ((1 << log) < n) ++log;
  return log;
}

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// A sine with a continuous first derivative, within 1e-3 of std::sin and several times cheaper:
// the pattern below is evaluated for every texel of every generated scene (millions), and only
// its smoothness, not its exactness, matters for showing seams.
inline float smooth_sine(float x) {
  constexpr float kInverseTwoPi = 0.15915494f;
  // Adding and subtracting 1.5 * 2^23 rounds to the nearest integer (for |t| < 2^22; beyond that
  // a float has no fraction left anyway) without a libm call, so loops over it vectorise.
  constexpr float kRoundingShift = 12582912.0f;
  float t = x * kInverseTwoPi;
  t -= (t + kRoundingShift) - kRoundingShift;  // one period, t in [-0.5, 0.5]
  const float parabola = 8.0f * t - 16.0f * t * std::fabs(t);
  return parabola + 0.225f * (parabola * std::fabs(parabola) - parabola);
}

void check_vec3(glm::vec3 v, const std::string& field) {
  if (!is_finite(v)) throw InputError(field, "must be finite");
}

// Why a camera's eye, target and up give no view ("eye must differ from camera.target", "up is
// parallel to the view direction", ...: the member at fault first), or nothing when they do.
std::optional<std::string> camera_problem(const Camera& camera) {
  const glm::vec3 view = camera.target - camera.eye;
  const float view_length = glm::length(view);
  const float scale = glm::length(camera.eye) + glm::length(camera.target);
  if (!(view_length > 1e-6f * scale) || !std::isfinite(view_length)) return "eye must differ from camera.target";
  const float up_length = glm::length(camera.up);
  if (!(up_length > 0.0f) || !std::isfinite(up_length)) return "up must be non-zero";
  const float sine_between = glm::length(glm::cross(view / view_length, camera.up / up_length));
  if (!(sine_between > 1e-4f)) return "up is parallel to the view direction";
  return std::nullopt;
}


void check_texture(const MipChain& chain, const std::string& field, bool may_defer) {
  if (chain.levels.empty()) throw InputError(field, "has no mip levels");
  const int width = chain.width();
  const int height = chain.height();
  if (!is_power_of_two(width) || !is_power_of_two(height) || width > kMaxTextureSide ||
      height > kMaxTextureSide) {
    throw InputError(field, "size " + size_text(width, height) +
                                " must be powers of two from 1 to " +
                                std::to_string(kMaxTextureSide));
  }
  const size_t expected_levels =
      1 + static_cast<size_t>(log2_of_power_of_two(std::max(width, height)));
  if (chain.levels.size() != expected_levels) {
    throw InputError(field, "has " + std::to_string(chain.levels.size()) +
                                " mip levels, expected " + std::to_string(expected_levels) +
                                " (a full chain down to 1x1)");
  }
  // Deferred: every level empty, and a texture_source to fill them.
  const bool deferred = is_deferred(chain);
  if (deferred && !may_defer) throw InputError(field, "mip level 0 has no texels");
  for (size_t k = 0; k < chain.levels.size(); ++k) {
    const TextureLevel& level = chain.levels[k];
    const int expected_width = std::max(1, width >> k);
    const int expected_height = std::max(1, height >> k);
    const size_t expected_texels = deferred ? 0 : static_cast<size_t>(expected_width) * expected_height;
    if (level.width != expected_width || level.height != expected_height || level.texels.size() != expected_texels) {
      throw InputError(field, "mip level " + std::to_string(k) + " is " +
                                  size_text(level.width, level.height) + " with " +
                                  std::to_string(level.texels.size()) + " texels, expected " +
                                  size_text(expected_width, expected_height));
    }
  }
  check_texel_magnitudes(chain, field);
}

}  // namespace

TextureLevel box_downsample(const TextureLevel& fine) {
  TextureLevel coarse;
  coarse.width = std::max(1, fine.width / 2);
  coarse.height = std::max(1, fine.height / 2);
  // A side that is already 1 is not halved, so its footprint along that axis is one texel.
  const int step_x = fine.width / coarse.width;
  const int step_y = fine.height / coarse.height;
  const float weight = 1.0f / static_cast<float>(step_x * step_y);
  coarse.texels.resize(static_cast<size_t>(coarse.width) * coarse.height);
  for (int j = 0; j < coarse.height; ++j) {
    for (int i = 0; i < coarse.width; ++i) {
      glm::vec4 sum(0.0f);
      for (int dy = 0; dy < step_y; ++dy)
        for (int dx = 0; dx < step_x; ++dx) sum += fine.at(i * step_x + dx, j * step_y + dy);
      coarse.texels[static_cast<size_t>(j) * coarse.width + i] = sum * weight;
    }
  }
  return coarse;
}

MipChain build_mip_chain(TextureLevel level0) {
  if (!is_power_of_two(level0.width) || !is_power_of_two(level0.height))
    throw InputError("texture", "size " + size_text(level0.width, level0.height) +
                                    " is not a power of two on each side");
  const size_t expected = static_cast<size_t>(level0.width) * level0.height;
  if (level0.texels.size() != expected)
    throw InputError("texture", "has " + std::to_string(level0.texels.size()) +
                                    " texels, expected " + std::to_string(expected));
  MipChain chain;
  chain.levels.push_back(std::move(level0));
  while (chain.levels.back().width > 1 || chain.levels.back().height > 1)
    chain.levels.push_back(box_downsample(chain.levels.back()));
  return chain;
}

MipChain deferred_mip_chain(int width, int height) {
  MipChain chain;
  int levels = 1;
  while ((width >> (levels - 1)) > 1 || (height >> (levels - 1)) > 1) ++levels;
  // Exactly sized: a scene holds one chain per face (99,037 of them at paper's largest sweep point).
  chain.levels.reserve(static_cast<size_t>(levels));
  for (int k = 0; k < levels; ++k)
    chain.levels.push_back({std::max(1, width >> k), std::max(1, height >> k), {}});
  return chain;
}

bool is_deferred(const MipChain& chain) { return !chain.levels.empty() && chain.levels.front().texels.empty(); }

MipChain face_texture(const Scene& scene, size_t face) {
  const MipChain& stored = scene.faces.at(face).texture;
  if (!is_deferred(stored)) return stored;
  if (!scene.texture_source) throw std::logic_error("face " + std::to_string(face) + " has a deferred texture and no source");
  MipChain made = scene.texture_source(face);
  bool same_sizes = made.levels.size() == stored.levels.size();
  for (size_t k = 0; same_sizes && k < made.levels.size(); ++k)
    same_sizes = made.levels[k].width == stored.levels[k].width && made.levels[k].height == stored.levels[k].height &&
                 made.levels[k].texels.size() == static_cast<size_t>(made.levels[k].width) * made.levels[k].height;
  if (!same_sizes) throw std::logic_error("texture_source made face " + std::to_string(face) + " at another size");
  return made;
}

bool has_deferred_textures(const Scene& scene) {
  return std::any_of(scene.faces.begin(), scene.faces.end(), [](const Face& f) { return is_deferred(f.texture); });
}

void materialize_textures(Scene& scene) {
  if (!has_deferred_textures(scene)) return;
  for_each_face_in_parallel(scene.faces.size(), [&](size_t f) {
    if (is_deferred(scene.faces[f].texture)) scene.faces[f].texture = face_texture(scene, f);
  });
}

void for_each_face_in_parallel(size_t count, const std::function<void(size_t face)>& work) {
  std::atomic<size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto run_remaining = [&] {
    try {
      for (size_t f = next++; f < count; f = next++) work(f);
    } catch (...) {
      // Out of memory must reach the caller rather than terminate the process from a thread.
      const std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = count;
    }
  };
  const unsigned helper_count = face_threads() - 1;
  std::vector<std::thread> helpers;
  try {
    for (unsigned h = 0; h < helper_count && h < count; ++h) helpers.emplace_back(run_remaining);
  } catch (const std::system_error&) {
    // Fewer helpers than asked for: this thread does whatever they do not.
  }
  run_remaining();
  for (std::thread& helper : helpers) helper.join();
  if (failure) std::rethrow_exception(failure);
}

glm::vec3 face_point(const std::array<glm::vec3, 4>& corners, float u, float v) {
  const auto& [p0, p1, p2, p3] = corners;
  // Barycentric weights of (u, v) in triangle (v0, v1, v2) = uv (0,0), (1,0), (1,1) ...
  if (u >= v) return (1.0f - u) * p0 + (u - v) * p1 + v * p2;
  // ... and in triangle (v0, v2, v3) = uv (0,0), (1,1), (0,1).
  return (1.0f - v) * p0 + u * p2 + (v - u) * p3;
}

TextureLevel bake_face_texture(const std::array<glm::vec3, 4>& corners, int width, int height,
                               const SurfaceColors& surface_colors) {
  TextureLevel level;
  level.width = width;
  level.height = height;
  level.texels.resize(static_cast<size_t>(width) * height);
  std::vector<glm::vec3> row(static_cast<size_t>(width));
  for (int j = 0; j < height; ++j) {
    const float v = (static_cast<float>(j) + 0.5f) / static_cast<float>(height);
    for (int i = 0; i < width; ++i) {
      const float u = (static_cast<float>(i) + 0.5f) / static_cast<float>(width);
      row[static_cast<size_t>(i)] = face_point(corners, u, v);
    }
    surface_colors(row.data(), row.size(), &level.texels[static_cast<size_t>(j) * width]);
  }
  return level;
}

TextureLevel bake_face_texture(const std::array<glm::vec3, 4>& corners, int width, int height,
                               const std::function<glm::vec4(glm::vec3)>& surface_color) {
  return bake_face_texture(corners, width, height, [&](const glm::vec3* points, size_t count, glm::vec4* colors) {
    for (size_t i = 0; i < count; ++i) colors[i] = surface_color(points[i]);
  });
}

namespace {

// On x86-64, surface_patterns is also compiled for AVX2 (8 lanes a vector instead of SSE2's 4) and
// the CPU picks at load time. AVX2 brings no FMA, so both compute the same roundings: the
// colours are the same on every CPU.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SEAMCL_AVX2_CLONE __attribute__((target_clones("avx2", "default")))
#else
#define SEAMCL_AVX2_CLONE
#endif

// surface_pattern's waves. Each channel sums two waves with different directions and wavelengths
// (0.5 to 0.75 units, so features of 0.25 to 0.4), and the colour changes along every direction
// of every surface. Light round spots (about 0.15 units, where three wave families peak together)
// add small features in which a shifted or mismatched seam shows at once. Stripes would read as
// seams (dark lines are what black's edges look like), so there are none. Waves 0-2 and 3-5 are
// the channels' (r, g, b), 6-8 the spots'.
constexpr int kWaves = 9;
constexpr float kWaveX[kWaves] = {7.1f, -4.4f, 3.6f, -2.7f, 10.8f, 2.4f, 6.3f, -3.1f, 1.2f};
constexpr float kWaveY[kWaves] = {2.3f, 6.2f, -7.7f, 9.4f, -3.1f, 4.9f, 1.1f, 6.0f, -6.6f};
constexpr float kWaveZ[kWaves] = {-3.9f, 8.3f, 5.1f, 4.6f, 2.2f, -11.2f, 3.7f, -3.5f, 5.2f};
constexpr float kPhase[kWaves] = {0.3f, 2.9f, 4.1f, 1.7f, 0.8f, 5.3f, 0.0f, 1.3f, 2.2f};

inline float surface_wave(int k, float x, float y, float z) {
  return smooth_sine(kWaveX[k] * x + kWaveY[k] * y + kWaveZ[k] * z + kPhase[k]);
}

// The colour of surface_pattern from its nine waves' values at the point.
glm::vec4 surface_color_of_waves(const float (&sine)[kWaves]) {
  glm::vec3 color(0.5f + 0.22f * sine[0] + 0.16f * sine[3],
                  0.5f + 0.22f * sine[1] + 0.16f * sine[4],
                  0.5f + 0.22f * sine[2] + 0.16f * sine[5]);
  // Each factor (0.5 + 0.5 sin)^2 peaks once per period; their product is near 1 only where all
  // three peak at once: round spots, not lines.
  float spot = 1.0f;
  for (int k = 6; k < 9; ++k) {
    const float s = 0.5f + 0.5f * sine[k];
    spot *= s * s;
  }
  color = glm::mix(color, glm::vec3(0.95f, 0.93f, 0.85f), 0.8f * std::sqrt(spot));
  return glm::vec4(glm::clamp(color, glm::vec3(0.05f), glm::vec3(0.95f)), 1.0f);
}

}  // namespace

glm::vec4 surface_pattern(glm::vec3 p) {
  float sine[kWaves];
  for (int k = 0; k < kWaves; ++k) sine[k] = surface_wave(k, p.x, p.y, p.z);
  return surface_color_of_waves(sine);
}

SEAMCL_AVX2_CLONE void surface_patterns(const glm::vec3* points, size_t count, glm::vec4* colors) {
  // The waves of 16 points at a time, each wave over the 16 as one loop that vectorises (the
  // waves are most of the pattern's cost); the same operations in the same order as
  // surface_pattern, so every colour equals its. Two AVX2 vectors a wave rather than one keep
  // more independent work in flight: 1.3x faster on this machine's AVX2 clone (4 M points, 65 ->
  // 50 ms, 2026-12-05); 32 were slower again (55 ms).
  constexpr size_t kLanes = 16;
  for (size_t first = 0; first < count; first += kLanes) {
    const size_t lanes = std::min(kLanes, count - first);
    float x[kLanes] = {}, y[kLanes] = {}, z[kLanes] = {};
    for (size_t l = 0; l < lanes; ++l) {
      x[l] = points[first + l].x;
      y[l] = points[first + l].y;
      z[l] = points[first + l].z;
    }
    float waves[kWaves][kLanes];
    for (int k = 0; k < kWaves; ++k)
      for (size_t l = 0; l < kLanes; ++l) waves[k][l] = surface_wave(k, x[l], y[l], z[l]);
    // surface_color_of_waves lane by lane, glm's mix (x (1 - a) + y a) and clamp written out.
    float rgb[3][kLanes];
    constexpr float kSpotColor[3] = {0.95f, 0.93f, 0.85f};
    for (size_t l = 0; l < kLanes; ++l) {
      float spot = 1.0f;
      for (int k = 6; k < 9; ++k) {
        const float s = 0.5f + 0.5f * waves[k][l];
        spot *= s * s;
      }
      const float a = 0.8f * std::sqrt(spot);
      for (int c = 0; c < 3; ++c) {
        const float base = 0.5f + 0.22f * waves[c][l] + 0.16f * waves[c + 3][l];
        const float mixed = base * (1.0f - a) + kSpotColor[c] * a;
        rgb[c][l] = std::min(std::max(mixed, 0.05f), 0.95f);
      }
    }
    for (size_t l = 0; l < lanes; ++l) colors[first + l] = glm::vec4(rgb[0][l], rgb[1][l], rgb[2][l], 1.0f);
  }
}

glm::vec4 detail_pattern(glm::vec3 p, float texel_spacing) {
  // Per channel three waves of wavelengths 5, 6.3 and 7.7 texels (features of 2.5 to 3.9), in
  // directions spread over the sphere so that every surface sees them at full frequency or
  // close to it.
  constexpr float kTwoPi = 6.2831853f;
  constexpr float kWavelengths[3] = {5.0f, 6.3f, 7.7f};
  constexpr float kDirections[9][3] = {{0.80f, 0.36f, -0.48f}, {-0.31f, 0.62f, 0.72f}, {0.45f, -0.85f, 0.27f},
                                       {-0.66f, -0.21f, 0.72f}, {0.12f, 0.95f, -0.29f}, {0.93f, 0.05f, 0.36f},
                                       {0.27f, -0.49f, -0.83f}, {-0.77f, 0.59f, -0.24f}, {0.52f, 0.52f, 0.68f}};
  constexpr float kPhase[9] = {0.4f, 2.1f, 4.4f, 1.3f, 3.7f, 5.9f, 0.9f, 2.8f, 5.1f};
  const float spacing = std::max(texel_spacing, 1e-6f);
  float channel[3];
  for (int c = 0; c < 3; ++c) {
    float sum = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const float* d = kDirections[3 * c + k];
      const float frequency = kTwoPi / (kWavelengths[k] * spacing);
      sum += smooth_sine(frequency * (d[0] * p.x + d[1] * p.y + d[2] * p.z) + kPhase[3 * c + k]);
    }
    channel[c] = 0.5f + 0.15f * sum;  // three sines in [-1, 1]: [0.05, 0.95]
  }
  return glm::vec4(glm::clamp(glm::vec3(channel[0], channel[1], channel[2]), glm::vec3(0.05f), glm::vec3(0.95f)), 1.0f);
}

void set_constant_textures(Scene& scene, glm::vec4 color) {
  scene.albedo = [color](size_t, glm::vec3) { return color; };
  // No face is deferred afterwards: what made them (a .ptx's bytes, say) is no longer needed.
  scene.texture_source = {};
  scene.texture_source_bytes = 0;
  scene.texture_source_decode_bytes.clear();
  for (Face& face : scene.faces) {
    const int width = face.texture.width();
    const int height = face.texture.height();
    face.texture.levels.clear();
    // A box filter of a constant is that constant, so each level is filled directly.
    for (int k = 0; k == 0 || (width >> (k - 1)) > 1 || (height >> (k - 1)) > 1; ++k) {
      TextureLevel level;
      level.width = std::max(1, width >> k);
      level.height = std::max(1, height >> k);
      level.texels.assign(static_cast<size_t>(level.width) * level.height, color);
      face.texture.levels.push_back(std::move(level));
    }
  }
}

std::array<glm::vec3, 4> Scene::corners(const Face& f) const {
  return {positions[f.vertices[0]], positions[f.vertices[1]], positions[f.vertices[2]],
          positions[f.vertices[3]]};
}

glm::vec3 Scene::face_normal(const Face& f) const {
  const auto [p0, p1, p2, p3] = corners(f);
  return glm::normalize(glm::cross(p2 - p0, p3 - p1));
}

size_t Scene::texel_count() const {
  size_t count = 0;
  for (const Face& face : faces)
    for (const TextureLevel& level : face.texture.levels)
      count += static_cast<size_t>(level.width) * static_cast<size_t>(level.height);
  return count;
}

size_t Scene::stored_texel_count() const {
  size_t count = 0;
  for (const Face& face : faces)
    for (const TextureLevel& level : face.texture.levels) count += level.texels.size();
  return count;
}

Camera orbit_camera(const Scene& scene, int frame, int frames) {
  if (!scene.orbit) throw InputError("frame", "scene '" + scene.name + "' has no orbit");
  if (frames < 1) throw InputError("frames", "must be at least 1, got " + std::to_string(frames));
  if (frame < 0 || frame >= frames)
    throw InputError(
        "frame", "must be in [0, " + std::to_string(frames) + "), got " + std::to_string(frame));
  const Orbit& orbit = *scene.orbit;
  const double degrees =
      static_cast<double>(orbit.start_degrees) + 360.0 * static_cast<double>(frame) / frames;
  const double radians = degrees * (3.14159265358979323846 / 180.0);
  // Angle 0 puts the eye on +z of the centre; angles grow towards +x.
  Camera camera = scene.camera;
  camera.eye =
      orbit.center + glm::vec3(orbit.radius * static_cast<float>(std::sin(radians)), orbit.height,
                               orbit.radius * static_cast<float>(std::cos(radians)));
  camera.target = orbit.center;
  // The orbit circles the vertical axis, so world up is parallel to the view direction only when
  // the radius is (next to) nothing beside the height: such an orbit is refused here, as a static
  // camera is in validate_scene, rather than rendered blank.
  camera.up = glm::vec3(0, 1, 0);
  if (const std::optional<std::string> problem = camera_problem(camera)) {
    // Said in the orbit's terms: its camera's members are not the user's to set.
    const bool on_centre = problem->starts_with("eye");
    throw InputError("orbit.radius", on_centre ? "and orbit.height put frame " + std::to_string(frame) + "'s eye on the centre"
                                               : "is too small beside orbit.height: frame " + std::to_string(frame) +
                                                     "'s eye would look straight along the vertical");
  }
  return camera;
}

namespace {

// A reflective face needs an environment to reflect and a unit shading normal at each corner.
void check_reflective_face(const Scene& scene, const Face& face, const std::string& face_field) {
  if (face.roughness < 0.0f) return;
  if (!(face.roughness <= 4.0f)) throw InputError(face_field + ".roughness", "must be in 0..4 (or < 0: diffuse)");
  if (!scene.environment) throw InputError(face_field + ".roughness", "a reflective face needs an environment");
  if (scene.normals.size() != scene.positions.size()) {
    throw InputError("normals", "reflective faces need one normal per position (" +
                                    std::to_string(scene.positions.size()) + "), got " +
                                    std::to_string(scene.normals.size()));
  }
  for (uint32_t v : face.vertices) {
    const glm::vec3 n = scene.normals[v];
    const float length = glm::length(n);
    if (!(std::fabs(length - 1.0f) < 1e-3f)) {
      throw InputError("normals[" + std::to_string(v) + "]", "must be a unit vector");
    }
  }
}

}  // namespace

void check_color(glm::vec3 c, const std::string& field) {
  if (!is_finite(c)) throw InputError(field, "must be finite");
  if (glm::any(glm::lessThan(c, glm::vec3(0.0f)))) throw InputError(field, "must not be negative");
  if (glm::any(glm::greaterThan(c, glm::vec3(kMaxColorMagnitude)))) throw InputError(field, "must be at most 1e9");
}

void check_texel_magnitudes(const MipChain& chain, const std::string& field) {
  for (size_t k = 0; k < chain.levels.size(); ++k) {
    // One compare a channel, which NaN fails too, over the level's floats (a loop that vectorises:
    // every baked texel passes here); only a level that fails is walked again for the message.
    const std::vector<glm::vec4>& texels = chain.levels[k].texels;
    const float* channels = reinterpret_cast<const float*>(texels.data());  // 4 floats a glm::vec4
    int outside = 0;
    for (size_t c = 0, n = 4 * texels.size(); c < n; ++c) outside |= !(std::fabs(channels[c]) <= kMaxColorMagnitude);
    if (!outside) continue;
    for (const glm::vec4& texel : texels)
      if (!is_finite(texel)) {
        throw InputError(field, "mip level " + std::to_string(k) + " has a non-finite texel");
      } else if (glm::any(glm::greaterThan(glm::abs(texel), glm::vec4(kMaxColorMagnitude)))) {
        throw InputError(field, "mip level " + std::to_string(k) + " has a texel of magnitude over 1e9");
      }
  }
}

void validate_scene(const Scene& scene) {
  if (scene.faces.empty()) throw InputError("faces", "the scene has no faces");
  for (size_t i = 0; i < scene.positions.size(); ++i)
    check_vec3(scene.positions[i], "positions[" + std::to_string(i) + "]");

  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const Face& face = scene.faces[f];
    const std::string face_field = "faces[" + std::to_string(f) + "]";
    for (size_t k = 0; k < 4; ++k) {
      if (face.vertices[k] >= scene.positions.size())
        throw InputError(face_field + ".vertices[" + std::to_string(k) + "]",
                         "index " + std::to_string(face.vertices[k]) + " out of range (" +
                             std::to_string(scene.positions.size()) + " positions)");
    }
    // A face without area has no normal to light it with (it would be NaN).
    const auto [p0, p1, p2, p3] = scene.corners(face);
    const glm::vec3 diagonal_cross = glm::cross(p2 - p0, p3 - p1);
    const float area_measure = glm::length(diagonal_cross);
    if (!std::isfinite(area_measure))
      throw InputError(face_field + ".vertices", "the quad's corners are too far apart (its area overflows a float)");
    if (!(area_measure > 0.0f)) throw InputError(face_field + ".vertices", "the quad is degenerate (zero area)");
    check_texture(face.texture, face_field + ".texture", static_cast<bool>(scene.texture_source));
    check_reflective_face(scene, face, face_field);
  }
  if (scene.environment) validate_environment(*scene.environment);

  const Camera& camera = scene.camera;
  check_vec3(camera.eye, "camera.eye");
  check_vec3(camera.target, "camera.target");
  check_vec3(camera.up, "camera.up");
  if (!std::isfinite(camera.fov_y_degrees) || !(camera.fov_y_degrees > 0.0f) ||
      !(camera.fov_y_degrees < 180.0f))
    throw InputError("camera.fov_y_degrees",
                     "must be in (0, 180), got " + std::to_string(camera.fov_y_degrees));
  if (const std::optional<std::string> problem = camera_problem(camera)) {
    // "eye must differ ..." / "up is parallel ...": the field is the problem's first word.
    const std::string field = problem->substr(0, problem->find(' '));
    throw InputError("camera." + field, problem->substr(field.size() + 1));
  }

  if (scene.orbit) {
    const Orbit& orbit = *scene.orbit;
    check_vec3(orbit.center, "orbit.center");
    if (!std::isfinite(orbit.radius) || !(orbit.radius > 0.0f))
      throw InputError("orbit.radius", "must be positive and finite");
    if (!std::isfinite(orbit.height)) throw InputError("orbit.height", "must be finite");
    if (!std::isfinite(orbit.start_degrees))
      throw InputError("orbit.start_degrees", "must be finite");
  }

  const Light& light = scene.light;
  check_vec3(light.to_light, "light.to_light");
  if (std::abs(glm::length(light.to_light) - 1.0f) > 1e-3f)
    throw InputError("light.to_light", "must be a unit vector");
  check_color(light.color, "light.color");
  if (!std::isfinite(light.ambient) || light.ambient < 0.0f || light.ambient > 1.0f)
    throw InputError("light.ambient", "must be in [0, 1]");
  check_color(scene.background, "background");
}

}  // namespace seamcl
