// Coverage is watertight: on a surface that covers the whole view every sample is covered by
// exactly one triangle, on a closed convex mesh by at most one (back faces culled), and the raster
// stage's winners agree. Coverage is counted independently of the raster kernel, from the edge
// functions setup wrote (every setup slot tested at every sample position of its box), so a crack
// shows as a count of 0 and double coverage as 2 even where the depth test would hide it. Where a
// sample should be covered is decided a third way, by casting its ray against the ideal geometry
// in double precision (only where the answer is the same half a pixel around the sample).
// Every case runs at 1, 2, 4, 8 and 16 samples. The one allowed exception: where snapping to
// 1/256 pixel turns a sliver thinner than that around, the snapped mesh folds over and the
// sliver's neighbours overlap (GrazingPlaneDoubleCoverageOnlyFromSnappedFolds bounds it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>
#include "pipeline/frame_params.h"
#include "test_support.h"

using namespace seamcl;

namespace {

constexpr int kSampleCounts[] = {1, 2, 4, 8, 16};
constexpr uint32_t kSlotsPerFace = 2 * SEAMCL_CLIP_SLOTS;

// The D3D11 standard sample positions, in 1/16 pixel from the pixel centre, y down.
constexpr int kD3D11Offsets[5][16][2] = {
    {{0, 0}},
    {{4, 4}, {-4, -4}},
    {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}},
    {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}},
    {{1, 1}, {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5}, {5, 3}, {3, -5},
     {-2, 6}, {0, -7}, {-4, -6}, {-6, 4}, {-8, 0}, {7, -4}, {6, 7}, {-7, -8}}};

int pattern_row(int samples) { return samples == 1 ? 0 : samples == 2 ? 1 : samples == 4 ? 2 : samples == 8 ? 3 : 4; }

// Fixed-point (8 sub-pixel bits) sample position: X = x * 256 + 128 + dx * 16.
int64_t sample_x(int x, int samples, int s) { return int64_t{x} * 256 + 128 + kD3D11Offsets[pattern_row(samples)][s][0] * 16; }
int64_t sample_y(int y, int samples, int s) { return int64_t{y} * 256 + 128 + kD3D11Offsets[pattern_row(samples)][s][1] * 16; }

bool setup_is_empty(const TriangleSetup& t) { return t.bbox_max_x < t.bbox_min_x || t.bbox_max_y < t.bbox_min_y; }

int64_t edge_value(const TriangleSetup& t, int i, int64_t X, int64_t Y) {
  return int64_t{t.edge_a[i]} * X + int64_t{t.edge_b[i]} * Y + t.edge_c[i];
}

bool covers(const TriangleSetup& t, int64_t X, int64_t Y) {
  return edge_value(t, 0, X, Y) >= 0 && edge_value(t, 1, X, Y) >= 0 && edge_value(t, 2, X, Y) >= 0;
}

MipChain constant_texture(glm::vec4 color) {
  TextureLevel level{2, 2, std::vector<glm::vec4>(4, color)};
  return build_mip_chain(std::move(level));
}

Face make_face(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  Face face;
  face.vertices = {a, b, c, d};
  face.texture = constant_texture(glm::vec4(0.6f, 0.5f, 0.4f, 1.0f));
  return face;
}

// ---------------------------------------------------------------------------------------------
// Rendering and counting

struct Frame {
  FrameParams params{};
  RenderResult result;
  std::vector<TriangleSetup> setups;
  std::vector<uint32_t> winners;    // per sample: slot or SEAMCL_NO_TRIANGLE
  std::vector<uint16_t> count;      // per sample: setup slots whose edge functions cover it
  std::vector<uint32_t> last_slot;  // per sample: the last slot found covering it
  int width = 0, height = 0, samples = 0;

  size_t index(int x, int y, int s) const { return (static_cast<size_t>(y) * width + x) * samples + s; }
};

// Every slot whose edge functions cover sample s of pixel (x, y), for the failure messages.
std::string describe_sample(const Frame& f, int x, int y, int s) {
  const int64_t X = sample_x(x, f.samples, s), Y = sample_y(y, f.samples, s);
  std::ostringstream out;
  out << "pixel (" << x << ", " << y << ") sample " << s << " of " << f.samples << " at fixed (" << X << ", " << Y
      << "): count " << f.count[f.index(x, y, s)] << ", winner ";
  const uint32_t w = f.winners[f.index(x, y, s)];
  if (w == SEAMCL_NO_TRIANGLE) out << "none";
  else out << "slot " << w << " (face " << w / kSlotsPerFace << ")";
  out << "; covering slots:";
  for (size_t slot = 0; slot < f.setups.size(); ++slot) {
    const TriangleSetup& t = f.setups[slot];
    if (setup_is_empty(t) || !covers(t, X, Y)) continue;
    out << " " << slot << " (face " << t.face << ", E = " << edge_value(t, 0, X, Y) << ", " << edge_value(t, 1, X, Y)
        << ", " << edge_value(t, 2, X, Y) << ")";
  }
  return out.str();
}

void count_coverage(Frame& f) {
  f.count.assign(static_cast<size_t>(f.width) * f.height * f.samples, 0);
  f.last_slot.assign(f.count.size(), SEAMCL_NO_TRIANGLE);
  // No sample lies more than 8/16 pixel from its pixel centre: a pixel whose centre is further
  // than that outside an edge (in the edge's L1 metric) holds no covered sample.
  for (size_t slot = 0; slot < f.setups.size(); ++slot) {
    const TriangleSetup& t = f.setups[slot];
    if (setup_is_empty(t)) continue;
    int64_t margin[3];
    for (int i = 0; i < 3; ++i) margin[i] = (std::llabs(t.edge_a[i]) + std::llabs(t.edge_b[i])) * 128;
    for (int y = t.bbox_min_y; y <= t.bbox_max_y; ++y) {
      for (int x = t.bbox_min_x; x <= t.bbox_max_x; ++x) {
        const int64_t cx = int64_t{x} * 256 + 128, cy = int64_t{y} * 256 + 128;
        if (edge_value(t, 0, cx, cy) < -margin[0] || edge_value(t, 1, cx, cy) < -margin[1] ||
            edge_value(t, 2, cx, cy) < -margin[2])
          continue;
        for (int s = 0; s < f.samples; ++s) {
          if (!covers(t, sample_x(x, f.samples, s), sample_y(y, f.samples, s))) continue;
          const size_t k = f.index(x, y, s);
          ++f.count[k];
          f.last_slot[k] = static_cast<uint32_t>(slot);
        }
      }
    }
  }
}

