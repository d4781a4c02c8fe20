#include "pipeline/stages/triangle_setup_twin.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "pipeline/stages/sample_pattern.h"

namespace seamcl {
namespace {

struct ClipVertex {
  float x, y, w;  // clip space; depth is 1/w, so z is not kept
  float u, v;
};

// Signed distance to clip plane `plane` (inside >= 0): w >= near, then the guard band.
float clip_distance(const ClipVertex& p, int plane, const FrameParams& f) {
  switch (plane) {
    case 0: return p.w - f.near_w;
    case 1: return f.guard_x * p.w - p.x;
    case 2: return f.guard_x * p.w + p.x;
    case 3: return f.guard_y * p.w - p.y;
    default: return f.guard_y * p.w + p.y;
  }
}

// Always interpolated from the inside end, so a shared edge yields the same vertex both ways.
ClipVertex clip_lerp(const ClipVertex& in, const ClipVertex& out, float d_in, float d_out) {
  const float t = d_in / (d_in - d_out);
  return {in.x + t * (out.x - in.x), in.y + t * (out.y - in.y), in.w + t * (out.w - in.w), in.u + t * (out.u - in.u),
          in.v + t * (out.v - in.v)};
}

int64_t floor_div(int64_t value, int64_t divisor) {
  return value >= 0 ? value / divisor : -((-value + divisor - 1) / divisor);
}

TriangleSetup empty_setup(uint32_t face) {
  TriangleSetup s{};
  for (int i = 0; i < 3; ++i) s.edge_c[i] = -1;
  s.bbox_max_x = -1;
  s.bbox_max_y = -1;
  s.face = face;
  return s;
}

TriangleSetup setup_screen_triangle(std::array<ClipVertex, 3> c, uint32_t face, const FrameParams& f, bool cull_sampleless) {
  constexpr int64_t one = SEAMCL_SUBPIXEL_ONE;
  std::array<int64_t, 3> X{}, Y{};
  std::array<float, 3> inv_w{};
  for (int i = 0; i < 3; ++i) {
    inv_w[i] = 1.0f / c[i].w;
    const float sx = (c[i].x * inv_w[i] * 0.5f + 0.5f) * static_cast<float>(f.width);
    const float sy = (0.5f - c[i].y * inv_w[i] * 0.5f) * static_cast<float>(f.height);
    X[i] = static_cast<int64_t>(std::rint(sx * static_cast<float>(one)));
    Y[i] = static_cast<int64_t>(std::rint(sy * static_cast<float>(one)));
  }
  int64_t area2 = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
  // Front faces are counter-clockwise in NDC (y up), so negative on screen (y down).
  if (area2 >= 0) return empty_setup(face);
  std::swap(X[1], X[2]);
  std::swap(Y[1], Y[2]);
  std::swap(inv_w[1], inv_w[2]);
  std::swap(c[1], c[2]);
  area2 = -area2;

  TriangleSetup s{};
  s.face = face;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const int64_t a = Y[i] - Y[j];
    const int64_t b = X[j] - X[i];
    const bool top_left = a > 0 || (a == 0 && b > 0);
    s.edge_a[i] = static_cast<cl_int>(a);
    s.edge_b[i] = static_cast<cl_int>(b);
    s.edge_c[i] = -(a * X[i] + b * Y[i]) - (top_left ? 0 : 1);
  }
  const auto [min_x, max_x] = std::minmax({X[0], X[1], X[2]});
  const auto [min_y, max_y] = std::minmax({Y[0], Y[1], Y[2]});
  // Samples of pixel p lie in [p*one, p*one + one - 16].
  const int64_t span = one - 16;
  s.bbox_min_x = static_cast<cl_int>(std::max<int64_t>(floor_div(min_x - span + one - 1, one), 0));
  s.bbox_min_y = static_cast<cl_int>(std::max<int64_t>(floor_div(min_y - span + one - 1, one), 0));
  s.bbox_max_x = static_cast<cl_int>(std::min<int64_t>(floor_div(max_x, one), f.width - 1));
  s.bbox_max_y = static_cast<cl_int>(std::min<int64_t>(floor_div(max_y, one), f.height - 1));
  if (cull_sampleless && !box_holds_sample(min_x, max_x, min_y, max_y, f)) return empty_setup(face);

