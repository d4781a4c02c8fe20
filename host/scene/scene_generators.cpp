#include <seamcl/scene/scene_generators.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <random>

#include <seamcl/core/input_error.h>
#include <seamcl/scene/envmap_scene.h>
#include "scene/displaced_scene.h"

namespace seamcl {
namespace {

constexpr float kPi = 3.14159265358979f;

struct TextureSize {
  int width;
  int height;
};

float median_spacing(const Scene& scene, const std::vector<TextureSize>& sizes) {
  std::vector<float> spacing;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const auto c = scene.corners(scene.faces[f]);
    const float area = 0.5f * glm::length(glm::cross(c[2] - c[0], c[3] - c[1]));
    spacing.push_back(std::sqrt(area / static_cast<float>(sizes[f].width * sizes[f].height)));
  }
  if (spacing.empty()) return 1.0f;
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2), spacing.end());
  return spacing[spacing.size() / 2];
}

// The albedo the options ask for: content (or the constant colour), times the face's tint.
std::function<glm::vec4(size_t, glm::vec3)> albedo_function(TextureContent content, float texel_spacing,
                                                            const GeneratorOptions& options) {
  const std::optional<glm::vec3> constant = options.constant_color;
  const bool tint = options.tint;
  return [=](size_t face, glm::vec3 p) {
    const glm::vec4 color = constant                              ? glm::vec4(*constant, 1.0f)
                            : content == TextureContent::Detail ? detail_pattern(p, texel_spacing)
                                                                  : surface_pattern(p);
    return tint ? color * glm::vec4(face_tint(face), 1.0f) : color;
  };
}

// The albedo over a row of points at once (what the bakes ask for), equal at every point to
// albedo_function's with the same arguments: the plain surface content, the generators' usual
// one, through surface_patterns, anything else a point at a time.
using FaceColors = std::function<void(size_t face, const glm::vec3* points, size_t count, glm::vec4* colors)>;

FaceColors face_colors_function(TextureContent content, float texel_spacing, const GeneratorOptions& options) {
  if (options.constant_color || content != TextureContent::Surface) {
    return [albedo = albedo_function(content, texel_spacing, options)](size_t face, const glm::vec3* points,
                                                                       size_t count, glm::vec4* colors) {
      for (size_t i = 0; i < count; ++i) colors[i] = albedo(face, points[i]);
    };
  }
  return [tint = options.tint](size_t face, const glm::vec3* points, size_t count, glm::vec4* colors) {
    surface_patterns(points, count, colors);
    if (!tint) return;
    const glm::vec4 factor(face_tint(face), 1.0f);
    for (size_t i = 0; i < count; ++i) colors[i] = colors[i] * factor;
  };
}

// Face f's chain baked from `colors` at its texel centres.
MipChain bake_face_chain(const std::array<glm::vec3, 4>& corners, TextureSize size, const FaceColors& colors,
                         size_t f) {
  return build_mip_chain(bake_face_texture(corners, size.width, size.height,
                                           [&](const glm::vec3* points, size_t count, glm::vec4* out) {
                                             colors(f, points, count, out);
                                           }));
}

// Texture contents for every face, in parallel, baked from `colors` (scene.albedo's): baking the
// paper scene's ~9 million texels is most of its generation time, and faces are independent, so
// the result does not depend on the number of threads or their timing. With defer, nothing is
// baked: every face gets its sizes and scene.texture_source the same recipe (its own copy of the
// corners and the colours, so it stays right in any copy of the scene), baked when packed.
void bake_textures(Scene& scene, const std::vector<TextureSize>& sizes, const FaceColors& colors, bool defer) {
  if (defer) {
    struct Recipe {
      std::vector<std::array<glm::vec3, 4>> corners;
      std::vector<TextureSize> sizes;
      FaceColors colors;
    };
    auto recipe = std::make_shared<Recipe>();
    for (const Face& face : scene.faces) recipe->corners.push_back(scene.corners(face));
    recipe->sizes = sizes;
    recipe->colors = colors;
    for (size_t f = 0; f < scene.faces.size(); ++f)
      scene.faces[f].texture = deferred_mip_chain(sizes[f].width, sizes[f].height);
    scene.texture_source = [recipe = std::shared_ptr<const Recipe>(std::move(recipe))](size_t f) {
      return bake_face_chain(recipe->corners.at(f), recipe->sizes.at(f), recipe->colors, f);
    };
    scene.texture_source_bytes = 0;  // whatever made the faces before is dropped
    return;
  }
  // Faces are handed out one at a time because their sizes differ by up to 64x.
  for_each_face_in_parallel(scene.faces.size(), [&](size_t f) {
    scene.faces[f].texture = bake_face_chain(scene.corners(scene.faces[f]), sizes[f], colors, f);
  });
}

