#include <seamcl/scene/cube_map.h>

#include <algorithm>
#include <cassert>
#include <cmath>

#include <seamcl/core/input_error.h>

namespace seamcl {

CubeCoords cube_coords(glm::vec3 d) {
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  CubeCoords c;
  float ma = 0;
  if (ax >= ay && ax >= az) {
    c.face = d.x < 0 ? 1 : 0;
    ma = ax;
    c.sc = d.x < 0 ? d.z : -d.z;
    c.tc = -d.y;
  } else if (ay >= az) {
    c.face = d.y < 0 ? 3 : 2;
    ma = ay;
    c.sc = d.x;
    c.tc = d.y < 0 ? -d.z : d.z;
  } else {
    c.face = d.z < 0 ? 5 : 4;
    ma = az;
    c.sc = d.z < 0 ? -d.x : d.x;
    c.tc = -d.y;
  }
  // |sc|, |tc| <= ma holds for every finite direction; a NaN component fails it.
  if (!(ma > 0.0f && ma < INFINITY && std::fabs(c.sc) <= ma && std::fabs(c.tc) <= ma)) return {};
  c.sc /= ma;
  c.tc /= ma;
  return c;
}

glm::vec3 cube_direction(int face, float sc, float tc) {
  switch (face) {
    case 0: return {1.0f, -tc, -sc};
    case 1: return {-1.0f, -tc, sc};
    case 2: return {sc, 1.0f, tc};
    case 3: return {sc, -1.0f, -tc};
    case 4: return {sc, -tc, 1.0f};
    default: assert(face == 5); return {-sc, -tc, -1.0f};
  }
}

std::string to_string(CubeBake bake) {
  switch (bake) {
    case CubeBake::Centres: return "centres";
    case CubeBake::Stretch: return "stretch";
    case CubeBake::Warp: return "warp";
    case CubeBake::Fov: return "fov";
  }
  return "centres";
}

float cube_map1(float x, int n) { return (x + 0.5f) * 2.0f / static_cast<float>(n) - 1.0f; }

float cube_map2(float x, int n) { return n == 1 ? 0.0f : 2.0f * x / static_cast<float>(n - 1) - 1.0f; }

float cube_warp_coefficient(int n) {
  if (n == 1) return 0.0f;
  const double m = n - 1;
  return static_cast<float>(static_cast<double>(n) * n / (m * m * m));
}

float cube_warp3(float u, int n) { return u + cube_warp_coefficient(n) * u * u * u; }

float cube_map_fov(float x, int n) {
  const float nf = static_cast<float>(n);
  return cube_map1(x, n) * (nf / (nf - 0.5f));
}

float cube_bake_coordinate(CubeBake bake, float x, int n) {
  switch (bake) {
    case CubeBake::Centres: return cube_map1(x, n);
    case CubeBake::Stretch: return cube_map2(x, n);
    case CubeBake::Warp: return cube_warp3(cube_map1(x, n), n);
    case CubeBake::Fov: return cube_map_fov(x, n);
  }
  return 0.0f;
}

int CubeMap::level_count() const { return size > 0 ? static_cast<int>(std::log2(size)) + 1 : 0; }

size_t CubeMap::texel_count() const {
  const size_t n = static_cast<size_t>(size);
  return size > 0 ? kCubeFaces * (4 * n * n - 1) / 3 : 0;
}

CubeMap bake_cube_map(const DirectionFunction& radiance, int size, CubeBake bake, int samples) {
  if (size < 1 || size > kMaxCubeSize || (size & (size - 1)) != 0) {
    throw InputError("cube_size", "must be a power of two in 1.." + std::to_string(kMaxCubeSize) + ", got " +
                                      std::to_string(size));
  }
  assert(samples >= 1);
  CubeMap cube;
  cube.size = size;
  cube.bake = bake;
  const float inv_samples = 1.0f / static_cast<float>(samples);
  for (int f = 0; f < kCubeFaces; ++f) {
    for (int m = size; m >= 1; m /= 2) {
      TextureLevel level{m, m, {}};
      level.texels.reserve(static_cast<size_t>(m) * m);
      for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
          // Stretch and warp edge texels stand for the cube edge itself, shared by both faces:
          // a spread of samples would reach past the edge on each face's own plane and the two
          // copies would differ, so they take their one direction.
          const bool edge = (bake == CubeBake::Stretch || bake == CubeBake::Warp) && (i == 0 || j == 0 || i == m - 1 || j == m - 1);
          const int k = edge ? 1 : samples;
          const float step = edge ? 1.0f : inv_samples;
          glm::vec4 sum(0.0f);
          for (int b = 0; b < k; ++b) {
            const float y = static_cast<float>(j) + (static_cast<float>(b) + 0.5f) * step - 0.5f;
            const float tc = cube_bake_coordinate(bake, y, m);
            for (int a = 0; a < k; ++a) {
              const float x = static_cast<float>(i) + (static_cast<float>(a) + 0.5f) * step - 0.5f;
              sum += radiance(glm::normalize(cube_direction(f, cube_bake_coordinate(bake, x, m), tc)));
            }
          }
          level.texels.push_back(sum * (step * step));
        }
      }
      cube.faces[f].levels.push_back(std::move(level));
    }
  }
  return cube;
}