Frame render_frame(Renderer& renderer, const Camera& camera, int width, int height, int samples) {
  RenderOptions options;
  options.width = width;
  options.height = height;
  options.msaa = samples;
  Frame f;
  f.result = renderer.render(camera, options);
  f.params = renderer.last_frame_params();
  f.setups = renderer.read_setups();
  f.winners = renderer.read_sample_triangles();
  f.width = width;
  f.height = height;
  f.samples = samples;
  count_coverage(f);
  return f;
}

// Reports at most a few offending samples per check, and the total.
struct FailureLog {
  explicit FailureLog(std::string description) : what(std::move(description)) {}
  FailureLog(const FailureLog&) = delete;
  FailureLog& operator=(const FailureLog&) = delete;
  std::string what;
  size_t failures = 0;
  std::string first;
  void add(const std::string& message) {
    if (failures++ < 4) first += "\n  " + message;
  }
  ~FailureLog() {
    if (failures > 0) ADD_FAILURE() << what << ": " << failures << " samples" << first;
  }
};

// The winners buffer agrees with the counts: a sample has a winner iff some slot covers it, the
// winner covers it, and where exactly one slot covers it that slot wins. No pixel is NaN.
void expect_winners_consistent(const Frame& f) {
  ASSERT_EQ(f.winners.size(), f.count.size());
  FailureLog log{"winner disagrees with edge-function coverage"};
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      for (int s = 0; s < f.samples; ++s) {
        const size_t k = f.index(x, y, s);
        const uint32_t w = f.winners[k];
        bool ok = (f.count[k] > 0) == (w != SEAMCL_NO_TRIANGLE);
        if (ok && w != SEAMCL_NO_TRIANGLE) {
          ok = w < f.setups.size() && covers(f.setups[w], sample_x(x, f.samples, s), sample_y(y, f.samples, s));
          if (f.count[k] == 1) ok = ok && w == f.last_slot[k];
        }
        if (!ok) log.add(describe_sample(f, x, y, s));
      }
  size_t nan_pixels = 0;
  for (const glm::vec4& p : f.result.pixels)
    nan_pixels += !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w));
  EXPECT_EQ(nan_pixels, 0u);
}

// Checks every sample's count against `expected(count)`; returns the number covered.
size_t check_counts(const Frame& f, const std::string& what, const std::function<bool(int)>& count_ok) {
  FailureLog log{what};
  size_t covered = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      for (int s = 0; s < f.samples; ++s) {
        const int c = f.count[f.index(x, y, s)];
        covered += c > 0;
        if (!count_ok(c)) log.add(describe_sample(f, x, y, s));
      }
  return covered;
}

size_t expect_exactly_once(const Frame& f) {
  return check_counts(f, "sample not covered exactly once", [](int c) { return c == 1; });
}
size_t expect_at_most_once(const Frame& f) {
  return check_counts(f, "sample covered more than once", [](int c) { return c <= 1; });
}

// ---------------------------------------------------------------------------------------------
// Ray casting against the ideal geometry

// The distance along the view axis (clip w) of the ray's hit, if any.
using RayCast = std::function<std::optional<double>(glm::dvec3 origin, glm::dvec3 direction)>;

struct CameraRays {
  glm::dvec3 eye, forward, right, up;
  double tan_half = 0, aspect = 1;
  int width = 0, height = 0;
  CameraRays(const Camera& c, int w, int h) : width(w), height(h) {
    eye = glm::dvec3(c.eye);
    forward = glm::normalize(glm::dvec3(c.target) - eye);
    right = glm::normalize(glm::cross(forward, glm::dvec3(c.up)));
    up = glm::cross(right, forward);
    tan_half = std::tan(glm::radians(static_cast<double>(c.fov_y_degrees)) / 2.0);
    aspect = static_cast<double>(w) / h;
  }
  // Screen position in pixels (y down) -> direction whose component along `forward` is 1.
  glm::dvec3 direction(double sx, double sy) const {
    const double ndc_x = 2.0 * sx / width - 1.0, ndc_y = 1.0 - 2.0 * sy / height;
    return forward + ndc_x * tan_half * aspect * right + ndc_y * tan_half * up;
  }
};

// Covered (by the ideal geometry) at screen point (sx, sy): a hit at view depth >= the near plane.
bool ideal_covered(const CameraRays& rays, const RayCast& cast, double sx, double sy) {
  const std::optional<double> t = cast(rays.eye, rays.direction(sx, sy));
  return t && *t >= static_cast<double>(kNearPlane);
}

// Per sample: 1 where the ray cast hits, 0 where it misses, -1 where it is unsure (the answer
// changes within half a pixel of the sample along x or y).
std::vector<int8_t> ray_cast_coverage(const Frame& f, const Camera& camera, const RayCast& cast) {
  const CameraRays rays(camera, f.width, f.height);
  std::vector<int8_t> out(f.count.size(), -1);
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      for (int s = 0; s < f.samples; ++s) {
        const double sx = static_cast<double>(sample_x(x, f.samples, s)) / 256.0;
        const double sy = static_cast<double>(sample_y(y, f.samples, s)) / 256.0;
        const bool here = ideal_covered(rays, cast, sx, sy);
        if (ideal_covered(rays, cast, sx - 0.5, sy) != here || ideal_covered(rays, cast, sx + 0.5, sy) != here ||
            ideal_covered(rays, cast, sx, sy - 0.5) != here || ideal_covered(rays, cast, sx, sy + 0.5) != here)
          continue;
        out[f.index(x, y, s)] = here ? 1 : 0;
      }
  return out;
}

