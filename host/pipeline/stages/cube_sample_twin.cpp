#include "pipeline/stages/cube_sample_twin.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include <seamcl/scene/cube_map.h>
#include "pipeline/stages/texture_sample_twin.h"

namespace seamcl {
namespace {

int select_face(glm::vec3 d) {
  const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
  if (ax >= ay && ax >= az) return d.x < 0.0f ? 1 : 0;
  if (ay >= az) return d.y < 0.0f ? 3 : 2;
  return d.z < 0.0f ? 5 : 4;
}

// (ma, sc, tc) of v on `face`: the major-axis table.
glm::vec3 face_components(int face, glm::vec3 v) {
  switch (face) {
    case 0: return {v.x, -v.z, -v.y};
    case 1: return {-v.x, v.z, -v.y};
    case 2: return {v.y, v.x, v.z};
    case 3: return {-v.y, v.x, -v.z};
    case 4: return {v.z, v.x, -v.y};
    default: return {-v.z, -v.x, -v.y};
  }
}

void add_texel(FilterSum& sum, const std::vector<float>& texels, uint32_t index, float weight) {
  assert(4 * size_t{index} + 3 < texels.size());
  sum.color.r += weight * texels[4 * size_t{index}];
  sum.color.g += weight * texels[4 * size_t{index} + 1];
  sum.color.b += weight * texels[4 * size_t{index} + 2];
  sum.color.a += weight * texels[4 * size_t{index} + 3];
  sum.weight += weight;
}

void tap(FilterSum& sum, const std::vector<float>& texels, int size, int face, int level, int m, int i, int j, float w,
         int method) {
  const bool out_i = i < 0 || i >= m;
  const bool out_j = j < 0 || j >= m;
  const int ci = std::clamp(i, 0, m - 1), cj = std::clamp(j, 0, m - 1);
  if (method == SEAMCL_CUBE_BORDER) {
    // The border holds what seamless reads one texel out; further out clamps to the border.
    add_texel(sum, texels, cube_border_texel_index(size, face, level, std::clamp(i, -1, m), std::clamp(j, -1, m)), w);
  } else if (!out_i && !out_j) {
    add_texel(sum, texels, cube_texel_index(size, face, level, i, j), w);
  } else if (method == SEAMCL_CUBE_DISCARD) {
    // border zero
  } else if (method != SEAMCL_CUBE_SEAMLESS) {
    add_texel(sum, texels, cube_texel_index(size, face, level, ci, cj), w);
  } else if (out_i && out_j) {
    // The mean of the three texels that meet at the corner.
    const float third = w * (1.0f / 3.0f);
    add_texel(sum, texels, cube_texel_index(size, face, level, ci, cj), third);
    add_texel(sum, texels, cube_fold_texel(size, face, level, m, i, cj), third);
    add_texel(sum, texels, cube_fold_texel(size, face, level, m, ci, j), third);
  } else {
    add_texel(sum, texels, cube_fold_texel(size, face, level, m, i, j), w);
  }
}

void bilinear(FilterSum& sum, const std::vector<float>& texels, int size, int face, int level, float s, float t,
              float weight, int method) {
  const int m = std::max(size >> level, 1);
  // fixup-level and fov: this level's own scale about the face centre.
  const float scale = cube_level_scale(method, m);
  s = 0.5f + (s - 0.5f) * scale;
  t = 0.5f + (t - 0.5f) * scale;
  const float lo = method == SEAMCL_CUBE_SEAMLESS ? -static_cast<float>(m) : -2.0f;
  const float hi = method == SEAMCL_CUBE_SEAMLESS ? 2.0f * static_cast<float>(m) - 2.0f : static_cast<float>(m) + 1.0f;
  const float x = std::fmin(std::fmax(s * static_cast<float>(m) - 0.5f, lo), hi);
  const float y = std::fmin(std::fmax(t * static_cast<float>(m) - 0.5f, lo), hi);
  const float x_floor = std::floor(x), y_floor = std::floor(y);
  const float fx = x - x_floor, fy = y - y_floor;
  const int ix = static_cast<int>(x_floor), iy = static_cast<int>(y_floor);
  const float w00 = (1.0f - fx) * (1.0f - fy);
  const float w10 = (1.0f - fy) - w00;
  const float w01 = (1.0f - fx) - w00;
  const float w11 = fy - w01;
  tap(sum, texels, size, face, level, m, ix, iy, weight * w00, method);
  tap(sum, texels, size, face, level, m, ix + 1, iy, weight * w10, method);
  tap(sum, texels, size, face, level, m, ix, iy + 1, weight * w01, method);
  tap(sum, texels, size, face, level, m, ix + 1, iy + 1, weight * w11, method);
}

void trilinear(FilterSum& sum, const std::vector<float>& texels, const CubeSampler& cube, int face, float s, float t,
               float lod, float weight, int method) {
  lod = std::fmin(std::fmax(lod, 0.0f), static_cast<float>(cube.level_count - 1));
  if (method == SEAMCL_CUBE_FIXUP) {
    const glm::vec2 fixed = cube_fixup_uv(s, t, lod, cube.size);
    s = fixed.x;
    t = fixed.y;
  }
  const int level0 = static_cast<int>(lod);
  const int level1 = std::min(level0 + 1, cube.level_count - 1);
  const float f = lod - static_cast<float>(level0);
  bilinear(sum, texels, cube.size, face, level0, s, t, weight * (1.0f - f), method);
  bilinear(sum, texels, cube.size, face, level1, s, t, weight * f, method);
}

float lod_of(float len2) { return 0.5f * approx_log2(std::fmax(len2, 1e-30f)); }

}  // namespace

CubeUv cube_project(glm::vec3 d, glm::vec3 ddx, glm::vec3 ddy) {
  CubeUv c;
  c.face = select_face(d);
  glm::vec3 p = face_components(c.face, d);  // (ma, sc, tc)
  const glm::vec3 px = face_components(c.face, ddx);
  const glm::vec3 py = face_components(c.face, ddy);
  // |sc|, |tc| <= ma holds for every finite direction; a NaN component fails it.
  c.valid = p.x > 0.0f && p.x < INFINITY && std::fabs(p.y) <= p.x && std::fabs(p.z) <= p.x;
  if (!c.valid) {
    c.face = 0;
    p = {1.0f, 0.0f, 0.0f};
  }
  const float inv = 1.0f / p.x;
  const float u = p.y * inv, v = p.z * inv;
  c.s = 0.5f * (u + 1.0f);
  c.t = 0.5f * (v + 1.0f);
  // d(sc/ma) = (dsc - (sc/ma) dma) / ma
  c.dsdx = 0.5f * (px.y - u * px.x) * inv;
  c.dtdx = 0.5f * (px.z - v * px.x) * inv;
  c.dsdy = 0.5f * (py.y - u * py.x) * inv;
  c.dtdy = 0.5f * (py.z - v * py.x) * inv;
  return c;
}

uint32_t cube_texel_index(int size, int face, int level, int i, int j) {
  const uint32_t n = static_cast<uint32_t>(size);
  const uint32_t m = std::max(n >> level, 1u);
  assert(i >= 0 && j >= 0 && static_cast<uint32_t>(i) < m && static_cast<uint32_t>(j) < m);
  const uint32_t face_start = static_cast<uint32_t>(face) * ((4u * n * n - 1u) / 3u);
  const uint32_t level_start = 4u * (n * n - m * m) / 3u;
  return face_start + level_start + static_cast<uint32_t>(j) * m + static_cast<uint32_t>(i);
}

uint32_t cube_border_texel_index(int size, int face, int level, int i, int j) {
  const uint32_t n = static_cast<uint32_t>(size);
  const uint32_t m = std::max(n >> level, 1u);
  assert(i >= -1 && j >= -1 && i <= static_cast<int>(m) && j <= static_cast<int>(m));
  uint32_t levels = 0;
  for (uint32_t k = n; k >= 1; k /= 2) ++levels;
  const uint32_t face_texels = (4u * n * n - 1u) / 3u + 8u * n - 4u + 4u * levels;
  const uint32_t level_start = 4u * (n * n - m * m) / 3u + 8u * (n - m) + 4u * static_cast<uint32_t>(level);
  return static_cast<uint32_t>(face) * face_texels + level_start + static_cast<uint32_t>(j + 1) * (m + 2u) +
         static_cast<uint32_t>(i + 1);
}

float cube_level_scale(int method, int m) {
  if (method == SEAMCL_CUBE_FIXUP_LEVEL) return 1.0f - 1.0f / static_cast<float>(m);
  if (method == SEAMCL_CUBE_FOV) return 1.0f - 0.5f / static_cast<float>(m);
  return 1.0f;
}

uint32_t cube_fold_texel(int size, int face, int level, int m, int i, int j) {
  const float sc = (static_cast<float>(i) + 0.5f) * 2.0f / static_cast<float>(m) - 1.0f;
  const float tc = (static_cast<float>(j) + 0.5f) * 2.0f / static_cast<float>(m) - 1.0f;
  glm::vec3 p = cube_direction(face, sc, tc);
  const int major = face >> 1;
  // Fold the component past +-1 about the cube edge: it becomes +-1 and the major component
  // shrinks by as much as it went past.
  float past = 0.0f;
  for (int k = 0; k < 3; ++k) {
    if (k != major && std::fabs(p[k]) > 1.0f) {
      past = std::fabs(p[k]) - 1.0f;
      p[k] = p[k] > 0.0f ? 1.0f : -1.0f;
      break;
    }
  }
  p[major] *= 1.0f - past;
  const int other = select_face(p);
  const glm::vec3 q = face_components(other, p);
  const int i2 = std::clamp(static_cast<int>(std::floor((q.y + 1.0f) * 0.5f * static_cast<float>(m))), 0, m - 1);
  const int j2 = std::clamp(static_cast<int>(std::floor((q.z + 1.0f) * 0.5f * static_cast<float>(m))), 0, m - 1);
  return cube_texel_index(size, other, level, i2, j2);
}

float cube_fixup_scale(float lod, int size) { return 1.0f - std::exp2(lod) / static_cast<float>(size); }

glm::vec2 cube_fixup_uv(float s, float t, float lod, int size) {
  const float scale = cube_fixup_scale(lod, size);
  return {0.5f + (s - 0.5f) * scale, 0.5f + (t - 0.5f) * scale};
}

FilterSum cube_filter_reference(const std::vector<float>& texels, const CubeSampler& cube, const CubeUv& c,
                                float roughness, float explicit_lod, int method) {
  FilterSum sum;
  const float n = static_cast<float>(cube.size);
  float ax_u = c.dsdx, ax_v = c.dtdx, ay_u = c.dsdy, ay_v = c.dtdy;
  float len2_x = (ax_u * ax_u + ax_v * ax_v) * (n * n);
  float len2_y = (ay_u * ay_u + ay_v * ay_v) * (n * n);
  if (roughness > 0.0f) {
    // Glossy: each axis lengthened, in quadrature, by a blur of roughness / 2 face widths.
    const float blur = 0.5f * roughness;
    const float blur2 = blur * blur * n * n;
    if (len2_x > 0.0f) {
      const float k = std::sqrt((len2_x + blur2) / len2_x);
      ax_u *= k;
      ax_v *= k;
    } else {
      ax_u = blur;
      ax_v = 0.0f;
    }
    if (len2_y > 0.0f) {
      const float k = std::sqrt((len2_y + blur2) / len2_y);
      ay_u *= k;
      ay_v *= k;
    } else {
      ay_u = 0.0f;
      ay_v = blur;
    }
    len2_x += blur2;
    len2_y += blur2;
  }
  const bool finite = c.valid && len2_x < INFINITY && len2_y < INFINITY;
  // Every filter is N probes along the longer axis, trilinear at one lod: one at the centre
  // except for aniso.
  int probes = 1;
  float lod = static_cast<float>(cube.level_count - 1);  // non-finite: the coarsest level
  float step_u = 0.0f, step_v = 0.0f;
  if (explicit_lod >= 0.0f) {
    lod = explicit_lod;
  } else if (!finite) {
  } else if (cube.filter == SEAMCL_FILTER_BILINEAR) {
    lod = 0.0f;
  } else if (cube.filter == SEAMCL_FILTER_TRILINEAR) {
    lod = lod_of(std::fmax(len2_x, len2_y));
  } else {
    const bool x_major = len2_x >= len2_y;
    const float major2 = x_major ? len2_x : len2_y;
    const float minor2 = x_major ? len2_y : len2_x;
    const float ratio = minor2 > 0.0f   ? std::sqrt(major2 / minor2)
                        : major2 > 0.0f ? static_cast<float>(cube.max_aniso)
                                        : 1.0f;
    probes = probe_count(ratio, cube.max_aniso);
    lod = lod_of(major2) - log2_probe_count(probes);
    step_u = (x_major ? ax_u : ay_u) / static_cast<float>(probes);
    step_v = (x_major ? ax_v : ay_v) / static_cast<float>(probes);
  }
  const float inv_probes = 1.0f / static_cast<float>(probes);
  float pu = c.s + step_u * (0.5f - 0.5f * static_cast<float>(probes));
  float pv = c.t + step_v * (0.5f - 0.5f * static_cast<float>(probes));
  for (int i = 0; i < probes; ++i) {
    trilinear(sum, texels, cube, c.face, pu, pv, lod, inv_probes, method);
    pu += step_u;
    pv += step_v;
  }
  return sum;
}

glm::vec4 sample_cube_reference(const std::vector<float>& texels, const CubeSampler& cube, glm::vec3 d, glm::vec3 ddx,
                                glm::vec3 ddy, float roughness, float explicit_lod) {
  const CubeUv c = cube_project(d, ddx, ddy);
  FilterSum sum = cube_filter_reference(texels, cube, c, roughness, explicit_lod, cube.method);
  if (cube.method != SEAMCL_CUBE_DISCARD) return sum.color;
  if (sum.weight == 0.0f) sum = cube_filter_reference(texels, cube, c, roughness, explicit_lod, SEAMCL_CUBE_CLAMP);
  return sum.color * (1.0f / sum.weight);
}

}  // namespace seamcl