// The generator's textures: `sizes` per face, painted as the options say over `content`, the
// generator's own content.
void paint_textures(Scene& scene, const std::vector<TextureSize>& sizes, const GeneratorOptions& options,
                    TextureContent content = TextureContent::Surface) {
  const TextureContent painted = options.content.value_or(content);
  const float spacing = median_spacing(scene, sizes);
  scene.albedo = albedo_function(painted, spacing, options);
  bake_textures(scene, sizes, face_colors_function(painted, spacing, options), options.defer_textures);
}

// A grid of nx x nz quads over [x0, x1] x [z0, z1] at height y, facing +y (counter-clockwise seen
// from above), u along +x and v along -z. Vertices are shared between neighbouring quads.
void add_ground_grid(Scene& scene, int nx, int nz, float x0, float x1, float z0, float z1,
                     float y) {
  const auto base = static_cast<uint32_t>(scene.positions.size());
  for (int j = 0; j <= nz; ++j)
    for (int i = 0; i <= nx; ++i)
      scene.positions.emplace_back(x0 + (x1 - x0) * static_cast<float>(i) / static_cast<float>(nx),
                                   y,
                                   z1 - (z1 - z0) * static_cast<float>(j) / static_cast<float>(nz));
  auto vertex = [&](int i, int j) { return base + static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < nz; ++j)
    for (int i = 0; i < nx; ++i)
      scene.faces.push_back(
          {{vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)}, {}});
}

// A closed torus standing upright: its axis is z, so the ring lies in the xy plane. Quad (i, j)
// spans major angles i..i+1 (u) and tube angles j..j+1 (v), which makes it counter-clockwise
// seen from outside.
void add_torus(Scene& scene, glm::vec3 center, float major_radius, float minor_radius,
               int major_segments, int minor_segments) {
  const auto base = static_cast<uint32_t>(scene.positions.size());
  for (int i = 0; i < major_segments; ++i) {
    const float theta = 2.0f * kPi * static_cast<float>(i) / static_cast<float>(major_segments);
    for (int j = 0; j < minor_segments; ++j) {
      const float phi = 2.0f * kPi * static_cast<float>(j) / static_cast<float>(minor_segments);
      const float ring = major_radius + minor_radius * std::cos(phi);
      scene.positions.push_back(center + glm::vec3(ring * std::cos(theta), ring * std::sin(theta),
                                                   minor_radius * std::sin(phi)));
    }
  }
  auto vertex = [&](int i, int j) {
    return base + static_cast<uint32_t>((i % major_segments) * minor_segments + j % minor_segments);
  };
  for (int i = 0; i < major_segments; ++i)
    for (int j = 0; j < minor_segments; ++j)
      scene.faces.push_back(
          {{vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)}, {}});
}

void set_orbit_and_camera(Scene& scene, Orbit orbit, float fov_y_degrees) {
  scene.orbit = orbit;
  scene.camera.fov_y_degrees = fov_y_degrees;
  scene.camera = orbit_camera(scene, 0, 1);
}

