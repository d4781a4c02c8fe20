#include <seamcl/eval/displacement_metrics.h>

#include <algorithm>
#include <cmath>
#include <map>

#include <seamcl/core/input_error.h>
#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/pipeline/renderer.h>
#include "pipeline/displacement_packing.h"
#include "pipeline/stages/sample_pattern.h"
#include "pipeline/stages/triangle_setup_twin.h"
#include "pipeline/stages/tessellate_launcher.h"
#include "pipeline/tessellation_factors.h"
#include "scene/displacement_map.h"

namespace seamcl {
namespace {

// Index of vertex (i, j) of `patch` in the tessellator's output.
size_t vertex_index(int patch, int i, int j, int t) {
  return (static_cast<size_t>(patch) * (t + 1) + static_cast<size_t>(j)) * (t + 1) + static_cast<size_t>(i);
}

// Grid position of step k (0..T) along edge e from corner e.
void edge_grid(int e, int k, int t, int* i, int* j) {
  switch (e) {
    case 0: *i = k; *j = 0; break;
    case 1: *i = t; *j = k; break;
    case 2: *i = t - k; *j = t; break;
    default: *i = 0; *j = t - k; break;
  }
}

// Adds the pair to the totals and returns its largest coordinate difference.
double compare(const TessVertex& a, const TessVertex& b, DisplacementGap& gap) {
  ++gap.compared_pairs;
  bool differ = false;
  double largest = 0.0;
  for (int c = 0; c < 3; ++c) {
    largest = std::max(largest, std::fabs(static_cast<double>(a.position[c]) - static_cast<double>(b.position[c])));
    differ = differ || a.position[c] != b.position[c];
  }
  gap.max_gap = std::max(gap.max_gap, largest);
  gap.differing_pairs += differ;
  return largest;
}

// A copy of one surface point: grid point (i, j) of a patch.
struct GridPoint {
  int patch, i, j;
  bool operator<(const GridPoint& o) const {
    return patch != o.patch ? patch < o.patch : (j != o.j ? j < o.j : i < o.i);
  }
};

// Every copy of grid point (i, j) of patch p, itself included, sorted: inside the patch only
// itself; on a shared edge the neighbour's point at the same step; at a corner the corner of
// every patch at that mesh vertex.
std::vector<GridPoint> copies_of(const PackedDisplacement& packed, int p, int i, int j) {
  const int t = packed.params.tessellation;
  std::vector<GridPoint> out{{p, i, j}};
  const DisplacementPatch& patch = packed.patches[static_cast<size_t>(p)];
  const bool corner = (i == 0 || i == t) && (j == 0 || j == t);
  if (corner) {
    const int c = j == 0 ? (i == 0 ? 0 : 1) : (i == t ? 2 : 3);
    const uint32_t vertex = patch.vertex[c];
    out.clear();
    for (int q = 0; q < static_cast<int>(packed.patches.size()); ++q) {
      for (int qc = 0; qc < 4; ++qc) {
        if (packed.patches[static_cast<size_t>(q)].vertex[qc] != vertex) continue;
        out.push_back({q, (qc == 1 || qc == 2) ? t : 0, qc >= 2 ? t : 0});
      }
    }
  } else {
    for (int e = 0; e < 4; ++e) {
      int k = -1;
      if (e == 0 && j == 0) k = i;
      if (e == 1 && i == t) k = j;
      if (e == 2 && j == t) k = t - i;
      if (e == 3 && i == 0) k = t - j;
      if (k < 0 || patch.neighbor[e] < 0) continue;
      int qi = 0, qj = 0;
      edge_grid(patch.neighbor_edge[e], patch.neighbor_same_way[e] ? k : t - k, t, &qi, &qj);
      out.push_back({patch.neighbor[e], qi, qj});
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Adaptive tessellation splits cells (T-1, 0) and (0, T-1) on their other diagonal
// (kernels/tessellate.cl, tessellated_setup).
bool cell_is_flipped(const PackedDisplacement& packed, int ci, int cj) {
  const int t = packed.params.tessellation;
  return packed.adaptive() && t >= 2 && ((ci == t - 1 && cj == 0) || (ci == 0 && cj == t - 1));
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace

DisplacementGap measure_gap(const PackedDisplacement& packed, const std::vector<TessVertex>& vertices,
                            const std::vector<cl_float4>* normals) {
  DisplacementGap gap;
  const int t = packed.params.tessellation;
  if (vertices.size() != packed.vertex_count()) throw std::invalid_argument("measure_gap: vertex count does not match");
  if (normals && normals->size() != vertices.size()) throw std::invalid_argument("measure_gap: normal count does not match");
  auto normal_at = [&](const GridPoint& g) -> std::array<float, 3> {
    if (!normals) return displaced_normal(packed, vertices, g.patch, g.i, g.j);
    const cl_float4& n = (*normals)[vertex_index(g.patch, g.i, g.j, t)];
    return {n.s[0], n.s[1], n.s[2]};
  };
  // Shared edges, each once (from the lower-numbered patch), all T+1 points including corners.
  for (int p = 0; p < static_cast<int>(packed.patches.size()); ++p) {
    const DisplacementPatch& patch = packed.patches[static_cast<size_t>(p)];
    for (int e = 0; e < 4; ++e) {
      const int q = patch.neighbor[e];
      if (q < 0 || q < p) continue;
      const int qe = patch.neighbor_edge[e];
      for (int k = 0; k <= t; ++k) {
        int i = 0, j = 0, qi = 0, qj = 0;
        edge_grid(e, k, t, &i, &j);
        edge_grid(qe, patch.neighbor_same_way[e] ? k : t - k, t, &qi, &qj);
        const double d = compare(vertices[vertex_index(p, i, j, t)], vertices[vertex_index(q, qi, qj, t)], gap);
        if (k > 0 && k < t) gap.max_edge_gap = std::max(gap.max_edge_gap, d);
      }
    }
  }
  // Every patch corner at a mesh vertex against the first patch's there (diagonal patches too).
  std::map<uint32_t, size_t> first_at_vertex;
  for (int p = 0; p < static_cast<int>(packed.patches.size()); ++p) {
    for (int c = 0; c < 4; ++c) {
      const int i = (c == 1 || c == 2) ? t : 0, j = (c >= 2) ? t : 0;
      const size_t index = vertex_index(p, i, j, t);
      const auto [it, inserted] = first_at_vertex.emplace(packed.patches[static_cast<size_t>(p)].vertex[c], index);
      if (!inserted) gap.max_corner_gap = std::max(gap.max_corner_gap, compare(vertices[it->second], vertices[index], gap));
    }
  }
  // Normals at every boundary point with more than one copy, once per point (from its
  // lowest-numbered copy).
  for (int p = 0; p < static_cast<int>(packed.patches.size()); ++p) {
    for (int j = 0; j <= t; ++j) {
      for (int i = 0; i <= t; i += (j == 0 || j == t) ? 1 : t) {
        const std::vector<GridPoint> copies = copies_of(packed, p, i, j);
        if (copies.size() < 2 || copies.front().patch != p || copies.front().i != i || copies.front().j != j) continue;
        const std::array<float, 3> first = normal_at({p, i, j});
        bool differ = false;
        for (size_t c = 1; c < copies.size(); ++c) {
          const std::array<float, 3> other = normal_at(copies[c]);
          for (int k = 0; k < 3; ++k) {
            gap.max_normal_gap =
                std::max(gap.max_normal_gap, std::fabs(static_cast<double>(first[k]) - static_cast<double>(other[k])));
            differ = differ || first[k] != other[k];
          }
        }
        gap.differing_normals += differ;
      }
    }
  }
  return gap;
}

std::array<float, 3> displaced_normal(const PackedDisplacement& packed, const std::vector<TessVertex>& vertices,
                                      int patch, int i, int j) {
  const int t = packed.params.tessellation;
  const TessVertex& own = vertices[vertex_index(patch, i, j, t)];
  float nx = 0.0f, ny = 0.0f, nz = 0.0f;
  for (const GridPoint& copy : copies_of(packed, patch, i, j)) {
    // Each cell of the copy's patch around the point, both triangles as the tessellator splits
    // them, (00, 10, 11) and (00, 11, 01), in one order (adaptive: the two flipped corner cells
    // (00, 10, 01) and (10, 11, 01)). Adaptive slots that share a point make degenerate
    // triangles, whose cross products are exactly 0.
    for (int cj = copy.j - 1; cj <= copy.j; ++cj) {
      for (int ci = copy.i - 1; ci <= copy.i; ++ci) {
        if (ci < 0 || cj < 0 || ci >= t || cj >= t) continue;
        const bool flip = cell_is_flipped(packed, ci, cj);
        const int plain[2][3][2] = {{{0, 0}, {1, 0}, {1, 1}}, {{0, 0}, {1, 1}, {0, 1}}};
        const int flipped[2][3][2] = {{{0, 0}, {1, 0}, {0, 1}}, {{1, 0}, {1, 1}, {0, 1}}};
        for (const auto& triangle : flip ? flipped : plain) {
          const TessVertex* v[3];
          bool touches = false;
          for (int k = 0; k < 3; ++k) {
            const int gi = ci + triangle[k][0], gj = cj + triangle[k][1];
            const bool centre = gi == copy.i && gj == copy.j;
            touches = touches || centre;
            v[k] = centre ? &own : &vertices[vertex_index(copy.patch, gi, gj, t)];
          }
          if (!touches) continue;
          const float ax = v[1]->position[0] - v[0]->position[0], ay = v[1]->position[1] - v[0]->position[1],
                      az = v[1]->position[2] - v[0]->position[2];
          const float bx = v[2]->position[0] - v[0]->position[0], by = v[2]->position[1] - v[0]->position[1],
                      bz = v[2]->position[2] - v[0]->position[2];
          nx += ay * bz - az * by;
          ny += az * bx - ax * bz;
          nz += ax * by - ay * bx;
        }
      }
    }
  }
  const float length = std::sqrt(nx * nx + ny * ny + nz * nz);
  if (!(length > 0.0f) || !std::isfinite(length)) return {0.0f, 0.0f, 0.0f};
  return {nx / length, ny / length, nz / length};
}

bool is_closed_mesh(const Scene& scene) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const Face& f : scene.faces) {
    for (int e = 0; e < 4; ++e) {
      const uint32_t a = f.vertices[e], b = f.vertices[(e + 1) % 4];
      ++uses[{std::min(a, b), std::max(a, b)}];
    }
  }
  if (uses.empty()) return false;
  for (const auto& [edge, count] : uses) {
    if (count != 2) return false;
  }
  return true;
}

Scene with_back_faces_flagged(const Scene& scene, const std::vector<TessVertex>& vertices, int tessellation,
                              bool adaptive) {
  const auto t = static_cast<size_t>(tessellation);
  const size_t per_patch = (t + 1) * (t + 1);
  if (tessellation < 1 || vertices.size() % per_patch != 0) {
    throw std::invalid_argument("with_back_faces_flagged: vertices are not whole patches at this tessellation");
  }
  const size_t patches = vertices.size() / per_patch;
  Scene out;
  out.name = scene.name;
  out.camera = scene.camera;
  out.orbit = scene.orbit;
  out.light = scene.light;
  out.background = scene.background;
  // One set of vertices for both: the flag must project exactly where the surface does (a flag
  // edge one subpixel past the surface's silhouette would show with nothing in front of it).
  out.positions.reserve(vertices.size());
  for (const TessVertex& v : vertices) out.positions.emplace_back(v.position[0], v.position[1], v.position[2]);
  auto solid = [](glm::vec3 colour) {
    TextureLevel level;
    level.width = level.height = 1;
    level.texels = {glm::vec4(colour, 1.0f)};
    return build_mip_chain(level);
  };
  const MipChain flag = solid(kFlagColor);
  out.faces.reserve(2 * patches * t * t);
  for (int pass = 0; pass < 2; ++pass) {
    for (size_t p = 0; p < patches; ++p) {
      // Light tints that differ between neighbours, never near the flag's magenta.
      const float k = static_cast<float>(p % 7) / 7.0f;
      const MipChain tint = pass == 0 ? solid(glm::vec3(0.55f + 0.3f * k, 0.75f - 0.2f * k, 0.6f)) : flag;
      for (size_t j = 0; j < t; ++j) {
        for (size_t i = 0; i < t; ++i) {
          auto at = [&](size_t di, size_t dj) {
            return static_cast<uint32_t>(p * per_patch + (j + dj) * (t + 1) + i + di);
          };
          // The tessellator splits a cell (00, 10, 11) + (00, 11, 01); a face (a, b, c, d)
          // renders as (a, b, c) + (a, c, d): the same triangles from corner 00. The reverse,
          // (00, 01, 11, 10), keeps that diagonal and turns both triangles over. Adaptive, the
          // cells (T-1, 0) and (0, T-1) split on 10-01: the same from corner 10.
          const bool flip = adaptive && t >= 2 && ((i == t - 1 && j == 0) || (i == 0 && j == t - 1));
          // Adaptive slots that share a point can make a cell without area (both its triangles
          // degenerate, nothing to draw), which a scene may not hold: left out of both passes.
          const glm::vec3 p0 = out.positions[at(0, 0)], p1 = out.positions[at(1, 0)], p2 = out.positions[at(1, 1)],
                          p3 = out.positions[at(0, 1)];
          if (!(glm::length(glm::cross(p2 - p0, p3 - p1)) > 0.0f)) continue;
          const std::array<uint32_t, 4> quad =
              flip ? (pass == 0 ? std::array<uint32_t, 4>{at(1, 0), at(1, 1), at(0, 1), at(0, 0)}
                                : std::array<uint32_t, 4>{at(1, 0), at(0, 0), at(0, 1), at(1, 1)})
                   : (pass == 0 ? std::array<uint32_t, 4>{at(0, 0), at(1, 0), at(1, 1), at(0, 1)}
                                : std::array<uint32_t, 4>{at(0, 0), at(0, 1), at(1, 1), at(1, 0)});
          out.faces.push_back({quad, tint});
        }
      }
    }
  }
  return out;
}

std::vector<TessVertex> tessellate_displacement(ClRuntime& runtime, const Scene& scene, const RenderOptions& options,
                                                const Camera* camera) {
  if (!options.displacement) throw InputError("displacement_method", "is needed to tessellate a displaced surface");
  TessellateLauncher stage(runtime);
  stage.load(pack_displacement(scene, displacement_settings(scene, options, camera ? *camera : scene.camera)));
  std::vector<TessVertex> vertices = stage.tessellate();
  stage.release();
  return vertices;
}

RenderOptions crack_render_options(const RenderOptions& options) {
  RenderOptions out;
  out.scene = options.scene;
  out.width = options.width;
  out.height = options.height;
  out.msaa = options.msaa;
  out.method = Method::Clamp;
  out.filter = Filter::Bilinear;
  return out;
}

size_t count_flag_pixels(const std::vector<uint32_t>& sample_triangles, int width, int height, int sample_count,
                         size_t first_flag_face) {
  size_t flagged = 0;
  const size_t pixels = static_cast<size_t>(width) * height;
  for (size_t pixel = 0; pixel < pixels && (pixel + 1) * sample_count <= sample_triangles.size(); ++pixel) {
    for (int s = 0; s < sample_count; ++s) {
      const uint32_t slot = sample_triangles[pixel * sample_count + s];
      if (slot != SEAMCL_NO_TRIANGLE && slot / SEAMCL_CLIP_SLOTS / 2 >= first_flag_face) {
        ++flagged;
        break;
      }
    }
  }
  return flagged;
}

size_t count_crack_pixels(const Scene& flagged, const FrameParams& frame, const std::vector<uint32_t>& sample_triangles,
                          size_t first_flag_face) {
  const std::vector<uint8_t> mask = crack_pixel_mask(flagged, frame, sample_triangles, first_flag_face);
  return static_cast<size_t>(std::count(mask.begin(), mask.end(), uint8_t{1}));
}

std::vector<uint8_t> crack_pixel_mask(const Scene& flagged, const FrameParams& frame,
                                      const std::vector<uint32_t>& sample_triangles, size_t first_flag_face) {
  const int width = frame.width, height = frame.height, samples = frame.sample_count;
  const size_t pixels = static_cast<size_t>(width) * height;
  if (sample_triangles.size() < pixels * samples) throw std::invalid_argument("crack_pixel_mask: too few samples");
  std::vector<uint8_t> cracks(pixels, 0);
  // The samples a flag face won, and their pixels.
  std::vector<char> candidate(pixels * samples, 0), candidate_pixel(pixels, 0);
  bool any = false;
  for (size_t i = 0; i < pixels * samples; ++i) {
    const uint32_t slot = sample_triangles[i];
    if (slot != SEAMCL_NO_TRIANGLE && slot / SEAMCL_CLIP_SLOTS / 2 >= first_flag_face) {
      candidate[i] = candidate_pixel[i / samples] = 1;
      any = true;
    }
  }
  if (!any) return cracks;
  // The faces that may cover one of them: projected with the frame's matrix, boxes padded by two
  // pixels (setup's snapping moves a vertex by less); a face reaching behind the near plane is
  // kept whole. The rest cannot change a candidate's balance.
  glm::mat4 view_proj;
  for (int k = 0; k < 16; ++k) view_proj[k / 4][k % 4] = frame.view_proj[k];
  std::vector<int> per_row_prefix(pixels + static_cast<size_t>(height), 0);  // candidates per row, prefix sums
  const int stride = width + 1;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      per_row_prefix[static_cast<size_t>(y) * stride + x + 1] =
          per_row_prefix[static_cast<size_t>(y) * stride + x] + candidate_pixel[static_cast<size_t>(y) * width + x];
    }
  }
  Scene near;
  near.positions = flagged.positions;
  std::vector<size_t> original;  // near's face f is flagged's face original[f]
  TextureLevel texel;
  texel.width = texel.height = 1;
  texel.texels = {glm::vec4(1.0f)};
  const MipChain plain = build_mip_chain(texel);
  for (size_t f = 0; f < flagged.faces.size(); ++f) {
    float x0 = 1e30f, x1 = -1e30f, y0 = 1e30f, y1 = -1e30f;
    bool behind = false;
    for (uint32_t v : flagged.faces[f].vertices) {
      const glm::vec4 c = view_proj * glm::vec4(flagged.positions[v], 1.0f);
      if (!(c.w > frame.near_w)) {
        behind = true;
        break;
      }
      const float sx = (c.x / c.w * 0.5f + 0.5f) * static_cast<float>(width);
      const float sy = (0.5f - c.y / c.w * 0.5f) * static_cast<float>(height);
      x0 = std::min(x0, sx), x1 = std::max(x1, sx), y0 = std::min(y0, sy), y1 = std::max(y1, sy);
    }
    bool keep = behind;
    if (!behind && x1 >= -2.0f && y1 >= -2.0f && x0 <= static_cast<float>(width) + 2.0f && y0 <= static_cast<float>(height) + 2.0f) {
      const int px0 = std::max(0, static_cast<int>(std::floor(x0)) - 2), px1 = std::min(width - 1, static_cast<int>(x1) + 2);
      const int py0 = std::max(0, static_cast<int>(std::floor(y0)) - 2), py1 = std::min(height - 1, static_cast<int>(y1) + 2);
      for (int y = py0; y <= py1 && !keep && px0 <= px1; ++y) {
        keep = per_row_prefix[static_cast<size_t>(y) * stride + px1 + 1] != per_row_prefix[static_cast<size_t>(y) * stride + px0];
      }
    }
    if (!keep) continue;
    near.faces.push_back({flagged.faces[f].vertices, plain});
    original.push_back(f);
  }
  FrameParams near_frame = frame;
  near_frame.input_triangles = static_cast<cl_int>(2 * near.faces.size());
  const std::vector<TriangleSetup> setups = setup_triangles_reference(pack_scene(near), near_frame);
  // Front faces +1, flag faces -1, at each candidate sample.
  std::vector<int> balance(pixels * samples, 0);
  const std::vector<SampleOffset>& pattern = sample_pattern(samples);
  for (size_t r = 0; r < setups.size(); ++r) {
    const TriangleSetup& s = setups[r];
    if (setup_is_empty(s)) continue;
    const int sign = original[r / SEAMCL_CLIP_SLOTS / 2] >= first_flag_face ? -1 : 1;
    for (int y = std::max(0, s.bbox_min_y); y <= std::min(height - 1, s.bbox_max_y); ++y) {
      for (int x = std::max(0, s.bbox_min_x); x <= std::min(width - 1, s.bbox_max_x); ++x) {
        const size_t pixel = static_cast<size_t>(y) * width + x;
        if (!candidate_pixel[pixel]) continue;
        for (int k = 0; k < samples; ++k) {
          if (candidate[pixel * samples + k] && setup_covers(s, sample_fixed_x(x, pattern[static_cast<size_t>(k)]),
                                                              sample_fixed_y(y, pattern[static_cast<size_t>(k)]))) {
            balance[pixel * samples + k] += sign;
          }
        }
      }
    }
  }
  for (size_t pixel = 0; pixel < pixels; ++pixel) {
    bool open = false;
    for (int k = 0; k < samples && !open; ++k) open = candidate[pixel * samples + k] && balance[pixel * samples + k] != 0;
    cracks[pixel] = open ? 1 : 0;
  }
  return cracks;
}

std::vector<uint8_t> frame_crack_pixels(ClRuntime& runtime, const Scene& scene, const Camera& camera,
                                        const RenderOptions& options, size_t device_byte_limit) {
  if (!options.displacement) throw InputError("displacement_method", "is needed to find crack pixels");
  if (!is_closed_mesh(scene)) {
    throw InputError("scene", "'" + scene.name + "' is not a closed mesh: crack pixels are found on closed meshes only");
  }
  // measure_displacement's steps 1 and 3 for one camera: the same settings, vertices, flagged
  // scene and crack render.
  PackedDisplacement packed = pack_displacement(scene, displacement_settings(scene, options, camera));
  const int slots = packed.params.tessellation;
  const bool adaptive = packed.adaptive();
  TessellateLauncher stage(runtime);
  stage.load(std::move(packed));
  const Scene flagged = with_back_faces_flagged(scene, stage.tessellate(), slots, adaptive);
  stage.release();
  const RenderOptions crack_options = crack_render_options(options);
  Renderer renderer(runtime);
  renderer.set_device_byte_limit(device_byte_limit);
  renderer.load_scene(flagged, crack_options.texels);
  renderer.render(camera, crack_options);
  return crack_pixel_mask(flagged, renderer.last_frame_params(), renderer.read_sample_triangles(),
                          flagged.faces.size() / 2);
}

nlohmann::json DisplacementReport::to_json() const {
  nlohmann::json out = {{"method", method},
                        {"tessellation", tessellation},
                        {"level", level},
                        {"max_gap", gap.max_gap},
                        {"max_edge_gap", gap.max_edge_gap},
                        {"max_corner_gap", gap.max_corner_gap},
                        {"max_normal_gap", gap.max_normal_gap},
                        {"differing_normals", gap.differing_normals},
                        {"compared_pairs", gap.compared_pairs},
                        {"differing_pairs", gap.differing_pairs},
                        {"crack_frames", crack_frames},
                        {"samples", samples},
                        {"vertices", vertices},
                        {"triangles", triangles},
                        {"surface_triangles", surface_triangles},
                        {"slots", slots},
                        {"tessellation_pixels", tessellation_pixels ? nlohmann::json(*tessellation_pixels) : nlohmann::json(nullptr)},
                        {"extra_bytes", extra_bytes},
                        {"matched_samples", matched_samples},
                        {"unmatched_edges", unmatched_edges},
                        {"tessellate_ms", tessellate_ms},
                        {"frame_ms", frame_ms}};
  out["crack_pixels"] = crack_pixels ? nlohmann::json(*crack_pixels) : nlohmann::json(nullptr);
  return out;
}

void check_tessellation_levels(const Scene& scene, const std::vector<int>& levels) {
  // A closed mesh's crack renders hold its micro-quads twice (with_back_faces_flagged).
  const size_t patches = (is_closed_mesh(scene) ? 2 : 1) * scene.faces.size();
  for (int t : levels) check_tessellation(patches, t);
}

DisplacementReport measure_displacement(ClRuntime& runtime, const Scene& scene, const Camera& camera,
                                        const RenderOptions& options, int orbit_frames, int repeat,
                                        size_t device_byte_limit) {
  if (!options.displacement) throw InputError("displacement_method", "is needed to measure displacement");
  if (orbit_frames > 0 && !scene.orbit) {
    throw InputError("crack_orbit", "scene '" + scene.name + "' has no orbit to count crack pixels over");
  }
  // Screen-space factors from `camera`, kept for every orbit frame: the crack renders draw one
  // tessellation, mixed factors included.
  const DisplacementSettings settings = displacement_settings(scene, options, camera);
  DisplacementReport report;
  report.method = to_string(settings.method);
  report.tessellation = settings.tessellation;
  report.level = settings.level;
  report.tessellation_pixels = options.tessellation_pixels;

  // 1. The gap, from the device's own tessellation (whose vertices the crack renders draw).
  PackedDisplacement packed = pack_displacement(scene, settings);
  report.extra_bytes = packed.method_bytes();
  report.matched_samples = packed.matched_samples;
  report.unmatched_edges = packed.unmatched_edges;
  report.triangles = packed.triangle_count();
  report.surface_triangles = packed.surface_triangle_count();
  report.slots = packed.params.tessellation;
  const bool adaptive = packed.adaptive();
  TessellateLauncher stage(runtime);
  stage.load(std::move(packed));
  const std::vector<cl_float4> normals = stage.tessellate_normals();  // what shading interpolates
  std::vector<TessVertex> vertices = stage.read_vertices();
  report.gap = measure_gap(stage.packed(), vertices, &normals);
  report.vertices = vertices.size();
  for (const TessVertex& v : vertices) report.samples += v.samples;
  stage.release();

  auto cameras = [&] {
    std::vector<Camera> list;
    if (orbit_frames > 0) {
      for (int f = 0; f < orbit_frames; ++f) list.push_back(orbit_camera(scene, f, orbit_frames));
    } else {
      list.push_back(camera);
    }
    return list;
  }();

  // 2. Time per frame, on the scene itself (repeat 0: the caller times its own renders).
  if (repeat > 0) {
    Renderer renderer(runtime);
    renderer.set_device_byte_limit(device_byte_limit);
    renderer.load_scene(scene, options.texels);
    renderer.render(cameras.front(), options);  // builds and warms the kernels
    std::vector<double> frame, tessellate;
    for (int r = 0; r < repeat; ++r) {
      const RenderResult result = renderer.render(cameras[static_cast<size_t>(r) % cameras.size()], options);
      frame.push_back(result.ms.total);
      tessellate.push_back(result.ms.tessellate);
    }
    report.frame_ms = median(frame);
    report.tessellate_ms = median(tessellate);
  }

  // 3. Crack pixels, on a closed mesh with its back faces flagged. The tessellation does not
  //    depend on the camera, so one copy of the displaced surface serves every frame.
  if (is_closed_mesh(scene)) {
    const RenderOptions crack_options = crack_render_options(options);
    Renderer renderer(runtime);
    renderer.set_device_byte_limit(device_byte_limit);
    const Scene flagged = with_back_faces_flagged(scene, vertices, report.slots, adaptive);
    const size_t first_flag_face = flagged.faces.size() / 2;
    vertices = {};
    renderer.load_scene(flagged, crack_options.texels);
    size_t cracks = 0;
    for (const Camera& c : cameras) {
      renderer.render(c, crack_options);
      cracks += count_crack_pixels(flagged, renderer.last_frame_params(), renderer.read_sample_triangles(), first_flag_face);
    }
    report.crack_pixels = cracks;
    report.crack_frames = static_cast<int>(cameras.size());
  }
  return report;
}

}  // namespace seamcl
