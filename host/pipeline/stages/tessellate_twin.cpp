#include "pipeline/stages/tessellate_twin.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace seamcl {
namespace {

constexpr int64_t kOne = SEAMCL_DOMAIN_ONE;
constexpr float kInvOne = 1.0f / static_cast<float>(SEAMCL_DOMAIN_ONE);

struct Map {
  const uint16_t* samples;
  int columns, rows;
};

Map map_of(const PackedDisplacement& d, int face) {
  const DisplacementPatch& p = d.patches[static_cast<size_t>(face)];
  return {d.samples.data() + p.map_offset, p.columns, p.rows};
}

float texel(const Map& m, int i, int j) { return static_cast<float>(m.samples[j * m.columns + i]); }

// Bilinear over the corner-to-corner sample grid, in float; 0 for a face without a map.
float sample_float(const Map& m, float u, float v) {
  if (m.columns == 0) return 0.0f;
  const float x = u * static_cast<float>(m.columns - 1);
  const float y = v * static_cast<float>(m.rows - 1);
  int i0 = static_cast<int>(x), j0 = static_cast<int>(y);
  i0 = i0 > m.columns - 2 ? m.columns - 2 : i0;
  j0 = j0 > m.rows - 2 ? m.rows - 2 : j0;
  i0 = i0 < 0 ? 0 : i0;
  j0 = j0 < 0 ? 0 : j0;
  const int i1 = m.columns > 1 ? i0 + 1 : 0, j1 = m.rows > 1 ? j0 + 1 : 0;
  const float fx = m.columns > 1 ? x - static_cast<float>(i0) : 0.0f;
  const float fy = m.rows > 1 ? y - static_cast<float>(j0) : 0.0f;
  const float bottom = (1.0f - fx) * texel(m, i0, j0) + fx * texel(m, i1, j0);
  const float top = (1.0f - fx) * texel(m, i0, j1) + fx * texel(m, i1, j1);
  return ((1.0f - fy) * bottom + fy * top) * (1.0f / 65535.0f);
}

// Bilinear in exact integer arithmetic at a fixed-point domain point: the same point on the same
// piecewise-linear samples gives the same integer, whichever face computes it.
float sample_exact(const Map& m, int64_t u, int64_t v) {
  if (m.columns == 0) return 0.0f;
  int64_t xn = u * (m.columns - 1), yn = v * (m.rows - 1);
  int64_t i0 = xn >> 16, j0 = yn >> 16, fx = xn & (kOne - 1), fy = yn & (kOne - 1);
  if (m.columns == 1) { i0 = 0; fx = 0; } else if (i0 >= m.columns - 1) { i0 = m.columns - 2; fx = kOne; }
  if (m.rows == 1) { j0 = 0; fy = 0; } else if (j0 >= m.rows - 1) { j0 = m.rows - 2; fy = kOne; }
  const int64_t i1 = m.columns > 1 ? i0 + 1 : 0, j1 = m.rows > 1 ? j0 + 1 : 0;
  auto at = [&](int64_t i, int64_t j) { return static_cast<int64_t>(m.samples[j * m.columns + i]); };
  const int64_t bottom = at(i0, j0) * (kOne - fx) + at(i1, j0) * fx;
  const int64_t top = at(i0, j1) * (kOne - fx) + at(i1, j1) * fx;
  const int64_t numerator = bottom * (kOne - fy) + top * fy;  // < 2^48
  return static_cast<float>(numerator) * (1.0f / 4294967296.0f) * (1.0f / 65535.0f);
}

// uv of the point at parameter s (fixed point, from corner e) on edge e.
void edge_uv(int e, int64_t s, int64_t* u, int64_t* v) {
  switch (e) {
    case 0: *u = s; *v = 0; break;
    case 1: *u = kOne; *v = s; break;
    case 2: *u = kOne - s; *v = kOne; break;
    default: *u = 0; *v = kOne - s; break;
  }
}

// Adaptive factors: slot k of T slots at factor f (1..T) is step k * f / T rounded half up.
int step_of_slot(int k, int f, int t) { return (2 * k * f + t) / (2 * t); }

// Adaptive: a slot on edge e whose step is 0 or the edge's factor is that corner's slot.
void collapse_to_corner(const DisplacementPatch& p, int t, int* i, int* j) {
  if ((*i == 0 || *i == t) && (*j == 0 || *j == t)) return;
  int e = -1, step = 0;
  if (*j == 0) { e = 0; step = *i; }
  else if (*i == t) { e = 1; step = *j; }
  else if (*j == t) { e = 2; step = t - *i; }
  else if (*i == 0) { e = 3; step = t - *j; }
  if (e < 0) return;
  const int f = p.edge_factor[e];
  const bool lower_first = p.vertex[e] < p.vertex[(e + 1) % 4];
  const int m = step_of_slot(lower_first ? step : t - step, f, t);
  const int from_e = lower_first ? m : f - m;
  if (from_e != 0 && from_e != f) return;
  const int c = from_e == 0 ? e : (e + 1) % 4;
  *i = (c == 1 || c == 2) ? t : 0;
  *j = c >= 2 ? t : 0;
}

// ptex-filter: a 3x3 tent (weights 1/4, 1/2, 1/4 per axis) of taps one own sample spacing apart;
// a tap past edge e reads the neighbour at the same distance past its side of the edge; taps past
// a corner or a boundary are dropped; the sum is renormalised.
float sample_across_edges(const PackedDisplacement& d, int face, float u, float v, cl_uint* taken) {
  const DisplacementPatch& p = d.patches[static_cast<size_t>(face)];
  const Map own = map_of(d, face);
  if (own.columns == 0) return 0.0f;
  const float rx = own.columns > 1 ? 1.0f / static_cast<float>(own.columns - 1) : 0.0f;
  const float ry = own.rows > 1 ? 1.0f / static_cast<float>(own.rows - 1) : 0.0f;
  const float tent[3] = {0.25f, 0.5f, 0.25f};
  float sum = 0.0f, weight = 0.0f;
  for (int b = 0; b < 3; ++b) {
    for (int a = 0; a < 3; ++a) {
      const float w = tent[a] * tent[b];
      const float tu = u + static_cast<float>(a - 1) * rx, tv = v + static_cast<float>(b - 1) * ry;
      const int out_u = tu < 0.0f ? 3 : tu > 1.0f ? 1 : -1, out_v = tv < 0.0f ? 0 : tv > 1.0f ? 2 : -1;
      if (out_u < 0 && out_v < 0) {
        sum = sum + w * sample_float(own, tu, tv);
        weight = weight + w;
        *taken += 1;
        continue;
      }
      if (out_u >= 0 && out_v >= 0) continue;  // past a corner
      const int e = out_u >= 0 ? out_u : out_v;
      const int n = p.neighbor[e];
      if (n < 0) continue;  // a boundary
      const float s = e == 0 ? tu : e == 1 ? tv : e == 2 ? 1.0f - tu : 1.0f - tv;
      const float depth = e == 0 ? -tv : e == 1 ? tu - 1.0f : e == 2 ? tv - 1.0f : -tu;
      const float sn = p.neighbor_same_way[e] ? s : 1.0f - s;
      const int m = p.neighbor_edge[e];
      // The neighbour's edge point, moved inwards by depth.
      const float nu = m == 0 ? sn : m == 1 ? 1.0f - depth : m == 2 ? 1.0f - sn : depth;
      const float nv = m == 0 ? depth : m == 1 ? sn : m == 2 ? 1.0f - depth : 1.0f - sn;
      const Map theirs = map_of(d, n);
      if (theirs.columns == 0) continue;
      sum = sum + w * sample_float(theirs, nu, nv);
      weight = weight + w;
      *taken += 1;
    }
  }
  return weight > 0.0f ? sum / weight : 0.0f;
}

}  // namespace

