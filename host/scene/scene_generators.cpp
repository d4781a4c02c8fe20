#include <seamcl/scene/scene_generators.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <mutex>
#include <random>
#include <system_error>
#include <thread>

#include <seamcl/core/input_error.h>
#include <seamcl/scene/envmap_scene.h>

namespace seamcl {
namespace {

constexpr float kPi = 3.14159265358979f;

struct TextureSize {
  int width;
  int height;
};

// Texture contents for every face, in parallel: baking the paper scene's ~9 million texels is
// most of its generation time, and faces are independent, so the result does not depend on the
// number of threads or their timing.
void paint_textures(Scene& scene, const std::vector<TextureSize>& sizes,
                    const GeneratorOptions& options) {
  auto paint_face = [&](size_t f) {
    Face& face = scene.faces[f];
    const glm::vec4 tint = options.tint ? glm::vec4(face_tint(f), 1.0f) : glm::vec4(1.0f);
    const std::optional<glm::vec3> constant = options.constant_color;
    auto color_at = [&](glm::vec3 p) {
      return (constant ? glm::vec4(*constant, 1.0f) : surface_pattern(p)) * tint;
    };
    face.texture = build_mip_chain(
        bake_face_texture(scene.corners(face), sizes[f].width, sizes[f].height, color_at));
  };
  // Faces are handed out one at a time because their sizes differ by up to 64x.
  std::atomic<size_t> next_face{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto paint_remaining = [&] {
    try {
      for (size_t f = next_face++; f < scene.faces.size(); f = next_face++) paint_face(f);
    } catch (...) {
      // Out of memory must reach the caller rather than terminate the process from a thread.
      const std::lock_guard lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next_face = scene.faces.size();
    }
  };
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());  // 0 if unknown
  const unsigned helper_count = std::min(7u, cores - 1);
  std::vector<std::thread> helpers;
  try {
    for (unsigned h = 0; h < helper_count && h < scene.faces.size(); ++h)
      helpers.emplace_back(paint_remaining);
  } catch (const std::system_error&) {
    // Fewer helpers than asked for: this thread paints whatever they do not.
  }
  paint_remaining();
  for (std::thread& helper : helpers) helper.join();
  if (failure) std::rethrow_exception(failure);
}

// A grid of nx x nz quads over [x0, x1] x [z0, z1] at height y, facing +y (counter-clockwise seen
// from above), u along +x and v along -z. Vertices are shared between neighbouring quads.
void add_ground_grid(Scene& scene, int nx, int nz, float x0, float x1, float z0, float z1,
                     float y) {
  const auto base = static_cast<uint32_t>(scene.positions.size());
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i)
      scene.positions.emplace_back(x0 + (x1 - x0) * static_cast<float>(i) / static_cast<float>(nx),
                                   y,
                                   z1 - (z1 - z0) * static_cast<float>(j) / static_cast<float>(nz));
  auto vertex = [&](int i, int j) { return base + static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      scene.faces.push_back(
          {{vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)}, {}});
}

// A closed torus standing upright: its axis is z, so the ring lies in the xy plane. Quad (i, j)
// spans major angles i..i+1 (u) and tube angles j..j+1 (v), which makes it counter-clockwise
// seen from outside.
void add_torus(Scene& scene, glm::vec3 center, float major_radius, float minor_radius,
               int major_segments, int minor_segments) {
  const auto base = static_cast<uint32_t>(scene.positions.size());
  for (int i = 0; i < major_segments; ++i) {
    const float theta = 2.0f * kPi * static_cast<float>(i) / static_cast<float>(major_segments);
    for (int j = 0; j < minor_segments; ++j) {
      const float phi = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(minor_segments);
      const float ring = major_radius + minor_radius * std::cos(phi);
      scene.positions.push_back(center + glm::vec3(ring * std::cos(theta), ring * std::sin(theta),
                                                   minor_radius * std::sin(phi)));
    }
  }
  auto vertex = [&](int i, int j) {
    return base + static_cast<uint32_t>((i % major_segments) * minor_segments + j % minor_segments);
  };
  for (int i = 0; i < major_segments; ++i)
    for (int j = 0; j < minor_segments; ++j)
      scene.faces.push_back(
          {{vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)}, {}});
}

void set_orbit_and_camera(Scene& scene, Orbit orbit, float fov_y_degrees) {
  scene.orbit = orbit;
  scene.camera.fov_y_degrees = fov_y_degrees;
  scene.camera = orbit_camera(scene, 0, 1);
}

// Figure 1 of the paper: a torus on a ground plane, every face with its own texture of a size
// drawn independently per axis from 16..128, so neighbouring faces rarely match.
Scene make_paper(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "paper";
  constexpr float kMajorRadius = 2.0f;
  constexpr float kMinorRadius = 0.7f;
  // Resting on the ground: the exact torus would touch y = 0; its polygonal version stays a few
  // thousandths above it.
  const glm::vec3 torus_center(0.0f, kMajorRadius + kMinorRadius, 0.0f);
  add_torus(scene, torus_center, kMajorRadius, kMinorRadius, 50, 29);
  add_ground_grid(scene, 32, 32, -8.0f, 8.0f, -8.0f, 8.0f, 0.0f);

  std::mt19937 random(20130805u);
  constexpr int kSides[] = {16, 32, 64, 128};
  std::vector<TextureSize> sizes(scene.faces.size());
  for (TextureSize& size : sizes) {
    size.width = kSides[random() % 4];
    size.height = kSides[random() % 4];
  }
  paint_textures(scene, sizes, options);

  set_orbit_and_camera(scene, Orbit{torus_center, 8.0f, 3.0f, 25.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(-0.5f, 1.0f, 0.6f));
  return scene;
}

// The smallest seam: two unit quads side by side in the z = 0 plane whose textures differ in
// size and aspect (64x64 on the left, 32x16 on the right).
Scene make_quad2(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "quad2";
  scene.positions = {{-1.0f, -0.5f, 0.0f}, {0.0f, -0.5f, 0.0f}, {1.0f, -0.5f, 0.0f},
                     {-1.0f, 0.5f, 0.0f},  {0.0f, 0.5f, 0.0f},  {1.0f, 0.5f, 0.0f}};
  scene.faces = {{{0, 1, 4, 3}, {}}, {{1, 2, 5, 4}, {}}};
  paint_textures(scene, {{64, 64}, {32, 16}}, options);
  // 2.7 units away a 45 degree view is 2.24 units wide: the pair fills most of a square image.
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.0f), 2.7f, 0.0f, 0.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 0.5f, 1.0f));
  return scene;
}

