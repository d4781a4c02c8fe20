#include <seamcl/scene/envmap_scene.h>

#include <cmath>

#include <seamcl/scene/cube_map.h>

namespace seamcl {
namespace {

constexpr float kTwoPi = 6.28318530718f;

// Reflective faces show the environment, not their texture; it is a constant grey, which is also
// the scene's albedo, so the analytic reference and the regime checks hold for it too.
constexpr glm::vec4 kUnusedAlbedo(0.5f, 0.5f, 0.5f, 1.0f);

MipChain unused_texture() { return build_mip_chain(TextureLevel{1, 1, {kUnusedAlbedo}}); }

}  // namespace

void add_reflective_grid(Scene& scene, int nu, int nv, const std::function<glm::vec3(float, float)>& point,
                         const std::function<glm::vec3(float, float)>& normal, float roughness) {
  const auto base = static_cast<uint32_t>(scene.positions.size());
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const float a = static_cast<float>(i) / static_cast<float>(nu);
      const float b = static_cast<float>(j) / static_cast<float>(nv);
      scene.positions.push_back(point(a, b));
      scene.normals.push_back(glm::normalize(normal(a, b)));
    }
  }
  auto vertex = [&](int i, int j) { return base + static_cast<uint32_t>(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      Face face;
      face.vertices = {vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)};
      const glm::vec3 centre_normal = normal((static_cast<float>(i) + 0.5f) / static_cast<float>(nu),
                                             (static_cast<float>(j) + 0.5f) / static_cast<float>(nv));
      if (glm::dot(scene.face_normal(face), centre_normal) < 0.0f) {
        face.vertices = {vertex(i, j), vertex(i, j + 1), vertex(i + 1, j + 1), vertex(i + 1, j)};
      }
      face.texture = unused_texture();
      face.roughness = roughness;
      scene.faces.push_back(std::move(face));
    }
  }
}

void add_reflective_sphere(Scene& scene, glm::vec3 center, float radius, int quads_per_side, float roughness) {
  // A cube sphere: no poles, so no degenerate quads. Points on shared edges are computed from the
  // same exact cube coordinates by both faces, so the surface is watertight.
  for (int f = 0; f < kCubeFaces; ++f) {
    auto direction = [f](float a, float b) { return glm::normalize(cube_direction(f, 2.0f * a - 1.0f, 2.0f * b - 1.0f)); };
    add_reflective_grid(
        scene, quads_per_side, quads_per_side, [&](float a, float b) { return center + radius * direction(a, b); },
        direction, roughness);
  }
}

void add_reflective_torus(Scene& scene, glm::vec3 center, float major_radius, float minor_radius, int major_segments,
                          int minor_segments, float roughness) {
  auto normal = [](float a, float b) {
    const float theta = kTwoPi * a, phi = kTwoPi * b;
    return glm::vec3(std::cos(phi) * std::cos(theta), std::sin(phi), std::cos(phi) * std::sin(theta));
  };
  auto point = [&](float a, float b) {
    const float theta = kTwoPi * a;
    const glm::vec3 ring = center + major_radius * glm::vec3(std::cos(theta), 0.0f, std::sin(theta));
    return ring + minor_radius * normal(a, b);
  };
  add_reflective_grid(scene, major_segments, minor_segments, point, normal, roughness);
}

Scene make_envmap_scene(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "envmap";
  scene.albedo = [](size_t, glm::vec3) { return kUnusedAlbedo; };
  Environment environment = options.environment.value_or(Environment{});
  if (options.constant_color) environment.constant = options.constant_color;
  scene.environment = environment;
  const glm::vec3 roughness = options.roughness.value_or(glm::vec3(0.0f, 0.15f, 0.0f));
  add_reflective_sphere(scene, glm::vec3(-1.25f, 1.0f, 0.0f), 1.0f, 12, roughness[0]);
  add_reflective_sphere(scene, glm::vec3(1.25f, 1.0f, 0.0f), 1.0f, 12, roughness[1]);
  add_reflective_torus(scene, glm::vec3(0.0f, 0.35f, 0.0f), 3.2f, 0.35f, 64, 12, roughness[2]);
  scene.orbit = Orbit{glm::vec3(0.0f, 0.9f, 0.0f), 6.5f, 1.6f, 20.0f};
  scene.camera.fov_y_degrees = 50.0f;
  scene.camera = orbit_camera(scene, 0, 1);
  return scene;
}

}  // namespace seamcl
