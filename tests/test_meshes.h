// Small closed quad meshes for the seam-method tests, with every kind of vertex the methods treat
// differently (valence 3, 4 and 5), and the rotation or mirroring of one face's vertex order with
// its texture carried along, so the same surface can be described two ways.
#pragma once
#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/scene/scene.h>
#include "pipeline/adjacency.h"

namespace seamcl_tests {

// Adds a quad over four positions, its vertex order turned so that it faces away from `inside`.
inline void add_outward_quad(seamcl::Scene& scene, std::array<uint32_t, 4> v, glm::vec3 inside) {
  const auto& p = scene.positions;
  const glm::vec3 normal = glm::cross(p[v[2]] - p[v[0]], p[v[3]] - p[v[1]]);
  const glm::vec3 centre = 0.25f * (p[v[0]] + p[v[1]] + p[v[2]] + p[v[3]]);
  if (glm::dot(normal, centre - inside) < 0.0f) std::swap(v[1], v[3]);
  seamcl::Face face;
  face.vertices = v;
  scene.faces.push_back(std::move(face));
}

// A cube of side 2 around the origin, each side split into n x n squares: valence 3 at the cube's
// eight corners, 4 everywhere else. Seen obliquely, three sides and a corner in view.
inline seamcl::Scene subdivided_cube(int n) {
  seamcl::Scene scene;
  scene.name = "subdivided_cube";
  std::map<std::tuple<int, int, int>, uint32_t> index;  // lattice point -> vertex
  auto vertex = [&](glm::ivec3 lattice) {
    const auto key = std::make_tuple(lattice.x, lattice.y, lattice.z);
    auto found = index.find(key);
    if (found != index.end()) return found->second;
    scene.positions.push_back(glm::vec3(lattice) * (2.0f / static_cast<float>(n)) - glm::vec3(1.0f));
    return index[key] = static_cast<uint32_t>(scene.positions.size() - 1);
  };
  // Each side: a corner of the lattice and two axes along it.
  const std::array<std::tuple<glm::ivec3, glm::ivec3, glm::ivec3>, 6> sides{{
      {{n, 0, 0}, {0, 1, 0}, {0, 0, 1}}, {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}}, {{0, n, 0}, {0, 0, 1}, {1, 0, 0}},
      {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}}, {{0, 0, n}, {1, 0, 0}, {0, 1, 0}}, {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}}}};
  for (const auto& [origin, a, b] : sides) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        add_outward_quad(scene, {vertex(origin + i * a + j * b), vertex(origin + (i + 1) * a + j * b),
                                 vertex(origin + (i + 1) * a + (j + 1) * b), vertex(origin + i * a + (j + 1) * b)},
                         glm::vec3(0.0f));
      }
    }
  }
  scene.camera.eye = {2.9f, 2.4f, 3.7f};
  scene.camera.target = {0, 0, 0};
  scene.camera.fov_y_degrees = 40.0f;
  scene.light.to_light = glm::normalize(glm::vec3(0.5f, 0.8f, 0.6f));
  return scene;
}

// A pentagonal prism whose caps are each split into five quads around the cap's centre (valence
// 5) through the midpoints of the cap's edges (valence 4), and whose sides are each split in two
// at those midpoints: the prism's corners keep valence 3. Seen from above, a cap in view.
inline seamcl::Scene split_pentagonal_prism() {
  seamcl::Scene scene;
  scene.name = "split_pentagonal_prism";
  constexpr float half_height = 0.6f;
  auto ring_point = [](float angle_turns, float radius, float y) {
    const float a = angle_turns * 6.2831853f;
    return glm::vec3(radius * std::cos(a), y, radius * std::sin(a));
  };
  // Per cap: centre, then corners 0..4, then midpoints 0..4 (midpoint i between corners i, i+1).
  std::array<uint32_t, 2> centre{};
  std::array<std::array<uint32_t, 5>, 2> corner{}, midpoint{};
  for (int cap = 0; cap < 2; ++cap) {
    const float y = cap == 0 ? half_height : -half_height;
    centre[cap] = static_cast<uint32_t>(scene.positions.size());
    scene.positions.emplace_back(0.0f, y, 0.0f);
    for (int i = 0; i < 5; ++i) {
      corner[cap][i] = static_cast<uint32_t>(scene.positions.size());
      scene.positions.push_back(ring_point(static_cast<float>(i) / 5.0f, 1.0f, y));
    }
    for (int i = 0; i < 5; ++i) {
      midpoint[cap][i] = static_cast<uint32_t>(scene.positions.size());
      scene.positions.push_back(0.5f * (scene.positions[corner[cap][i]] + scene.positions[corner[cap][(i + 1) % 5]]));
    }
  }
  const glm::vec3 inside(0.0f);
  for (int cap = 0; cap < 2; ++cap) {
    for (int i = 0; i < 5; ++i) {
      add_outward_quad(scene, {centre[cap], midpoint[cap][(i + 4) % 5], corner[cap][i], midpoint[cap][i]}, inside);
    }
  }
  for (int i = 0; i < 5; ++i) {
    const int next = (i + 1) % 5;
    add_outward_quad(scene, {corner[1][i], midpoint[1][i], midpoint[0][i], corner[0][i]}, inside);
    add_outward_quad(scene, {midpoint[1][i], corner[1][next], corner[0][next], midpoint[0][i]}, inside);
  }
  scene.camera.eye = {1.3f, 2.6f, 2.2f};
  scene.camera.target = {0, 0, 0};
  scene.camera.fov_y_degrees = 45.0f;
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.5f));
  return scene;
}