// Figure 1 of the paper: a torus on a ground plane, every face with its own texture of a size
// drawn independently per axis from 16..128, so neighbouring faces rarely match. With
// options.faces, the same scene subdivided further (or less), its textures scaled to keep about
// the same texels; with options.texture_scale_log2, every texture side scaled by a power of two.
Scene make_paper(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "paper";
  constexpr float kMajorRadius = 2.0f;
  constexpr float kMinorRadius = 0.7f;
  const double target = static_cast<double>(options.faces.value_or(kPaperFaces));
  const double scale = std::sqrt(target / kPaperFaces);  // of the segment counts
  auto segments = [&](int original) { return std::max(3, static_cast<int>(std::lround(original * scale))); };
  // The area of each texture divided by 2^area_shift, split over the two sides (u takes the larger half).
  const int area_shift = static_cast<int>(std::lround(std::log2(target / kPaperFaces)));
  const int u_shift = area_shift >= 0 ? (area_shift + 1) / 2 : area_shift / 2;
  const int v_shift = area_shift - u_shift;
  const int texture_scale = options.texture_scale_log2.value_or(0);
  auto scaled_side = [](int side, int log2_factor) {
    const int scaled = log2_factor >= 0 ? side << log2_factor : side >> -log2_factor;
    return std::clamp(scaled, 1, 4096);
  };
  // Resting on the ground: the exact torus would touch y = 0; its polygonal version stays a few
  // thousandths above it.
  const glm::vec3 torus_center(0.0f, kMajorRadius + kMinorRadius, 0.0f);
  add_torus(scene, torus_center, kMajorRadius, kMinorRadius, segments(50), segments(29));
  // The ground takes what the torus leaves of the count (32 x 32 for the paper scene itself).
  const int torus_faces = segments(50) * segments(29);
  const int ground = std::max(3, static_cast<int>(std::lround(std::sqrt(std::max(target - torus_faces, 9.0)))));
  add_ground_grid(scene, ground, ground, -8.0f, 8.0f, -8.0f, 8.0f, 0.0f);

  std::mt19937 random(20130805u);
  constexpr int kSides[] = {16, 32, 64, 128};
  std::vector<TextureSize> sizes(scene.faces.size());
  for (TextureSize& size : sizes) {
    size.width = scaled_side(kSides[random() % 4], texture_scale - u_shift);
    size.height = scaled_side(kSides[random() % 4], texture_scale - v_shift);
  }
  paint_textures(scene, sizes, options);

  set_orbit_and_camera(scene, Orbit{torus_center, 8.0f, 3.0f, 25.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(-0.5f, 1.0f, 0.6f));
  return scene;
}

// The smallest seam: two unit quads side by side in the z = 0 plane whose textures differ in
// size and aspect (64x64 on the left, 32x16 on the right).
Scene make_quad2(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "quad2";
  scene.positions = {{-1.0f, -0.5f, 0.0f}, {0.0f, -0.5f, 0.0f}, {1.0f, -0.5f, 0.0f},
                     {-1.0f, 0.5f, 0.0f},  {0.0f, 0.5f, 0.0f},  {1.0f, 0.5f, 0.0f}};
  scene.faces = {{{0, 1, 4, 3}, {}}, {{1, 2, 5, 4}, {}}};
  paint_textures(scene, {{64, 64}, {32, 16}}, options);
  // 2.7 units away a 45 degree view is 2.24 units wide: the pair fills most of a square image.
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.0f), 2.7f, 0.0f, 0.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 0.5f, 1.0f));
  return scene;
}

// Strong anisotropy: a large ground plane seen from eye height 1, the far edge nearly at the
// horizon.
Scene make_plane(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "plane";
  add_ground_grid(scene, 64, 64, -64.0f, 64.0f, -64.0f, 64.0f, 0.0f);
  paint_textures(scene, std::vector<TextureSize>(scene.faces.size(), {32, 32}), options);
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.0f), 8.0f, 1.0f, 0.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f));
  return scene;
}

// A closed cube, side 2, centred at the origin; seen obliquely, so three faces and the edges and
// corner between them show.
Scene make_cube(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "cube";
  // Corner index = x_bit + 2 y_bit + 4 z_bit, a set bit meaning +1.
  for (uint32_t corner = 0; corner < 8; ++corner)
    scene.positions.emplace_back((corner & 1) ? 1.0f : -1.0f, (corner & 2) ? 1.0f : -1.0f,
                                 (corner & 4) ? 1.0f : -1.0f);
  // Faces +x, -x, +y, -y, +z, -z, each counter-clockwise seen from outside.
  scene.faces = {{{5, 1, 3, 7}, {}}, {{0, 4, 6, 2}, {}}, {{6, 7, 3, 2}, {}},
                 {{0, 1, 5, 4}, {}}, {{4, 5, 7, 6}, {}}, {{1, 0, 2, 3}, {}}};
  paint_textures(scene, std::vector<TextureSize>(scene.faces.size(), {64, 64}), options);
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.0f), 5.0f, 3.2f, 35.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 1.0f, 0.55f));
  return scene;
}