// Compares each sample's coverage with the ray cast wherever that is sure. Returns the number
// of samples compared.
size_t expect_matches_ray_cast(const Frame& f, const Camera& camera, const RayCast& cast) {
  const std::vector<int8_t> expected = ray_cast_coverage(f, camera, cast);
  FailureLog log{"coverage differs from the ray cast"};
  size_t compared = 0;
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x)
      for (int s = 0; s < f.samples; ++s) {
        const int8_t here = expected[f.index(x, y, s)];
        if (here < 0) continue;
        ++compared;
        if ((f.count[f.index(x, y, s)] > 0) != (here == 1))
          log.add(describe_sample(f, x, y, s) + (here ? " (the ray hits the surface)" : " (the ray misses)"));
      }
  return compared;
}

std::optional<double> ray_triangle(glm::dvec3 o, glm::dvec3 d, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
  // Moller-Trumbore, either side.
  const glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (std::abs(det) < 1e-300) return std::nullopt;
  const glm::dvec3 q = o - a;
  const double u = glm::dot(q, p) / det;
  if (u < 0 || u > 1) return std::nullopt;
  const glm::dvec3 r = glm::cross(q, e1);
  const double v = glm::dot(d, r) / det;
  if (v < 0 || u + v > 1) return std::nullopt;
  const double t = glm::dot(e2, r) / det;
  if (t <= 0) return std::nullopt;
  return t;
}

// The nearest hit on any of the scene's triangles (for small meshes).
RayCast mesh_ray_cast(const Scene& scene) {
  return [&scene](glm::dvec3 o, glm::dvec3 d) -> std::optional<double> {
    std::optional<double> best;
    for (const Face& face : scene.faces) {
      const auto c = scene.corners(face);
      for (const auto& [i, j, k] : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
        const auto t = ray_triangle(o, d, glm::dvec3(c[i]), glm::dvec3(c[j]), glm::dvec3(c[k]));
        if (t && (!best || *t < *best)) best = t;
      }
    }
    return best;
  };
}

// ---------------------------------------------------------------------------------------------
// Planar scenes: a rectangle of the plane through `origin` spanned by the unit vectors u_axis
// and v_axis, described in local (u, v) coordinates.

struct PlaneFrame {
  glm::dvec3 origin{0.0}, u_axis{1, 0, 0}, v_axis{0, 1, 0};
  glm::dvec3 normal() const { return glm::cross(u_axis, v_axis); }
  glm::vec3 world(double u, double v) const { return glm::vec3(origin + u * u_axis + v * v_axis); }
};

struct Rect {
  double u0, u1, v0, v1;
};

RayCast plane_ray_cast(const PlaneFrame& frame, const Rect& rect) {
  return [frame, rect](glm::dvec3 o, glm::dvec3 d) -> std::optional<double> {
    const glm::dvec3 n = frame.normal();
    const double dn = glm::dot(d, n);
    if (dn == 0) return std::nullopt;
    const double t = glm::dot(frame.origin - o, n) / dn;
    if (t <= 0) return std::nullopt;
    const glm::dvec3 p = o + t * d - frame.origin;
    const double u = glm::dot(p, frame.u_axis), v = glm::dot(p, frame.v_axis);
    if (u < rect.u0 || u > rect.u1 || v < rect.v0 || v > rect.v1) return std::nullopt;
    return t;
  };
}

// A grid of quads over the given u and v coordinates (ascending), counter-clockwise seen from
// the side the normal points to; interior vertices moved by up to `jitter` times the smaller
// neighbouring cell along each axis at random (below 0.25 every quad stays convex), except the
// one at local (0, 0) when there is one.
Scene grid_scene(const PlaneFrame& frame, const std::vector<double>& us, const std::vector<double>& vs, double jitter,
                 uint32_t seed) {
  Scene scene;
  scene.name = "grid";
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int nu = static_cast<int>(us.size()), nv = static_cast<int>(vs.size());
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      double u = us[i], v = vs[j];
      const bool interior = i > 0 && j > 0 && i < nu - 1 && j < nv - 1;
      const double ju = unit(rng), jv = unit(rng);
      if (interior && jitter > 0 && !(u == 0 && v == 0)) {
        u += jitter * ju * std::min(us[i + 1] - us[i], us[i] - us[i - 1]);
        v += jitter * jv * std::min(vs[j + 1] - vs[j], vs[j] - vs[j - 1]);
      }
      scene.positions.push_back(frame.world(u, v));
    }
  auto vertex = [&](int i, int j) { return static_cast<uint32_t>(j * nu + i); };
  for (int j = 0; j + 1 < nv; ++j)
    for (int i = 0; i + 1 < nu; ++i)
      scene.faces.push_back(make_face(vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)));
  return scene;
}

std::vector<double> evenly(double from, double to, int cells) {
  std::vector<double> out;
  for (int i = 0; i <= cells; ++i) out.push_back(from + (to - from) * i / cells);
  return out;
}

// A camera `distance` in front of local point (0, 0), looking straight at it, rolled by `roll`
// radians about the view axis.
Camera straight_camera(const PlaneFrame& frame, double distance, double roll) {
  Camera camera;
  camera.target = frame.world(0, 0);
  camera.eye = glm::vec3(frame.origin + distance * frame.normal());
  camera.up = glm::vec3(std::cos(roll) * frame.v_axis + std::sin(roll) * frame.u_axis);
  camera.fov_y_degrees = 45.0f;
  return camera;
}