  const float scale = 1.0f / static_cast<float>(one);
  const float dx1 = static_cast<float>(X[1] - X[0]) * scale, dy1 = static_cast<float>(Y[1] - Y[0]) * scale;
  const float dx2 = static_cast<float>(X[2] - X[0]) * scale, dy2 = static_cast<float>(Y[2] - Y[0]) * scale;
  const float inv_det = 1.0f / (static_cast<float>(area2) * scale * scale);
  s.ref_x = static_cast<float>(X[0]) * scale;
  s.ref_y = static_cast<float>(Y[0]) * scale;
  // Planes of 1/w, u/w and v/w: value at vertex 0 and the screen gradient.
  auto plane = [&](const std::array<float, 3>& a, cl_float out[3]) {
    const float d1 = a[1] - a[0];
    const float d2 = a[2] - a[0];
    out[0] = a[0];
    out[1] = (d1 * dy2 - d2 * dy1) * inv_det;
    out[2] = (d2 * dx1 - d1 * dx2) * inv_det;
  };
  plane(inv_w, s.inv_w);
  plane({c[0].u * inv_w[0], c[1].u * inv_w[1], c[2].u * inv_w[2]}, s.u_over_w);
  plane({c[0].v * inv_w[0], c[1].v * inv_w[1], c[2].v * inv_w[2]}, s.v_over_w);
  return s;
}

// Clip-space vertex i (0..2) of input triangle t (face t/2; t even: quad corners 0,1,2, odd: 0,2,3).
ClipVertex input_vertex(const PackedScene& scene, const FrameParams& f, int t, int i) {
  constexpr float corner_u[4] = {0, 1, 1, 0};
  constexpr float corner_v[4] = {0, 0, 1, 1};
  const FaceGpu& face = scene.faces.at(static_cast<size_t>(t / 2));
  const int corner = i == 0 ? 0 : (t & 1) ? i + 1 : i;
  const cl_float4& p = scene.positions.at(face.vertex[corner]);
  const float* m = f.view_proj;
  const float px = p.s[0], py = p.s[1], pz = p.s[2];
  return {m[0] * px + m[4] * py + m[8] * pz + m[12], m[1] * px + m[5] * py + m[9] * pz + m[13],
          m[3] * px + m[7] * py + m[11] * pz + m[15], corner_u[corner], corner_v[corner]};
}

}  // namespace

EarlyCullCounts early_culled_reference(const PackedScene& scene, const FrameParams& f) {
  constexpr int64_t one = SEAMCL_SUBPIXEL_ONE;
  // Samples of pixel p lie in [p*one, p*one + one - 16].
  const int64_t last_x = (f.width - 1) * one + one - 16, last_y = (f.height - 1) * one + one - 16;
  EarlyCullCounts culled;
  for (int t = 0; t < f.input_triangles; ++t) {
    bool inside = true;
    std::array<bool, 5> outside_all{true, true, true, true, true};
    std::array<int64_t, 3> X{}, Y{};
    for (int i = 0; i < 3; ++i) {
      const ClipVertex c = input_vertex(scene, f, t, i);
      for (int plane = 0; plane < 5; ++plane) {
        const float d = clip_distance(c, plane, f);
        inside &= d >= 0.0f;
        outside_all[static_cast<size_t>(plane)] = outside_all[static_cast<size_t>(plane)] && d < 0.0f;
      }
      // setup_screen_triangle's snapping
      const float inv_w = 1.0f / c.w;
      const float sx = (c.x * inv_w * 0.5f + 0.5f) * static_cast<float>(f.width);
      const float sy = (0.5f - c.y * inv_w * 0.5f) * static_cast<float>(f.height);
      X[i] = static_cast<int64_t>(std::rint(sx * static_cast<float>(one)));
      Y[i] = static_cast<int64_t>(std::rint(sy * static_cast<float>(one)));
    }
    if (!inside) {
      // Clipped triangles go to the full setup, unless all three vertices lie outside one plane.
      culled.outside_a_plane += std::find(outside_all.begin(), outside_all.end(), true) != outside_all.end();
      continue;
    }
    const int64_t area2 = (X[1] - X[0]) * (Y[2] - Y[0]) - (Y[1] - Y[0]) * (X[2] - X[0]);
    const auto all = [](const std::array<int64_t, 3>& v, auto past) { return past(v[0]) && past(v[1]) && past(v[2]); };
    const bool off_image = all(X, [](int64_t v) { return v < 0; }) || all(Y, [](int64_t v) { return v < 0; }) ||
                           all(X, [&](int64_t v) { return v > last_x; }) || all(Y, [&](int64_t v) { return v > last_y; });
    culled.unclipped += area2 >= 0 || off_image;
  }
  return culled;
}