// A flat grid of nx x ny unit quads in the z = 0 plane, centred on the origin, facing +z, u along
// +x and v along +y: every face's texture continues its neighbours', so with equal sizes the
// grid is one texture (the seamless reference).
void add_wall_grid(Scene& scene, int nx, int ny) {
  const auto base = static_cast<uint32_t>(scene.positions.size());
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      scene.positions.emplace_back(static_cast<float>(i) - 0.5f * static_cast<float>(nx),
                                   static_cast<float>(j) - 0.5f * static_cast<float>(ny), 0.0f);
  auto vertex = [&](int i, int j) { return base + static_cast<uint32_t>(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      scene.faces.push_back({{vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)}, {}});
}

// Magnification at a seam: two 16x16-texel unit quads side by side, the camera 1.2 units from
// their shared edge, a little off-axis: about 12 texels across the view, so every
// texel spans many pixels and a filter's taps at the seam are the neighbour's texels.
Scene make_closeup_seam(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "closeup-seam";
  add_wall_grid(scene, 2, 1);
  paint_textures(scene, std::vector<TextureSize>(scene.faces.size(), {16, 16}), options, TextureContent::Detail);
  // Centred a little beside the seam: a vertical line through the target would project onto the
  // image's middle column, exactly between two pixels.
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.15f, 0.05f, 0.0f), 1.2f, 0.25f, 20.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.3f, 0.5f, 1.0f));
  return scene;
}

// Magnification at a corner: four 16x16-texel unit quads around one vertex (valence 4), seen
// from 1.2 units, a little off-axis: footprints past the corner reach the diagonal face.
Scene make_closeup_corner(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "closeup-corner";
  add_wall_grid(scene, 2, 2);
  paint_textures(scene, std::vector<TextureSize>(scene.faces.size(), {16, 16}), options, TextureContent::Detail);
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.12f, 0.1f, 0.0f), 1.2f, 0.3f, -25.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(-0.3f, 0.4f, 1.0f));
  return scene;
}

// A closed quad mesh with vertices of valence 3, 4 and 5: a pentagonal prism whose 7 faces are
// each split into quads around their centre (a Catmull-Clark step without the smoothing), 30
// quads. Texture sizes run from 1x1 to 256x256 side by side (powers of two per axis, non-square
// included) and every face starts its vertex order at a different corner, so neighbours meet
// rotated by every multiple of 90 degrees.
Scene make_mixed(const GeneratorOptions& options) {
  Scene scene;
  scene.name = "mixed";
  constexpr int kSides = 5;
  constexpr float kRadius = 1.0f, kHalfHeight = 0.7f;
  for (int ring = 0; ring < 2; ++ring)
    for (int k = 0; k < kSides; ++k) {
      const float angle = 2.0f * kPi * static_cast<float>(k) / kSides;
      scene.positions.emplace_back(kRadius * std::cos(angle), ring == 0 ? -kHalfHeight : kHalfHeight,
                                   kRadius * std::sin(angle));
    }
  std::vector<std::vector<uint32_t>> polygons;
  std::vector<uint32_t> bottom, top;
  for (uint32_t k = 0; k < kSides; ++k) {
    bottom.push_back(k);
    top.push_back(kSides + k);
    polygons.push_back({k, (k + 1) % kSides, kSides + (k + 1) % kSides, kSides + k});
  }
  polygons.push_back(bottom);
  polygons.push_back(top);
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;  // shared, so the mesh stays closed
  auto midpoint = [&](uint32_t a, uint32_t b) {
    const auto key = std::minmax(a, b);
    auto it = midpoints.find(key);
    if (it != midpoints.end()) return it->second;
    scene.positions.push_back(0.5f * (scene.positions[a] + scene.positions[b]));
    return midpoints[key] = static_cast<uint32_t>(scene.positions.size() - 1);
  };
  std::mt19937 random(5u);
  for (std::vector<uint32_t> polygon : polygons) {
    glm::vec3 center(0.0f);
    for (uint32_t v : polygon) center += scene.positions[v];
    center /= static_cast<float>(polygon.size());
    // Counter-clockwise seen from outside (the prism is convex around the origin).
    const glm::vec3 normal = glm::cross(scene.positions[polygon[1]] - scene.positions[polygon[0]],
                                        scene.positions[polygon[2]] - scene.positions[polygon[1]]);
    if (glm::dot(normal, center) < 0.0f) std::reverse(polygon.begin(), polygon.end());
    scene.positions.push_back(center);
    const auto center_index = static_cast<uint32_t>(scene.positions.size() - 1);
    const size_t n = polygon.size();
    for (size_t i = 0; i < n; ++i) {
      std::array<uint32_t, 4> quad = {polygon[i], midpoint(polygon[i], polygon[(i + 1) % n]), center_index,
                                      midpoint(polygon[(i + n - 1) % n], polygon[i])};
      std::rotate(quad.begin(), quad.begin() + random() % 4, quad.end());
      scene.faces.push_back({quad, {}});
    }
  }
  std::vector<TextureSize> sizes(scene.faces.size());
  for (TextureSize& size : sizes) size = {1 << (random() % 9), 1 << (random() % 9)};
  // Both extremes, whatever the draw: a 1x1 face beside a 256x256 one (faces 0 and 1 share an
  // edge: consecutive quads of a polygon do).
  sizes[0] = {1, 1};
  sizes[1] = {256, 256};
  paint_textures(scene, sizes, options);
  set_orbit_and_camera(scene, Orbit{glm::vec3(0.0f), 3.2f, 1.9f, 15.0f}, 45.0f);
  scene.light.to_light = glm::normalize(glm::vec3(0.4f, 1.0f, 0.5f));
  return scene;
}