PlaneFrame rotated_frame(glm::dvec3 origin) {
  PlaneFrame frame;
  frame.origin = origin;
  frame.u_axis = glm::normalize(glm::dvec3(0.8, 0.3, -0.2));
  frame.v_axis = glm::normalize(glm::cross(glm::dvec3(0.1, 0.4, 1.0), frame.u_axis));
  return frame;
}

// Renders at every sample count and image size: every sample covered exactly once, by the winner.
void expect_screen_filled(const Scene& scene, const Camera& camera, const RayCast& cast,
                          const std::vector<std::pair<int, int>>& sizes,
                          const std::function<void(const Frame&)>& also_check = {}) {
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  for (const auto& [width, height] : sizes)
    for (const int samples : kSampleCounts) {
      SCOPED_TRACE(scene.name + " " + std::to_string(width) + "x" + std::to_string(height) + ", " +
                   std::to_string(samples) + " samples");
      const Frame f = render_frame(renderer, camera, width, height, samples);
      expect_exactly_once(f);
      expect_winners_consistent(f);
      const size_t compared = expect_matches_ray_cast(f, camera, cast);
      EXPECT_EQ(compared, f.count.size());  // the surface fills the view: no boundary in sight
      if (also_check) also_check(f);
    }
}

// Where a vertex lies exactly on a sample, every triangle around it has two edge functions equal
// to zero there (-1 where the fill rule biased the edge out). Counts those triangles at the
// sample nearest the view centre when that sample is at the exact centre, else returns -1.
int triangles_with_vertex_on_centre_sample(const Frame& f) {
  const int64_t cx = int64_t{f.width} * 128, cy = int64_t{f.height} * 128;
  for (int s = 0; s < f.samples; ++s) {
    const int x = static_cast<int>((cx - 128 - kD3D11Offsets[pattern_row(f.samples)][s][0] * 16) / 256);
    const int y = static_cast<int>((cy - 128 - kD3D11Offsets[pattern_row(f.samples)][s][1] * 16) / 256);
    if (sample_x(x, f.samples, s) != cx || sample_y(y, f.samples, s) != cy) continue;
    int triangles = 0;
    for (const TriangleSetup& t : f.setups) {
      if (setup_is_empty(t)) continue;
      int on_edge = 0;
      for (int i = 0; i < 3; ++i) on_edge += edge_value(t, i, cx, cy) == 0 || edge_value(t, i, cx, cy) == -1;
      triangles += on_edge >= 2;
    }
    return triangles;
  }
  return -1;
}

// With the view centre on a sample (1 sample at 75x53, 16 samples at 76x53), at least
// `min_triangles` triangles meet there.
std::function<void(const Frame&)> expect_vertex_on_centre_sample(int min_triangles) {
  return [min_triangles](const Frame& f) {
    const bool centre_on_sample = (f.samples == 1 && f.width % 2 == 1 && f.height % 2 == 1) ||
                                  (f.samples == 16 && f.width % 2 == 0 && f.height % 2 == 1);
    if (centre_on_sample) {
      EXPECT_GE(triangles_with_vertex_on_centre_sample(f), min_triangles);
    }
  };
}

// 75x53 puts the view centre at a pixel centre (the 1-sample position), 76x53 on the left edge
// of a pixel at mid-height (sample 12 of the 16-sample pattern, offset (-8, 0)): a vertex at the
// view centre then sits exactly on a sample.
const std::vector<std::pair<int, int>> kSizes = {{75, 53}, {76, 53}};

// ---------------------------------------------------------------------------------------------
// Closed convex meshes

Scene cube_scene() {
  Scene scene;
  scene.name = "cube";
  for (uint32_t corner = 0; corner < 8; ++corner)
    scene.positions.emplace_back((corner & 1) ? 1.0f : -1.0f, (corner & 2) ? 1.0f : -1.0f, (corner & 4) ? 1.0f : -1.0f);
  // +x, -x, +y, -y, +z, -z, counter-clockwise seen from outside.
  const uint32_t faces[6][4] = {{5, 1, 3, 7}, {0, 4, 6, 2}, {6, 7, 3, 2}, {0, 1, 5, 4}, {4, 5, 7, 6}, {1, 0, 2, 3}};
  for (const auto& f : faces) scene.faces.push_back(make_face(f[0], f[1], f[2], f[3]));
  return scene;
}

// A latitude-longitude ellipsoid: planar trapezoids between rings, and each polar ring closed by
// a fan of planar quads. Every face lies on the convex hull of the vertices, so the mesh is
// convex. Faces are oriented to face outward.
Scene ellipsoid_scene(int rings, int segments, glm::dvec3 radii, glm::dvec3 center) {
  Scene scene;
  scene.name = "ellipsoid";
  const double pi = 3.14159265358979323846;
  auto vertex = [&](int ring, int seg) { return static_cast<uint32_t>(ring * segments + (seg % segments)); };
  for (int r = 0; r < rings; ++r) {
    const double lat = -pi / 2 + pi * (r + 1) / (rings + 1);
    for (int s = 0; s < segments; ++s) {
      const double lon = 2 * pi * s / segments + 0.1;
      const glm::dvec3 unit(std::cos(lat) * std::cos(lon), std::sin(lat), std::cos(lat) * std::sin(lon));
      scene.positions.push_back(glm::vec3(center + radii * unit));
    }
  }
  std::vector<std::array<uint32_t, 4>> quads;
  for (int r = 0; r + 1 < rings; ++r)
    for (int s = 0; s < segments; ++s)
      quads.push_back({vertex(r, s), vertex(r, s + 1), vertex(r + 1, s + 1), vertex(r + 1, s)});
  for (const int r : {0, rings - 1})
    for (int s = 1; s + 2 < segments; s += 2) quads.push_back({vertex(r, 0), vertex(r, s), vertex(r, s + 1), vertex(r, s + 2)});
  const glm::vec3 c(center);
  for (auto q : quads) {
    Face face = make_face(q[0], q[1], q[2], q[3]);
    glm::vec3 mid(0.0f);
    for (uint32_t v : q) mid += scene.positions[v] * 0.25f;
    if (glm::dot(scene.face_normal(face), mid - c) < 0) face.vertices = {q[0], q[3], q[2], q[1]};
    scene.faces.push_back(std::move(face));
  }
  return scene;
}