bool box_holds_sample(int64_t min_x, int64_t max_x, int64_t min_y, int64_t max_y, const FrameParams& f) {
  constexpr int64_t one = SEAMCL_SUBPIXEL_ONE;
  for (const SampleOffset& o : sample_pattern(f.sample_count)) {
    // Sample o of pixel p sits at p * one + centre; the first and last pixel that put it in range.
    const int64_t centre_x = sample_fixed_x(0, o), centre_y = sample_fixed_y(0, o);
    const int64_t first_x = std::max<int64_t>(-floor_div(centre_x - min_x, one), 0);
    const int64_t last_x = std::min<int64_t>(floor_div(max_x - centre_x, one), f.width - 1);
    const int64_t first_y = std::max<int64_t>(-floor_div(centre_y - min_y, one), 0);
    const int64_t last_y = std::min<int64_t>(floor_div(max_y - centre_y, one), f.height - 1);
    if (first_x <= last_x && first_y <= last_y) return true;
  }
  return false;
}

std::vector<TriangleSetup> setup_triangles_reference(const PackedScene& scene, const FrameParams& f, bool cull_sampleless) {
  std::vector<TriangleSetup> out;
  out.reserve(static_cast<size_t>(f.input_triangles) * SEAMCL_CLIP_SLOTS);
  for (int t = 0; t < f.input_triangles; ++t) {
    const uint32_t face_index = static_cast<uint32_t>(t / 2);
    std::vector<ClipVertex> polygon;
    for (int i = 0; i < 3; ++i) polygon.push_back(input_vertex(scene, f, t, i));
    // Sutherland-Hodgman against the near plane and the guard band.
    for (int plane = 0; plane < 5 && !polygon.empty(); ++plane) {
      std::vector<float> d;
      for (const ClipVertex& p : polygon) d.push_back(clip_distance(p, plane, f));
      if (std::all_of(d.begin(), d.end(), [](float x) { return x >= 0.0f; })) continue;
      std::vector<ClipVertex> clipped;
      const size_t n = polygon.size();
      for (size_t i = 0; i < n; ++i) {
        const size_t j = (i + 1) % n;
        const bool in_i = d[i] >= 0.0f, in_j = d[j] >= 0.0f;
        if (in_i) clipped.push_back(polygon[i]);
        if (in_i != in_j) {
          clipped.push_back(in_i ? clip_lerp(polygon[i], polygon[j], d[i], d[j]) : clip_lerp(polygon[j], polygon[i], d[j], d[i]));
        }
      }
      polygon = std::move(clipped);
    }
    // Fan triangulation into the fixed slots.
    for (int k = 0; k < SEAMCL_CLIP_SLOTS; ++k) {
      if (static_cast<size_t>(k + 2) < polygon.size()) {
        out.push_back(setup_screen_triangle({polygon[0], polygon[k + 1], polygon[k + 2]}, face_index, f, cull_sampleless));
      } else {
        out.push_back(empty_setup(face_index));
      }
    }
  }
  return out;
}

}  // namespace seamcl
