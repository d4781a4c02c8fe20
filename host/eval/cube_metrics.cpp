#include <seamcl/eval/cube_metrics.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <seamcl/core/elapsed.h>
#include <seamcl/pipeline/cube_lookups.h>
#include <seamcl/pipeline/packed_cube.h>
#include <seamcl/scene/cube_map.h>

namespace seamcl {
namespace {

// An edge: components a and b at sign_a, sign_b, the third (c) running along it.
struct Edge {
  int a, b, c;
  float sign_a, sign_b;
};

std::vector<Edge> cube_edges() {
  std::vector<Edge> out;
  for (int a = 0; a < 3; ++a)
    for (int b = a + 1; b < 3; ++b)
      for (float sa : {-1.0f, 1.0f})
        for (float sb : {-1.0f, 1.0f}) out.push_back({a, b, 3 - a - b, sa, sb});
  return out;
}

// The point `inside` face-coordinate units into face A (major a) or B (major b) from the edge
// point at `along`.
glm::vec3 edge_point(const Edge& e, float along, bool face_a, float inside) {
  glm::vec3 d(0.0f);
  d[e.a] = e.sign_a;
  d[e.b] = e.sign_b;
  d[e.c] = along;
  if (face_a) {
    d[e.b] *= 1.0f - inside;
  } else {
    d[e.a] *= 1.0f - inside;
  }
  return d;
}

// Samples of one cube-edge pixel lie within 0.25 radians of each other.
constexpr float kContinuousCos = 0.9689124f;  // cos(0.25)

double rgb_norm(glm::vec4 v) { return glm::length(glm::dvec3(v.r, v.g, v.b)); }

// Directions over a disk of half-angle `angle` around unit d (Vogel's spiral, 16 points).
std::vector<glm::vec3> disk_directions(glm::vec3 d, float angle) {
  const glm::vec3 helper = std::fabs(d.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  const glm::vec3 t = glm::normalize(glm::cross(d, helper));
  const glm::vec3 b = glm::cross(d, t);
  const float radius = std::tan(angle);
  constexpr int kPoints = 16;
  std::vector<glm::vec3> out;
  for (int k = 0; k < kPoints; ++k) {
    const float r = radius * std::sqrt((static_cast<float>(k) + 0.5f) / kPoints);
    const float phi = 2.39996323f * static_cast<float>(k);
    out.push_back(glm::normalize(d + t * (r * std::cos(phi)) + b * (r * std::sin(phi))));
  }
  return out;
}

}  // namespace

EdgeMeasures measure_cube_edges(ClRuntime& runtime, const Environment& environment, CubeMethod method, int size,
                                int points) {
  const DirectionFunction radiance = environment_function(environment);
  const auto bake_start = std::chrono::steady_clock::now();
  const CubeMap cube = bake_cube_for(method, radiance, size, environment.bake_samples);
  const bool border = cube_preparation(method).border;
  const size_t packed_floats = pack_cube_texels(cube, border).size();
  const double bake_ms = ms_since(bake_start);
  CubeLookups lookups(runtime, cube, border);
  const CubeSampler sampler = cube_sampler(method, Filter::Trilinear, 16, size);
  EdgeMeasures out;
  out.size = size;
  out.bake_ms = bake_ms;
  out.cube_bytes = packed_floats * sizeof(float);
  const std::vector<Edge> edges = cube_edges();
  auto along = [&](int k) { return -1.0f + (2.0f * static_cast<float>(k) + 1.0f) / static_cast<float>(points); };

  // Zero order, per lod: both sides 1e-4 face widths from the edge; at every integer lod, then
  // half-way between each two (where trilinear mixes two levels and one coordinate scale cannot
  // suit both).
  for (int step = 0; step < 2 * cube.level_count() - 1; ++step) {
    const float lod = step < cube.level_count() ? static_cast<float>(step) : static_cast<float>(step - cube.level_count()) + 0.5f;
    std::vector<CubeLookup> batch;
    for (const Edge& e : edges) {
      for (int k = 0; k < points; ++k) {
        for (bool face_a : {true, false}) {
          batch.push_back({edge_point(e, along(k), face_a, 2e-4f), glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, lod});
        }
      }
    }
    const std::vector<glm::vec4> values = lookups.sample(batch, sampler);
    double sum = 0, worst = 0;
    for (size_t i = 0; i < values.size(); i += 2) {
      const double jump = rgb_norm(values[i] - values[i + 1]);
      sum += jump;
      worst = std::max(worst, jump);
    }
    if (step < cube.level_count()) {
      out.seam_step_mean.push_back(sum / static_cast<double>(values.size() / 2));
      out.seam_step_max.push_back(worst);
    } else {
      out.seam_step_half_lod.push_back(sum / static_cast<double>(values.size() / 2));
    }
  }

  // First order at lod 0: points 0.25 and 0.75 level-0 texels (2/n face units each) inside.
  const float texel = 2.0f / static_cast<float>(size);
  const float offsets[2] = {0.25f * texel, 0.75f * texel};
  std::vector<CubeLookup> batch;
  std::vector<glm::vec3> directions;
  for (const Edge& e : edges) {
    for (int k = 0; k < points; ++k) {
      for (bool face_a : {true, false}) {
        for (float inside : offsets) {
          directions.push_back(edge_point(e, along(k), face_a, inside));
          batch.push_back({directions.back(), glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, 0.0f});
        }
      }
    }
  }
  const std::vector<glm::vec4> values = lookups.sample(batch, sampler);
  double jump_sum = 0, environment_sum = 0;
  auto jump = [](glm::vec4 a_near, glm::vec4 a_far, glm::vec4 b_near, glm::vec4 b_far) {
    // Slopes per texel along A -> B: (near - far) / 0.5 on A, (far - near) / 0.5 on B.
    return ((b_far - b_near) - (a_near - a_far)) * 2.0f;
  };
  for (size_t i = 0; i < values.size(); i += 4) {
    glm::vec4 env[4];
    for (int k = 0; k < 4; ++k) env[k] = radiance(glm::normalize(directions[i + k]));
    const glm::vec4 method_jump = jump(values[i], values[i + 1], values[i + 2], values[i + 3]);
    const glm::vec4 environment_jump = jump(env[0], env[1], env[2], env[3]);
    jump_sum += rgb_norm(method_jump - environment_jump);
    environment_sum += rgb_norm(environment_jump);
  }
  const double count = static_cast<double>(values.size() / 4);
  out.first_order_jump = jump_sum / count;
  out.environment_first_order_jump = environment_sum / count;

  // The band: kBandSteps lookups per level-0 texel on a path straight across the edge, one texel
  // deep into each face; the slope of each step within a face (none straddles the edge, whose
  // step is zero order) against the environment's own slope there.
  constexpr int kBandSteps = 8;
  std::vector<CubeLookup> band;
  std::vector<glm::vec3> band_directions;
  for (const Edge& e : edges) {
    for (int k = 0; k < points; ++k) {
      for (bool face_a : {true, false}) {
        for (int s = 0; s < kBandSteps; ++s) {
          const float inside = (static_cast<float>(s) + 0.5f) / kBandSteps * texel;
          band_directions.push_back(edge_point(e, along(k), face_a, inside));
          band.push_back({band_directions.back(), glm::vec3(0.0f), glm::vec3(0.0f), 0.0f, 0.0f});
        }
      }
    }
  }
  const std::vector<glm::vec4> band_values = lookups.sample(band, sampler);
  double deviation_sum = 0, slope_sum = 0;
  size_t steps = 0;
  for (size_t run = 0; run < band_values.size(); run += kBandSteps) {
    for (int s = 0; s + 1 < kBandSteps; ++s) {
      // Per level-0 texel: a step is 1 / kBandSteps of one.
      const glm::vec4 slope = (band_values[run + s + 1] - band_values[run + s]) * static_cast<float>(kBandSteps);
      const glm::vec4 truth = (radiance(glm::normalize(band_directions[run + s + 1])) -
                               radiance(glm::normalize(band_directions[run + s]))) *
                              static_cast<float>(kBandSteps);
      deviation_sum += rgb_norm(slope - truth);
      slope_sum += rgb_norm(truth);
      ++steps;
    }
  }
  out.first_order_band = deviation_sum / static_cast<double>(steps);
  out.environment_band_slope = slope_sum / static_cast<double>(steps);
  return out;
}

CubeReference cube_reference(Renderer& renderer, const Camera& camera, const RenderOptions& options, int scale) {
  const Scene& scene = renderer.scene();
  if (!scene.environment) throw std::invalid_argument("cube_reference needs a scene with an environment");
  RenderOptions big = options;
  big.width = options.width * scale;
  big.height = options.height * scale;
  big.msaa = 1;
  big.shading = ShadingMode::Pixel;
  const RenderResult directions = renderer.render_directions(camera, big);
  const DirectionFunction radiance = environment_function(*scene.environment);

  CubeReference out;
  out.width = options.width;
  out.height = options.height;
  out.pixels.assign(static_cast<size_t>(out.width) * out.height, glm::vec4(0.0f));
  out.cube_edge.assign(out.pixels.size(), 0);
  const glm::vec4 background(scene.background, 1.0f);
  const float inv = 1.0f / static_cast<float>(scale * scale);
  for (int y = 0; y < out.height; ++y) {
    for (int x = 0; x < out.width; ++x) {
      glm::vec4 sum(0.0f);
      int first_face = -1;
      bool crosses = false;
      // A pixel whose samples' directions spread wide (a silhouette: reflection against sky, or
      // a grazing fold) or that shows background is not a cube-edge pixel, whatever faces its
      // samples select: its error is the silhouette's.
      bool continuous = true;
      glm::vec3 first_direction(0.0f);
      for (int sy = 0; sy < scale; ++sy) {
        for (int sx = 0; sx < scale; ++sx) {
          const glm::vec4 p = directions.pixels[static_cast<size_t>(y * scale + sy) * big.width + (x * scale + sx)];
          const glm::vec3 d(p);
          const float length = glm::length(d);
          if (!(length > 0.5f)) {  // not an environment lookup: the background (skybox off)
            sum += background;
            continuous = false;
            continue;
          }
          const glm::vec3 unit = d / length;
          if (first_face < 0) first_direction = unit;
          continuous = continuous && glm::dot(unit, first_direction) > kContinuousCos;
          const float roughness = length - 1.0f;
          if (roughness > 1e-4f) {
            glm::vec4 disk(0.0f);
            const std::vector<glm::vec3> spread = disk_directions(unit, 0.5f * roughness);
            for (const glm::vec3& s : spread) disk += radiance(s);
            sum += disk / static_cast<float>(spread.size());
          } else {
            sum += radiance(unit);
          }
          const int face = cube_coords(unit).face;
          crosses = crosses || (first_face >= 0 && face != first_face);
          if (first_face < 0) first_face = face;
        }
      }
      const size_t i = static_cast<size_t>(y) * out.width + x;
      out.pixels[i] = glm::vec4(glm::vec3(sum * inv), 1.0f);
      const bool edge = crosses && continuous;
      out.cube_edge[i] = edge ? 1 : 0;
      out.edge_pixels += edge ? 1 : 0;
    }
  }
  return out;
}

std::vector<glm::vec3> lookup_directions(Renderer& renderer, const Camera& camera, const RenderOptions& options) {
  const Scene& scene = renderer.scene();
  if (!scene.environment) throw std::invalid_argument("lookup_directions needs a scene with an environment");
  RenderOptions one = options;
  one.msaa = 1;
  one.shading = ShadingMode::Pixel;
  const RenderResult frame = renderer.render_directions(camera, one);
  // A diffuse face writes its colour, an empty pixel without a skybox the background: the
  // winners say which pixels looked the environment up.
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  std::vector<glm::vec3> out(frame.pixels.size(), glm::vec3(0.0f));
  for (size_t p = 0; p < out.size(); ++p) {
    const uint32_t slot = winners.at(p);
    const bool looks_up = slot == SEAMCL_NO_TRIANGLE ? scene.environment->skybox
                                                     : scene.faces.at(static_cast<size_t>(setups.at(slot).face)).roughness >= 0.0f;
    const glm::vec3 d(frame.pixels[p]);
    const float length = glm::length(d);
    if (looks_up && length > 0.0f) out[p] = d / length;
  }
  return out;
}

std::vector<uint8_t> cube_edge_pixels(const std::vector<glm::vec3>& directions, int width, int height) {
  const size_t pixels = static_cast<size_t>(width) * height;
  if (directions.size() != pixels) throw std::invalid_argument("cube_edge_pixels: not width x height directions");
  std::vector<int> face(pixels, -1);
  for (size_t p = 0; p < pixels; ++p) {
    if (glm::dot(directions[p], directions[p]) > 0.0f) face[p] = cube_coords(directions[p]).face;
  }
  auto crosses = [&](size_t a, size_t b) {
    return face[a] >= 0 && face[b] >= 0 && face[a] != face[b] &&
           glm::dot(glm::normalize(directions[a]), glm::normalize(directions[b])) > kContinuousCos;
  };
  std::vector<uint8_t> out(pixels, 0);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t p = static_cast<size_t>(y) * width + x;
      if ((x + 1 < width && crosses(p, p + 1)) || (y + 1 < height && crosses(p, p + width))) out[p] = 1;
    }
  }
  return out;
}

}  // namespace seamcl