namespace {

// (sc, tc) of point p (major component +-1) on `face`: the major-axis table without the division.
glm::vec2 face_coordinates(int face, glm::vec3 p) {
  switch (face) {
    case 0: return {-p.z, -p.y};
    case 1: return {p.z, -p.y};
    case 2: return {p.x, p.z};
    case 3: return {p.x, -p.z};
    case 4: return {p.x, -p.y};
    default: return {-p.x, -p.y};
  }
}

int texel_of(float coordinate, int m) {
  return std::clamp(static_cast<int>(std::floor((coordinate + 1.0f) * 0.5f * static_cast<float>(m))), 0, m - 1);
}

}  // namespace

std::vector<CubeTexel> cube_edge_partners(int face, int m, int i, int j) {
  std::vector<CubeTexel> out;
  if (m == 1) {
    for (int f = 0; f < kCubeFaces; ++f)
      if (f != face) out.push_back({f, 0, 0});
    return out;
  }
  const float sc = cube_map1(static_cast<float>(i), m), tc = cube_map1(static_cast<float>(j), m);
  // Push the texel centre onto each edge it touches; the component that becomes +-1 there (other
  // than the face's own major one) is the adjacent face's major axis.
  auto across = [&](float edge_sc, float edge_tc) {
    const glm::vec3 p = cube_direction(face, edge_sc, edge_tc);
    const int major = face >> 1;
    for (int k = 0; k < 3; ++k) {
      if (k == major || std::fabs(p[k]) != 1.0f) continue;
      const int other = 2 * k + (p[k] < 0.0f ? 1 : 0);
      const glm::vec2 q = face_coordinates(other, p);
      out.push_back({other, texel_of(q.x, m), texel_of(q.y, m)});
      return;
    }
    assert(false);
  };
  if (i == 0 || i == m - 1) across(i == 0 ? -1.0f : 1.0f, tc);
  if (j == 0 || j == m - 1) across(sc, j == 0 ? -1.0f : 1.0f);
  return out;
}

void average_cube_edges(CubeMap& cube) {
  const CubeMap source = cube;  // every mean reads the baked values, never one already averaged
  for (int level = 0; level < cube.level_count(); ++level) {
    const int m = cube.size >> level;
    for (int f = 0; f < kCubeFaces; ++f) {
      for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
          std::vector<CubeTexel> group = cube_edge_partners(f, m, i, j);
          if (group.empty()) continue;
          group.push_back({f, i, j});
          // One order for every member of the group: the same sum, bit for bit.
          std::sort(group.begin(), group.end());
          glm::vec4 sum(0.0f);
          for (const CubeTexel& t : group) sum += source.faces[t.face].levels[level].at(t.i, t.j);
          cube.faces[f].levels[level].texels[static_cast<size_t>(j) * m + i] = sum / static_cast<float>(group.size());
        }
      }
    }
  }
}

size_t cube_texel_count(int size, bool border) {
  if (size <= 0) return 0;
  const size_t n = static_cast<size_t>(size);
  size_t levels = 0;
  for (size_t k = n; k >= 1; k /= 2) ++levels;
  return kCubeFaces * ((4 * n * n - 1) / 3 + (border ? 8 * n - 4 + 4 * levels : 0));
}

}  // namespace seamcl
