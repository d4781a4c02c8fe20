#include "scene/displaced_scene.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace seamcl {

float displacement_pattern(glm::vec3 p) {
  // Three waves in different directions; their sum stays in [-1.75, 1.75], mapped to [0, 1].
  const float a = std::sin(7.0f * p.x + 1.3f) * std::sin(6.0f * p.y + 0.4f);
  const float b = 0.5f * std::sin(11.0f * p.z - 5.0f * p.x + 2.1f);
  const float c = 0.25f * std::cos(17.0f * p.y + 9.0f * p.z);
  return std::clamp(0.5f + (a + b + c) / 3.5f, 0.0f, 1.0f);
}

glm::vec3 bilinear_point(const std::array<glm::vec3, 4>& c, float u, float v) {
  const float w0 = (1.0f - u) * (1.0f - v), w1 = u * (1.0f - v), w2 = u * v, w3 = (1.0f - u) * v;
  return w0 * c[0] + w1 * c[1] + w2 * c[2] + w3 * c[3];
}

DisplacementMap bake_displacement_map(const std::array<glm::vec3, 4>& corners, int columns, int rows,
                                      const std::function<float(glm::vec3)>& height) {
  DisplacementMap map;
  map.columns = columns;
  map.rows = rows;
  map.samples.resize(static_cast<size_t>(columns) * rows);
  for (int j = 0; j < rows; ++j) {
    const float v = rows > 1 ? static_cast<float>(j) / static_cast<float>(rows - 1) : 0.0f;
    for (int i = 0; i < columns; ++i) {
      const float u = columns > 1 ? static_cast<float>(i) / static_cast<float>(columns - 1) : 0.0f;
      const float h = std::clamp(height(bilinear_point(corners, u, v)), 0.0f, 1.0f);
      map.at(i, j) = static_cast<uint16_t>(std::lround(h * 65535.0f));
    }
  }
  return map;
}

Scene make_displaced_scene(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "displaced";
  constexpr int kSplit = 2;  // quads per cube-face side
  // Vertices on the cube's surface lattice, shared between faces, then projected to the sphere.
  std::map<std::tuple<int, int, int>, uint32_t> lattice;
  auto vertex = [&](int x, int y, int z) {
    const auto key = std::make_tuple(x, y, z);
    const auto found = lattice.find(key);
    if (found != lattice.end()) return found->second;
    const glm::vec3 cube(2.0f * static_cast<float>(x) / kSplit - 1.0f, 2.0f * static_cast<float>(y) / kSplit - 1.0f,
                         2.0f * static_cast<float>(z) / kSplit - 1.0f);
    scene.positions.push_back(glm::normalize(cube));
    const auto index = static_cast<uint32_t>(scene.positions.size() - 1);
    lattice.emplace(key, index);
    return index;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      for (int b = 0; b < kSplit; ++b) {
        for (int a = 0; a < kSplit; ++a) {
          // Lattice point (a', b') of this cube face, its fixed coordinate 0 or kSplit.
          auto at = [&](int da, int db) {
            int p[3];
            p[axis] = side * kSplit;
            p[(axis + 1) % 3] = a + da;
            p[(axis + 2) % 3] = b + db;
            return vertex(p[0], p[1], p[2]);
          };
          std::array<uint32_t, 4> quad{at(0, 0), at(1, 0), at(1, 1), at(0, 1)};
          // Counter-clockwise seen from outside: flip the quads whose normal points inwards.
          const glm::vec3 p0 = scene.positions[quad[0]], p1 = scene.positions[quad[1]], p2 = scene.positions[quad[2]];
          if (glm::dot(glm::cross(p1 - p0, p2 - p0), p0 + p2) < 0.0f) std::swap(quad[1], quad[3]);
          // Start each face's vertex list at a different corner: neighbours meet rotated.
          const size_t rotate = (scene.faces.size() * 2654435761u >> 5) % 4;
          std::rotate(quad.begin(), quad.begin() + static_cast<std::ptrdiff_t>(rotate), quad.end());
          scene.faces.push_back({quad, {}});
        }
      }
    }
  }
  // Map resolutions (intervals per side) from 1 to 32, non-square among them, so that
  // neighbours differ by up to 32x along a shared edge.
  constexpr std::array<int, 7> kIntervals{1, 2, 4, 8, 16, 32, 4};
  auto displacement = std::make_shared<Displacement>();
  displacement->scale = 0.12f;
  displacement->source = "generator 'displaced'";
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const int nu = kIntervals[f % kIntervals.size()];
    const int nv = kIntervals[(f * 3 + 1) % kIntervals.size()];
    displacement->maps.push_back(
        bake_displacement_map(scene.corners(scene.faces[f]), nu + 1, nv + 1, displacement_pattern));
  }
  scene.displacement = displacement;
  // Colour textures show the height (so the displacement reads in a flat-shaded image) over the
  // surface pattern's hues.
  scene.albedo = [](size_t, glm::vec3 p) {
    const float h = displacement_pattern(p);
    return glm::vec4(glm::vec3(surface_pattern(p)) * (0.35f + 0.65f * h), 1.0f);
  };
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    scene.faces[f].texture = build_mip_chain(
        bake_face_texture(scene.corners(scene.faces[f]), 32, 32, [&](glm::vec3 p) { return scene.albedo(f, p); }));
  }
  apply_generator_options(scene, options);
  scene.orbit = Orbit{glm::vec3(0.0f), 4.2f, 3.2f, 40.0f};
  scene.camera.fov_y_degrees = 32.0f;
  scene.camera = orbit_camera(scene, 0, 1);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.5f));
  return scene;
}

}  // namespace seamcl