struct Generator {
  GeneratorInfo info;
  Scene (*make)(const GeneratorOptions&);
};

const std::vector<Generator>& generators() {
  static const std::vector<Generator> list = {
      {{"paper",
        "the paper's Figure 1: an upright torus (50x29 quads) on a ground plane (32x32 quads), "
        "every face its own texture, sides 16 to 128, mixed and non-square; minified, smooth content"},
       make_paper},
      {{"quad2", "two unit quads sharing one edge, textures 64x64 and 32x16"}, make_quad2},
      {{"plane", "a 128x128 ground plane of 64x64 quads (32x32 textures) at a grazing angle"},
       make_plane},
      {{"cube", "a closed cube of six 64x64-textured faces, seen obliquely"}, make_cube},
      {{"closeup-seam", "magnified: two 16x16-texel unit quads, the camera 1.2 units from their shared edge; detail content",
        TextureContent::Detail},
       make_closeup_seam},
      {{"closeup-corner",
        "magnified: four 16x16-texel unit quads around a valence-4 vertex, seen from 1.2 units; detail content",
        TextureContent::Detail},
       make_closeup_corner},
      {{"mixed",
        "a closed mesh (a split pentagonal prism, 30 quads, vertices of valence 3, 4 and 5) with textures from 1x1 to "
        "256x256 side by side and neighbours rotated by every multiple of 90 degrees"},
       make_mixed},
      {{"envmap", "mirror and glossy spheres and a mirror torus in an analytic environment (skybox), "
                  "for the cube-map methods (cube_method)"},
       [](const GeneratorOptions& options) { return make_envmap_scene(options); }},
      {{"displaced",
        "a closed cube-sphere of 24 quads with displacement maps (2x2 to 33x33 samples, neighbours rotated); "
        "render it with displacement_method"},
       make_displaced_scene},
  };
  return list;
}

uint32_t hash32(uint32_t x) {
  // A well-mixed integer hash (lowbias32), so that neighbouring indices get unrelated colours.
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

}  // namespace

std::optional<TextureContent> parse_texture_content(std::string_view name) {
  if (name == "surface") return TextureContent::Surface;
  if (name == "detail") return TextureContent::Detail;
  return std::nullopt;
}

std::string to_string(TextureContent content) {
  return content == TextureContent::Detail ? "detail" : "surface";
}

std::vector<std::string> texture_content_names() { return {"surface", "detail"}; }

float median_texel_spacing(const Scene& scene) {
  std::vector<TextureSize> sizes;
  for (const Face& face : scene.faces) sizes.push_back({face.texture.width(), face.texture.height()});
  return median_spacing(scene, sizes);
}

const std::vector<GeneratorInfo>& scene_generators() {
  static const std::vector<GeneratorInfo> infos = [] {
    std::vector<GeneratorInfo> list;
    for (const Generator& generator : generators()) list.push_back(generator.info);
    return list;
  }();
  return infos;
}