// Strong anisotropy: a large ground plane seen from eye height 1, the far edge nearly at the
// horizon.
Scene make_plane(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "plane";
  add_ground_grid(scene, 64, 64, -64.0f, 64.0f, -64.0f, 64.0f, 0.0f);
  paint_textures(scene, std::vector<TextureSize>(scene.faces.size(), {32, 32}), options);
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.0f), 8.0f, 1.0f, 0.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f));
  return scene;
}

// A closed cube, side 2, centred at the origin; seen obliquely, so three faces and the edges and
// corner between them show.
Scene make_cube(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "cube";
  // Corner index = x_bit + 2 y_bit + 4 z_bit, a set bit meaning +1.
  for (uint32_t corner = 0; corner < 8; ++corner)
    scene.positions.emplace_back((corner & 1) ? 1.0f : -1.0f, (corner & 2) ? 1.0f : -1.0f,
                                 (corner & 4) ? 1.0f : -1.0f);
  // Faces +x, -x, +y, -y, +z, -z, each counter-clockwise seen from outside.
  scene.faces = {{{5, 1, 3, 7}, {}}, {{0, 4, 6, 2}, {}}, {{6, 7, 3, 2}, {}},
                 {{0, 1, 5, 4}, {}}, {{4, 5, 7, 6}, {}}, {{1, 0, 2, 3}, {}}};
  paint_textures(scene, std::vector<TextureSize>(scene.faces.size(), {64, 64}), options);
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.0f), 5.0f, 3.2f, 35.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.55f));
  return scene;
}

struct Generator {
  GeneratorInfo info;
  Scene (*make)(const GeneratorOptions&);
};

const std::vector<Generator>& generators() {
  static const std::vector<Generator> list = {
      {{"paper",
        "the paper's Figure 1: an upright torus (50x29 quads) on a ground plane (32x32 quads), "
        "every face its own texture, sides 16 to 128, mixed and non-square"},
       make_paper},
      {{"quad2", "two unit quads sharing one edge, textures 64x64 and 32x16"}, make_quad2},
      {{"plane", "a 128x128 ground plane of 64x64 quads (32x32 textures) at a grazing angle"},
       make_plane},
      {{"cube", "a closed cube of six 64x64-textured faces, seen obliquely"}, make_cube},
      {{"envmap", "mirror and glossy spheres and a mirror torus in an analytic environment (skybox), "
                  "for the cube-map methods (cube_method)"},
       [](const GeneratorOptions& options) { return make_envmap_scene(options); }},
  };
  return list;
}

uint32_t hash32(uint32_t x) {
  // A well-mixed integer hash (lowbias32), so that neighbouring indices get unrelated colours.
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

}  // namespace

const std::vector<GeneratorInfo>& scene_generators() {
  static const std::vector<GeneratorInfo> infos = [] {
    std::vector<GeneratorInfo> list;
    for (const Generator& generator : generators()) list.push_back(generator.info);
    return list;
  }();
  return infos;
}

Scene generate_scene(const std::string& name, const GeneratorOptions& options) {
  for (const Generator& generator : generators()) {
    if (generator.info.name != name) continue;
    Scene scene = generator.make(options);
    validate_scene(scene);
    return scene;
  }
  std::string known;
  for (const Generator& generator : generators())
    known += (known.empty() ? "" : ", ") + generator.info.name;
  throw InputError("scene", "unknown scene '" + name + "' (known: " + known + ")");
}

glm::vec3 face_tint(size_t face_index) {
  const uint32_t hash = hash32(static_cast<uint32_t>(face_index));
  const float hue = static_cast<float>(hash % 3600u) / 3600.0f;
  const float saturation = 0.25f + 0.2f * static_cast<float>((hash >> 12) % 256u) / 255.0f;
  // A fully saturated hue, then mixed towards white: a pastel with every channel >= 0.55.
  const glm::vec3 pure = glm::clamp(
      glm::abs(glm::fract(glm::vec3(hue) + glm::vec3(1.0f, 2.0f / 3.0f, 1.0f / 3.0f)) * 6.0f -
               glm::vec3(3.0f)) -
          glm::vec3(1.0f),
      glm::vec3(0.0f), glm::vec3(1.0f));
  return glm::mix(glm::vec3(1.0f), pure, saturation);
}

void apply_generator_options(Scene& scene, const GeneratorOptions& options) {
  if (options.constant_color)
    set_constant_textures(scene, glm::vec4(*options.constant_color, 1.0f));
  if (options.constant_color && scene.environment) scene.environment->constant = *options.constant_color;
  if (!options.tint) return;
  // The box filter is linear, so scaling every level equals re-filtering a scaled level 0.
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const glm::vec4 tint(face_tint(f), 1.0f);
    for (TextureLevel& level : scene.faces[f].texture.levels)
      for (glm::vec4& texel : level.texels) texel *= tint;
  }
}

}  // namespace seamcl