// Texture sizes from 1x1 to 256x256, square and not, so that neighbours differ.
inline const std::vector<glm::ivec2>& mixed_texture_sizes() {
  static const std::vector<glm::ivec2> sizes{{1, 1},  {256, 256}, {4, 4},  {32, 8},  {2, 2},   {64, 64},
                                             {8, 32}, {16, 16},   {1, 4},  {128, 128}, {8, 8}, {4, 1}};
  return sizes;
}

// Gives face i a texture of sizes[i % size count] whose level 0 is `texel(face, i, j)`.
inline void set_textures(seamcl::Scene& scene, const std::vector<glm::ivec2>& sizes,
                         const std::function<glm::vec4(size_t, int, int)>& texel) {
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const glm::ivec2 size = sizes[f % sizes.size()];
    seamcl::TextureLevel level{size.x, size.y, {}};
    for (int j = 0; j < size.y; ++j) {
      for (int i = 0; i < size.x; ++i) level.texels.push_back(texel(f, i, j));
    }
    scene.faces[f].texture = seamcl::build_mip_chain(std::move(level));
  }
}

// A texel value that tells every texel of every face apart, in (0, 1).
inline glm::vec4 distinct_texel(size_t face, int i, int j) {
  uint32_t h = static_cast<uint32_t>(face) * 2654435761u ^ static_cast<uint32_t>(i) * 40503u ^
               static_cast<uint32_t>(j) * 2246822519u;
  auto next = [&h]() {
    h ^= h >> 15;
    h *= 2246822519u;
    h ^= h >> 13;
    return 0.05f + 0.9f * static_cast<float>(h & 0xffffu) / 65535.0f;
  };
  const float r = next(), g = next(), b = next();
  return {r, g, b, 1.0f};
}

// The same surface with face `face`'s vertex list turned: its corner c becomes the old corner
// (c + rotation) mod 4, after reversing the list (old corner (4 - c) mod 4) when `mirror`. Every
// level of its texture turns with it, texel for texel. `to_new` receives the map from the face's
// old uv to its new uv (a reversed face also faces the other way: lookups only, not renders).
inline seamcl::Scene turn_face(const seamcl::Scene& scene, uint32_t face, int rotation, bool mirror,
                               seamcl::UvMap* to_new = nullptr) {
  seamcl::Scene out = scene;
  constexpr float cu[4] = {0, 1, 1, 0}, cv[4] = {0, 0, 1, 1};
  auto old_corner = [&](int c) { return ((mirror ? (4 - c) % 4 : c) + rotation) % 4; };
  seamcl::Face& turned = out.faces[face];
  for (int c = 0; c < 4; ++c) turned.vertices[c] = scene.faces[face].vertices[old_corner(c)];
  // The affine map taking old corner old_corner(c) to new corner c, from three of them.
  const glm::vec2 o0(cu[old_corner(0)], cv[old_corner(0)]), o1(cu[old_corner(1)], cv[old_corner(1)]),
      o3(cu[old_corner(3)], cv[old_corner(3)]);
  // new uv (s, t) is old o0 + s (o1 - o0) + t (o3 - o0): invert that (its columns are unit axes).
  const glm::mat2 new_to_old(o1 - o0, o3 - o0);
  seamcl::UvMap map;
  map.linear = glm::inverse(new_to_old);
  map.offset = -(map.linear * o0);
  if (to_new) *to_new = map;
  const bool swapped = new_to_old[0].x == 0.0f;  // new u runs along old v
  for (size_t l = 0; l < scene.faces[face].texture.levels.size(); ++l) {
    const seamcl::TextureLevel& old_level = scene.faces[face].texture.levels[l];
    seamcl::TextureLevel level{swapped ? old_level.height : old_level.width,
                               swapped ? old_level.width : old_level.height, {}};
    for (int j = 0; j < level.height; ++j) {
      for (int i = 0; i < level.width; ++i) {
        const glm::vec2 centre((static_cast<float>(i) + 0.5f) / static_cast<float>(level.width),
                               (static_cast<float>(j) + 0.5f) / static_cast<float>(level.height));
        const glm::vec2 old_uv = o0 + new_to_old * centre;
        const int oi = static_cast<int>(old_uv.x * static_cast<float>(old_level.width));
        const int oj = static_cast<int>(old_uv.y * static_cast<float>(old_level.height));
        level.texels.push_back(old_level.at(oi, oj));
      }
    }
    turned.texture.levels[l] = std::move(level);
  }
  return out;
}

}  // namespace seamcl_tests