void check_paper_scaling(const std::string& scene, const GeneratorOptions& options, const std::string& path) {
  const std::string prefix = path.empty() ? "" : path + ".";
  if (options.faces) {
    if (scene != "paper") throw InputError(prefix + "faces", "only the paper scene takes a face count, not '" + scene + "'");
    if (*options.faces < kMinPaperFaces || *options.faces > kMaxPaperFaces) {
      throw InputError(prefix + "faces", "must be in " + std::to_string(kMinPaperFaces) + ".." +
                                             std::to_string(kMaxPaperFaces) + ", got " + std::to_string(*options.faces));
    }
  }
  if (options.texture_scale_log2) {
    if (scene != "paper")
      throw InputError(prefix + "texture_scale_log2", "only the paper scene takes a texture scale, not '" + scene + "'");
    if (*options.texture_scale_log2 < kMinTextureScaleLog2 || *options.texture_scale_log2 > kMaxTextureScaleLog2) {
      throw InputError(prefix + "texture_scale_log2", "must be in " + std::to_string(kMinTextureScaleLog2) + ".." +
                                                          std::to_string(kMaxTextureScaleLog2) + ", got " +
                                                          std::to_string(*options.texture_scale_log2));
    }
  }
}

Scene generate_scene(const std::string& name, const GeneratorOptions& options) {
  for (const Generator& generator : generators()) {
    if (generator.info.name != name) continue;
    check_paper_scaling(name, options);
    Scene scene = generator.make(options);
    validate_scene(scene);
    return scene;
  }
  std::string known;
  for (const Generator& generator : generators())
    known += (known.empty() ? "" : ", ") + generator.info.name;
  throw InputError("scene", "unknown scene '" + name + "' (known: " + known + ")");
}

glm::vec3 face_tint(size_t face_index) {
  const uint32_t hash = hash32(static_cast<uint32_t>(face_index));
  const float hue = static_cast<float>(hash % 3600u) / 3600.0f;
  const float saturation = 0.25f + 0.2f * static_cast<float>((hash >> 12) % 256u) / 255.0f;
  // A fully saturated hue, then mixed towards white: a pastel with every channel >= 0.55.
  const glm::vec3 pure = glm::clamp(
      glm::abs(glm::fract(glm::vec3(hue) + glm::vec3(1.0f, 2.0f / 3.0f, 1.0f / 3.0f)) * 6.0f -
               glm::vec3(3.0f)) -
          glm::vec3(1.0f),
      glm::vec3(0.0f), glm::vec3(1.0f));
  return glm::mix(glm::vec3(1.0f), pure, saturation);
}

void apply_generator_options(Scene& scene, const GeneratorOptions& options) {
  if (options.content && !options.constant_color) {
    std::vector<TextureSize> sizes;
    for (const Face& face : scene.faces) sizes.push_back({face.texture.width(), face.texture.height()});
    paint_textures(scene, sizes, options);  // tint included
    return;
  }
  if (options.constant_color)
    set_constant_textures(scene, glm::vec4(*options.constant_color, 1.0f));
  if (options.constant_color && scene.environment) scene.environment->constant = *options.constant_color;
  if (!options.tint) return;
  // The box filter is linear, so scaling every level equals re-filtering a scaled level 0.
  auto tint_chain = [](MipChain& chain, size_t f) {
    const glm::vec4 tint(face_tint(f), 1.0f);
    for (TextureLevel& level : chain.levels)
      for (glm::vec4& texel : level.texels) texel *= tint;
  };
  // Deferred faces stay deferred: their source tints what it makes (a deferred face has no
  // texels to tint here; stored faces are tinted below).
  if (scene.texture_source) {
    scene.texture_source = [untinted = scene.texture_source, tint_chain](size_t f) {
      MipChain chain = untinted(f);
      tint_chain(chain, f);
      return chain;
    };
  }
  for (size_t f = 0; f < scene.faces.size(); ++f) tint_chain(scene.faces[f].texture, f);
  if (scene.albedo) {
    scene.albedo = [untinted = scene.albedo](size_t face, glm::vec3 p) {
      return untinted(face, p) * glm::vec4(face_tint(face), 1.0f);
    };
  }
}

}  // namespace seamcl