TessVertex tessellate_vertex_reference(const PackedDisplacement& d, int patch, int i, int j) {
  const TessellationParams& params = d.params;
  const DisplacementPatch& p = d.patches[static_cast<size_t>(patch)];
  const int t = params.tessellation;
  const bool naive = params.method == SEAMCL_DISPLACEMENT_NAIVE;
  const bool adaptive = p.inner_factor > 0;
  // 1. The domain point. Which edge (if any) the vertex lies on, and its step from corner e.
  if (adaptive) collapse_to_corner(p, t, &i, &j);
  int edge = -1, step = 0;
  const bool corner = (i == 0 || i == t) && (j == 0 || j == t);
  if (!corner) {
    if (j == 0) { edge = 0; step = i; }
    else if (i == t) { edge = 1; step = j; }
    else if (j == t) { edge = 2; step = t - i; }
    else if (i == 0) { edge = 3; step = t - j; }
  }
  int64_t uf = int64_t{i} * kOne / t, vf = int64_t{j} * kOne / t;
  float naive_u = static_cast<float>(i) / static_cast<float>(t), naive_v = static_cast<float>(j) / static_cast<float>(t);
  int64_t s = 0;  // on an edge: the fixed-point parameter from corner `edge`
  if (edge >= 0) {
    // Computed from the edge's end with the lower vertex index and mirrored at the other, so the
    // two patches sharing the edge produce the same points.
    const bool lower_first = p.vertex[edge] < p.vertex[(edge + 1) % 4];
    if (adaptive) {
      const int f = p.edge_factor[edge];
      const int m = step_of_slot(lower_first ? step : t - step, f, t);
      s = lower_first ? int64_t{m} * kOne / f : kOne - int64_t{m} * kOne / f;
      const float ns = static_cast<float>(lower_first ? m : f - m) / static_cast<float>(f);
      naive_u = edge == 0 ? ns : edge == 1 ? 1.0f : edge == 2 ? 1.0f - ns : 0.0f;
      naive_v = edge == 0 ? 0.0f : edge == 1 ? ns : edge == 2 ? 1.0f : 1.0f - ns;
    } else {
      s = lower_first ? int64_t{step} * kOne / t : kOne - int64_t{t - step} * kOne / t;
    }
    edge_uv(edge, s, &uf, &vf);
  } else if (adaptive && !corner) {
    // The inner grid at the inside's factor, one step in from every edge.
    const int f = p.inner_factor;
    const int a = std::clamp(step_of_slot(i, f, t), 1, f - 1), b = std::clamp(step_of_slot(j, f, t), 1, f - 1);
    uf = int64_t{a} * kOne / f;
    vf = int64_t{b} * kOne / f;
    naive_u = static_cast<float>(a) / static_cast<float>(f);
    naive_v = static_cast<float>(b) / static_cast<float>(f);
  }
  const float u = naive ? naive_u : static_cast<float>(uf) * kInvOne;
  const float v = naive ? naive_v : static_cast<float>(vf) * kInvOne;

  // 2. The base surface: bilinear in the corners, positions and vertex normals.
  const float w[4] = {(1.0f - u) * (1.0f - v), u * (1.0f - v), u * v, (1.0f - u) * v};
  float pos[3] = {0.0f, 0.0f, 0.0f}, nrm[3] = {0.0f, 0.0f, 0.0f};
  for (int k = 0; k < 4; ++k) {
    const cl_float4& P = d.positions[p.vertex[k]];
    const cl_float4& N = d.normals[p.vertex[k]];
    for (int c = 0; c < 3; ++c) {
      pos[c] = pos[c] + w[k] * P.s[c];
      nrm[c] = nrm[c] + w[k] * N.s[c];
    }
  }
  const float length = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
  const float inv_length = length > 0.0f ? 1.0f / length : 0.0f;

  // 3. The displacement, by the method's rule.
  const Map own = map_of(d, patch);
  float h = 0.0f;
  cl_uint samples = 0;
  if (params.method == SEAMCL_DISPLACEMENT_NAIVE) {
    h = sample_float(own, u, v);
    samples = own.columns > 0;
  } else if (params.method == SEAMCL_DISPLACEMENT_FIXED) {
    h = sample_exact(own, uf, vf);
    samples = own.columns > 0;
  } else if (params.method == SEAMCL_DISPLACEMENT_PTEX_FILTER) {
    h = sample_across_edges(d, patch, u, v, &samples);
  } else if (params.method == SEAMCL_DISPLACEMENT_ZIPPER) {
    if (corner) {
      h = p.corner_value[(i == 0 ? (j == 0 ? 0 : 3) : (j == 0 ? 1 : 2))];
    } else if (edge >= 0 && p.neighbor[edge] >= 0) {
      // Both sides' samples at the same edge point, each from its own map; a + b == b + a.
      const int other = p.neighbor[edge];
      int64_t ou = 0, ov = 0;
      edge_uv(p.neighbor_edge[edge], p.neighbor_same_way[edge] ? s : kOne - s, &ou, &ov);
      const Map theirs = map_of(d, other);
      h = (sample_float(own, u, v) + sample_float(theirs, static_cast<float>(ou) * kInvOne,
                                                  static_cast<float>(ov) * kInvOne)) * 0.5f;
      samples = (own.columns > 0) + (theirs.columns > 0);
    } else {
      h = sample_float(own, u, v);
      samples = own.columns > 0;
    }
  } else {  // ownership: the post's index formulas over corners (0,0), (1,0), (1,1), (0,1)
    const int x0 = uf == 0, x1 = uf == kOne, y0 = vf == 0, y1 = vf == kOne;
    const int index[4] = {2 * x0 + y0, 2 * y0 + x1, 2 * x1 + y1, 2 * y1 + x0};
    float tu = 0.0f, tv = 0.0f;
    int face = -1;
    float heaviest = 0.0f;
    for (int k = 0; k < 4; ++k) {
      const DisplacementTexcoord& tc = p.texcoord[k][index[k]];
      tu = tu + w[k] * tc.u;
      tv = tv + w[k] * tc.v;
      if (w[k] > heaviest) {
        heaviest = w[k];
        face = tc.face;
      }
    }
    if (face >= 0) {
      const Map m = map_of(d, face);
      h = sample_float(m, tu, tv);
      samples = m.columns > 0;
    }
  }

  // 4. Displace along the unit normal.
  const float offset = params.scale * h;
  TessVertex out{};
  for (int c = 0; c < 3; ++c) out.position[c] = pos[c] + (nrm[c] * inv_length) * offset;
  out.u = u;
  out.v = v;
  out.displacement = h;
  out.samples = samples;
  return out;
}

std::vector<TessVertex> tessellate_reference(const PackedDisplacement& packed) {
  std::vector<TessVertex> out;
  const int t = packed.params.tessellation;
  out.reserve(packed.vertex_count());
  for (int patch = 0; patch < static_cast<int>(packed.patches.size()); ++patch)
    for (int j = 0; j <= t; ++j)
      for (int i = 0; i <= t; ++i) out.push_back(tessellate_vertex_reference(packed, patch, i, j));
  return out;
}

}  // namespace seamcl