Camera look(glm::vec3 eye, glm::vec3 target, glm::vec3 up = {0, 1, 0}, float fov = 45.0f) {
  Camera c;
  c.eye = eye;
  c.target = target;
  c.up = up;
  c.fov_y_degrees = fov;
  return c;
}

void expect_closed_convex(const Scene& scene, const std::vector<Camera>& cameras) {
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  const RayCast cast = mesh_ray_cast(scene);
  for (size_t v = 0; v < cameras.size(); ++v)
    for (const int samples : kSampleCounts) {
      SCOPED_TRACE(scene.name + " view " + std::to_string(v) + ", " + std::to_string(samples) + " samples");
      const Frame f = render_frame(renderer, cameras[v], 71, 53, samples);
      const size_t covered = expect_at_most_once(f);
      EXPECT_GT(covered, f.count.size() / 20);
      EXPECT_LT(covered, f.count.size());
      expect_winners_consistent(f);
      const size_t compared = expect_matches_ray_cast(f, cameras[v], cast);
      EXPECT_GT(compared, f.count.size() * 8 / 10);
    }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

TEST(Watertight, TessellatedPlaneCoversEverySampleOnce) {
  // 13 x 9 cells of 1 unit, jittered, over [-6, 7] x [-4, 5]: a vertex (kept unjittered) at the
  // view centre. At distance 5 the view is 4.1 units high, 5.9 wide: well inside the grid.
  const PlaneFrame frame;
  const Scene scene = grid_scene(frame, evenly(-6, 7, 13), evenly(-4, 5, 9), 0.2, 1);
  expect_screen_filled(scene, straight_camera(frame, 5.0, 0.0), plane_ray_cast(frame, {-6, 7, -4, 5}), kSizes,
                       expect_vertex_on_centre_sample(6));
}

TEST(Watertight, RotatedTessellatedPlaneCoversEverySampleOnce) {
  const PlaneFrame frame = rotated_frame(glm::dvec3(0.3, -0.2, 0.1));
  const Scene scene = grid_scene(frame, evenly(-6, 7, 13), evenly(-4, 5, 9), 0.2, 2);
  expect_screen_filled(scene, straight_camera(frame, 5.0, 0.4), plane_ray_cast(frame, {-6, 7, -4, 5}), {{75, 53}});
}

TEST(Watertight, PlaneFarFromOriginCoversEverySampleOnce) {
  // The plane and the camera 1e4 and 1e5 units from the origin: float positions there are only
  // good to 1e-3 and 1e-2 units, but shared vertices stay shared.
  for (const double offset : {1e4, 1e5}) {
    const PlaneFrame frame = rotated_frame(glm::dvec3(offset, -offset, 0.7 * offset));
    Scene scene = grid_scene(frame, evenly(-6, 7, 13), evenly(-4, 5, 9), 0.2, 3);
    scene.name = "plane at " + std::to_string(offset);
    expect_screen_filled(scene, straight_camera(frame, 5.0, 0.7), plane_ray_cast(frame, {-6, 7, -4, 5}), {{75, 53}});
  }
}

TEST(Watertight, SliverQuadsCoverEverySampleOnce) {
  // Between regular cells, 400 columns 1e-3 wide and 1000 columns 6e-4 wide, in rows 1 long:
  // 12600 quads with an aspect of 1e-3 or less (0.008 to 0.013 pixels wide, 13 long), seen
  // rolled so that their long edges are diagonal on screen.
  const PlaneFrame frame = rotated_frame(glm::dvec3(0.0));
  std::vector<double> us = evenly(-6, -1, 5);
  for (int i = 1; i <= 400; ++i) us.push_back(-1.0 + 1e-3 * i);
  for (int i = 1; i <= 1000; ++i) us.push_back(-0.6 + 0.6e-3 * i);  // 1000 more, 0.6e-3 wide
  for (const double u : evenly(0, 7, 7)) if (u > 0) us.push_back(u);
  Scene scene = grid_scene(frame, us, evenly(-4, 5, 9), 0.0, 4);
  scene.name = "slivers";
  expect_screen_filled(scene, straight_camera(frame, 5.0, 0.35), plane_ray_cast(frame, {-6, 7, -4, 5}), {{75, 53}});
}

TEST(Watertight, FanOfSliversCoversEverySampleOnce) {
  // Triangles fanning out of one vertex at the view centre (exactly on a sample, see kSizes) to
  // the boundary of a 12 x 12 square, `per_side` boundary points per side: apex angles of
  // 360 / (4 per_side) degrees, far ends 12 / per_side units wide and 6 to 8.5 long. The plane is
  // z = 0 and the eye on the z axis, so the apex projects exactly onto the view centre.
  const PlaneFrame frame;
  const double half = 6.0;
  const int per_side = 2000;
  Scene scene;
  scene.name = "fan";
  scene.positions.push_back(frame.world(0, 0));
  // Boundary points counter-clockwise, starting at corner (half, -half).
  for (int side = 0; side < 4; ++side)
    for (int i = 0; i < per_side; ++i) {
      const double t = -half + 2 * half * i / per_side;
      const glm::dvec2 p = side == 0 ? glm::dvec2(half, t) : side == 1 ? glm::dvec2(-t, half)
                         : side == 2 ? glm::dvec2(-half, -t) : glm::dvec2(t, -half);
      scene.positions.push_back(frame.world(p.x, p.y));
    }
  const uint32_t boundary = 4 * per_side;
  for (uint32_t i = 0; i < boundary; i += 2)
    scene.faces.push_back(make_face(0, 1 + i, 1 + (i + 1) % boundary, 1 + (i + 2) % boundary));
  expect_screen_filled(scene, straight_camera(frame, 5.0, 0.2), plane_ray_cast(frame, {-half, half, -half, half}),
                       kSizes, expect_vertex_on_centre_sample(4 * per_side));
}

TEST(Watertight, CubeCoversSilhouetteOnce) {
  const Scene scene = cube_scene();
  expect_closed_convex(scene, {
                                  look({2.87f, 3.2f, 4.1f}, {0, 0, 0}),             // three faces and a corner
                                  look({0.0f, 0.0f, 5.0f}, {0, 0, 0}),              // one face straight on
                                  look({1.0f, 0.3f, 4.0f}, {0.1f, 0.0f, 0}),        // +x face exactly edge-on
                                  look({-3.0f, -2.5f, 2.0f}, {0.2f, 0.1f, 0}, {0.3f, 1, 0}),  // from below, rolled
                              });
}

TEST(Watertight, EllipsoidCoversSilhouetteOnce) {
  const Scene scene = ellipsoid_scene(7, 10, {1.6, 1.0, 0.8}, {0.2, -0.1, 0.3});
  expect_closed_convex(scene, {
                                  look({3.0f, 1.5f, 4.0f}, {0, 0, 0}),
                                  look({0.0f, 4.5f, 0.5f}, {0, 0, 0}, {0, 0, -1}),  // over the pole
                                  look({-4.0f, -1.0f, -2.0f}, {0.3f, 0, 0}, {0.2f, 1, 0}),
                              });
}

namespace {

// Grid lines at 0, +-spacing, +-2 spacing ... out to `uniform_extent`, then cells growing by
// `growth` each out to at least `extent`.
std::vector<double> graded(double spacing, double uniform_extent, double growth, double extent) {
  std::vector<double> positive;
  double step = spacing, at = spacing;
  for (; at <= uniform_extent; at += step) positive.push_back(at);
  for (; at - step < extent; step *= growth, at += step) positive.push_back(at);
  std::vector<double> out(positive.rbegin(), positive.rend());
  for (double& v : out) v = -v;
  out.push_back(0.0);
  out.insert(out.end(), positive.begin(), positive.end());
  return out;
}

// A camera `height` above local point `foot` of the plane, looking along `along` (in the
// plane) pitched down by `pitch` radians towards the plane and rolled by `roll`.
Camera camera_over_plane(const PlaneFrame& frame, glm::dvec2 foot, double height, double pitch, double roll) {
  const glm::dvec3 n = frame.normal();
  const glm::dvec3 along = glm::normalize(0.8 * frame.u_axis + 0.6 * frame.v_axis);
  const glm::dvec3 eye = glm::dvec3(frame.world(foot.x, foot.y)) + height * n;
  const glm::dvec3 forward = std::cos(pitch) * along - std::sin(pitch) * n;
  const glm::dvec3 up0 = std::sin(pitch) * along + std::cos(pitch) * n;
  const glm::dvec3 side = glm::cross(forward, up0);
  Camera camera;
  camera.eye = glm::vec3(eye);
  camera.target = glm::vec3(eye + 2.0 * forward);
  camera.up = glm::vec3(std::cos(roll) * up0 + std::sin(roll) * side);
  camera.fov_y_degrees = 45.0f;
  return camera;
}

size_t nonempty_extra_slots(const Frame& f) {
  size_t extra = 0;
  for (size_t slot = 0; slot < f.setups.size(); ++slot)
    extra += slot % SEAMCL_CLIP_SLOTS != 0 && !setup_is_empty(f.setups[slot]);
  return extra;
}

// ---------------------------------------------------------------------------------------------
// Snapped folds. Snapping vertices to 1/256 pixel can turn a front-facing sliver thinner than
// the snapping error into a back-facing one; it is culled, and the two neighbours that now
// overlap where it was cover those samples twice (the snapped mesh folds over). No rasteriser
// that snaps and culls can avoid it, so the grazing-angle test allows exactly that much.

struct ScreenTriangle {
  int64_t X[3], Y[3];
};

// Triangles that face the camera in exact arithmetic but not once snapped as the setup kernel
// snaps them (same float operations), among the input triangles no clip plane touches; also
// those whose snapped area is within a rounding disagreement of zero. `flipped` counts the first
// kind.
std::vector<ScreenTriangle> snapped_folds(const Scene& scene, const FrameParams& p, const Camera& camera,
                                          size_t* flipped = nullptr) {
  const float* m = p.view_proj;
  const glm::dmat4 exact = glm::dmat4(view_projection(camera, p.width, p.height));
  std::vector<ScreenTriangle> folds;
  for (const Face& face : scene.faces) {
    for (const auto& corner : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
      ScreenTriangle t{};
      double ex[3], ey[3];
      bool unclipped = true;
      for (int i = 0; i < 3; ++i) {
        const glm::vec3 v = scene.positions[face.vertices[corner[i]]];
        const float x = m[0] * v.x + m[4] * v.y + m[8] * v.z + m[12];
        const float y = m[1] * v.x + m[5] * v.y + m[9] * v.z + m[13];
        const float w = m[3] * v.x + m[7] * v.y + m[11] * v.z + m[15];
        unclipped = unclipped && w - p.near_w >= 0 && p.guard_x * w - x >= 0 && p.guard_x * w + x >= 0 &&
                    p.guard_y * w - y >= 0 && p.guard_y * w + y >= 0;
        const float inv_w = 1.0f / w;
        t.X[i] = std::llrint((x * inv_w * 0.5f + 0.5f) * static_cast<float>(p.width) * 256.0f);
        t.Y[i] = std::llrint((0.5f - y * inv_w * 0.5f) * static_cast<float>(p.height) * 256.0f);
        const glm::dvec4 c = exact * glm::dvec4(glm::dvec3(v), 1.0);
        ex[i] = (c.x / c.w * 0.5 + 0.5) * p.width * 256.0;
        ey[i] = (0.5 - c.y / c.w * 0.5) * p.height * 256.0;
      }
      if (!unclipped) continue;
      const double exact_area = (ex[1] - ex[0]) * (ey[2] - ey[0]) - (ey[1] - ey[0]) * (ex[2] - ex[0]);
      const int64_t area = (t.X[1] - t.X[0]) * (t.Y[2] - t.Y[0]) - (t.Y[1] - t.Y[0]) * (t.X[2] - t.X[0]);
      int64_t longest = 0;
      for (int i = 0; i < 3; ++i)
        longest = std::max<int64_t>(longest, std::llabs(t.X[(i + 1) % 3] - t.X[i]) + std::llabs(t.Y[(i + 1) % 3] - t.Y[i]));
      // Front-facing is a negative area on screen (y down). Folded: snapped area positive (the
      // kernel culls it); the near-zero ones are kept too in case an ulp decides differently.
      if (exact_area < 0 && area >= -4 * longest) folds.push_back(t);
      if (exact_area < 0 && area > 0 && flipped) ++*flipped;
    }
  }
  return folds;
}

// How many of `folds` contain each sample (boundaries included).
std::vector<uint16_t> fold_counts(const Frame& f, const std::vector<ScreenTriangle>& folds) {
  std::vector<uint16_t> out(f.count.size(), 0);
  for (const ScreenTriangle& t : folds) {
    auto orient = [&](int i, int64_t X, int64_t Y) {
      const int j = (i + 1) % 3;
      return (t.X[j] - t.X[i]) * (Y - t.Y[i]) - (t.Y[j] - t.Y[i]) * (X - t.X[i]);
    };
    const int64_t x0 = std::max<int64_t>(0, (std::min({t.X[0], t.X[1], t.X[2]}) - 256) / 256);
    const int64_t x1 = std::min<int64_t>(f.width - 1, std::max({t.X[0], t.X[1], t.X[2]}) / 256 + 1);
    const int64_t y0 = std::max<int64_t>(0, (std::min({t.Y[0], t.Y[1], t.Y[2]}) - 256) / 256);
    const int64_t y1 = std::min<int64_t>(f.height - 1, std::max({t.Y[0], t.Y[1], t.Y[2]}) / 256 + 1);
    for (int64_t y = y0; y <= y1; ++y)
      for (int64_t x = x0; x <= x1; ++x)
        for (int s = 0; s < f.samples; ++s) {
          const int64_t X = sample_x(static_cast<int>(x), f.samples, s), Y = sample_y(static_cast<int>(y), f.samples, s);
          const int64_t o0 = orient(0, X, Y), o1 = orient(1, X, Y), o2 = orient(2, X, Y);
          if ((o0 >= 0 && o1 >= 0 && o2 >= 0) || (o0 <= 0 && o1 <= 0 && o2 <= 0))
            ++out[f.index(static_cast<int>(x), static_cast<int>(y), s)];
        }
  }
  return out;
}

}  // namespace

TEST(Watertight, MeshCrossingNearPlaneCoversOnceWithoutNaN) {
  // A jittered grid in a tilted plane; the camera 0.005 above it, inside its extent, pitched
  // down 35 degrees and rolled: the plane crosses the near plane (w = 0.01) inside the view and
  // extends behind the camera; the horizon is above the view. Covered: the part of the view
  // beyond the near-plane cut. Two grids: cells of 4 units (the view sees a corner of one or two
  // cells, clipped into fans), and cells 7e-4 wide around the camera growing 1.4 times per cell
  // beyond 0.02 units, so that many edges cross the near-plane cut inside the view (there the
  // clipped triangles' new vertices must agree).
  const PlaneFrame frame = rotated_frame(glm::dvec3(0.5, 0.2, -0.3));
  struct Grid {
    std::vector<double> us, vs;
    size_t min_extra_slots;
  };
  const std::vector<double> fine = graded(7e-4, 0.02, 1.4, 3.0);
  for (const Grid& grid : {Grid{evenly(-26, 26, 13), evenly(-18, 18, 9), 1}, Grid{fine, fine, 20}}) {
    Scene scene = grid_scene(frame, grid.us, grid.vs, 0.2, 5);
    scene.name = std::to_string(grid.us.size() - 1) + " x " + std::to_string(grid.vs.size() - 1) + " grid";
    const Camera camera = camera_over_plane(frame, {3.1e-4, -1.7e-4}, 0.005, glm::radians(35.0), 0.3);
    Renderer renderer(seamcl_tests::shared_runtime());
    renderer.load_scene(scene);
    const RayCast cast = plane_ray_cast(frame, {grid.us.front(), grid.us.back(), grid.vs.front(), grid.vs.back()});
    for (const int samples : kSampleCounts) {
      SCOPED_TRACE(scene.name + ", " + std::to_string(samples) + " samples");
      const Frame f = render_frame(renderer, camera, 75, 53, samples);
      const size_t covered = expect_at_most_once(f);
      EXPECT_GT(covered, f.count.size() / 5);
      EXPECT_LT(covered, f.count.size() * 4 / 5);
      expect_winners_consistent(f);
      const size_t compared = expect_matches_ray_cast(f, camera, cast);
      EXPECT_GT(compared, f.count.size() * 8 / 10);
      // Triangles really were clipped into more than one slot.
      EXPECT_GE(nonempty_extra_slots(f), grid.min_extra_slots);
    }
  }
}

TEST(Watertight, GrazingPlaneDoubleCoverageOnlyFromSnappedFolds) {
  // The graded grid out to 26 units, seen from 0.003 above it pitched down only 20 degrees: the
  // horizon is in view, with the grid's far cells squeezed into slivers a few thousandths of a
  // pixel high, some of which fold over once snapped. Every sample the plane covers is covered
  // (no crack), and a sample is covered twice only inside such a fold.
  const PlaneFrame frame = rotated_frame(glm::dvec3(0.5, 0.2, -0.3));
  const std::vector<double> fine = graded(2e-4, 0.0, 1.3, 26.0);
  // (Jitter seed 10 shows two doubly covered samples at 16 samples per pixel.)
  const Scene scene = grid_scene(frame, fine, fine, 0.2, 10);
  const Camera camera = camera_over_plane(frame, {3e-5, -7e-5}, 0.003, glm::radians(20.0), 0.3);
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  const RayCast cast = plane_ray_cast(frame, {fine.front(), fine.back(), fine.front(), fine.back()});
  size_t flipped = 0;
  for (const int samples : kSampleCounts) {
    SCOPED_TRACE(std::to_string(samples) + " samples");
    const Frame f = render_frame(renderer, camera, 75, 53, samples);
    expect_winners_consistent(f);
    EXPECT_GE(nonempty_extra_slots(f), 1u);  // the near plane cuts the grid too
    const std::vector<ScreenTriangle> folds = snapped_folds(scene, f.params, camera, &flipped);
    const std::vector<uint16_t> in_folds = fold_counts(f, folds);
    const std::vector<int8_t> expected = ray_cast_coverage(f, camera, cast);
    FailureLog cracks{"crack: sample the plane covers is not covered"};
    FailureLog doubles{"sample covered more than once outside any snapped fold"};
    size_t covered = 0, double_covered = 0;
    for (int y = 0; y < f.height; ++y)
      for (int x = 0; x < f.width; ++x)
        for (int s = 0; s < f.samples; ++s) {
          const size_t k = f.index(x, y, s);
          covered += f.count[k] > 0;
          double_covered += f.count[k] > 1;
          if (expected[k] == 1 && f.count[k] == 0) cracks.add(describe_sample(f, x, y, s));
          const int allowed = (expected[k] == 0 ? 0 : 1) + in_folds[k];
          if (f.count[k] > allowed) doubles.add(describe_sample(f, x, y, s) + ", in " + std::to_string(in_folds[k]) + " folds");
        }
    EXPECT_GT(covered, f.count.size() / 5);
    EXPECT_LT(covered, f.count.size() * 4 / 5);
    RecordProperty("double_covered_samples_" + std::to_string(samples), static_cast<int>(double_covered));
  }
  EXPECT_GT(flipped, 0u);  // the case this test is about does occur
}

TEST(Watertight, NearerQuadWinsWhereItCovers) {
  // Two parallel quads; the nearer one (z = 0.5) is listed second, so slot order alone would
  // pick the farther one. Each sample's winner must be the nearer of the faces covering it.
  for (const bool near_first : {false, true}) {
    Scene scene;
    scene.name = near_first ? "near first" : "far first";
    const std::vector<glm::vec3> far_quad = {{-2, -2, 0}, {2, -2, 0}, {2, 2, 0}, {-2, 2, 0}};
    const std::vector<glm::vec3> near_quad = {{-1, -0.5f, 0.5f}, {2.5f, -0.5f, 0.5f}, {2.5f, 1.2f, 0.5f}, {-1, 1.2f, 0.5f}};
    for (const auto* quad : near_first ? std::vector{&near_quad, &far_quad} : std::vector{&far_quad, &near_quad})
      for (const glm::vec3& p : *quad) scene.positions.push_back(p);
    scene.faces.push_back(make_face(0, 1, 2, 3));
    scene.faces.push_back(make_face(4, 5, 6, 7));
    const uint32_t near_face = near_first ? 0 : 1, far_face = 1 - near_face;
    Renderer renderer(seamcl_tests::shared_runtime());
    renderer.load_scene(scene);
    const Camera camera = look({0.4f, 0.3f, 5.0f}, {0.2f, 0.1f, 0.0f});
    for (const int samples : kSampleCounts) {
      SCOPED_TRACE(scene.name + ", " + std::to_string(samples) + " samples");
      const Frame f = render_frame(renderer, camera, 64, 48, samples);
      expect_winners_consistent(f);
      FailureLog log{"winner is not the nearest covering face"};
      size_t near_wins = 0, far_wins = 0;
      for (int y = 0; y < f.height; ++y)
        for (int x = 0; x < f.width; ++x)
          for (int s = 0; s < f.samples; ++s) {
            bool near_covers = false, far_covers = false;
            for (size_t slot = 0; slot < f.setups.size(); ++slot) {
              const TriangleSetup& t = f.setups[slot];
              if (setup_is_empty(t) || !covers(t, sample_x(x, samples, s), sample_y(y, samples, s))) continue;
              (t.face == near_face ? near_covers : far_covers) = true;
            }
            const uint32_t w = f.winners[f.index(x, y, s)];
            const uint32_t expected = near_covers ? near_face : far_covers ? far_face : SEAMCL_NO_TRIANGLE;
            const uint32_t got = w == SEAMCL_NO_TRIANGLE ? w : w / kSlotsPerFace;
            near_wins += got == near_face;
            far_wins += got == far_face;
            if (got != expected) log.add(describe_sample(f, x, y, s));
          }
      EXPECT_GT(near_wins, f.count.size() / 10);
      EXPECT_GT(far_wins, f.count.size() / 10);
    }
  }
}
