// The scene model, as small as a scene needs: quad patches over shared vertices, one texture
// (with its own mip chain) per face, a pinhole camera with an optional orbit, one directional light.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/scene/environment.h>

namespace seamcl {

struct Displacement;  // per-face displacement maps (scene/displacement_map.h)

// One mip level, texels in linear RGBA, row-major, row 0 at v = 0.
struct TextureLevel {
  int width = 0;
  int height = 0;
  std::vector<glm::vec4> texels;
  const glm::vec4& at(int i, int j) const { return texels[static_cast<size_t>(j) * width + i]; }
};

// A face's texture: level 0 is width x height (powers of two, not necessarily equal); each next
// level is a 2x2 box (2x1 or 1x2 once a side reaches 1) of the one before, down to 1x1. No data
// from neighbouring faces.
struct MipChain {
  std::vector<TextureLevel> levels;
  int width() const { return levels.empty() ? 0 : levels.front().width; }
  int height() const { return levels.empty() ? 0 : levels.front().height; }
};

// Builds the whole chain from level 0 (must be power-of-two sized).
MipChain build_mip_chain(TextureLevel level0);

// A chain that says only its levels' sizes (width x height down to 1x1) and holds no texels: the
// texture of a face whose texels Scene::texture_source makes when they are needed.
MipChain deferred_mip_chain(int width, int height);
// Level 0 holds no texels: the chain is a deferred one (a built level 0 has at least one).
bool is_deferred(const MipChain& chain);

// The next level of a chain: each side above 1 halved, each texel the mean of its 2x2 (2x1, 1x2)
// block.
TextureLevel box_downsample(const TextureLevel& fine);

// A quad patch. Vertices are counter-clockwise seen from the front and carry uv (0,0), (1,0),
// (1,1), (0,1) in order; it renders as triangles (v0,v1,v2) and (v0,v2,v3).
struct Face {
  std::array<uint32_t, 4> vertices{};
  MipChain texture;
  // < 0: a diffuse face showing its texture. >= 0: the face reflects the scene's environment
  // (0 a mirror; more widens the lookup, glossy), shaded with Scene::normals.
  float roughness = -1.0f;
};

// The point of the face at (u, v), piecewise linear over its two triangles exactly as rendered,
// so that texture content baked from a function of this point is continuous across shared edges.
glm::vec3 face_point(const std::array<glm::vec3, 4>& corners, float u, float v);

// Colours at surface points: colors[i] for points[i], i < count. A bake asks for a row of texels
// at a time, so that a pattern can be evaluated over many points at once (surface_patterns).
using SurfaceColors = std::function<void(const glm::vec3* points, size_t count, glm::vec4* colors)>;

// Level 0 of a face texture of the given size, each texel the function at its centre's surface
// point (face_point at ((i+.5)/w, (j+.5)/h)).
TextureLevel bake_face_texture(const std::array<glm::vec3, 4>& corners, int width, int height,
                               const SurfaceColors& surface_colors);
TextureLevel bake_face_texture(const std::array<glm::vec3, 4>& corners, int width, int height,
                               const std::function<glm::vec4(glm::vec3)>& surface_color);

struct Camera {
  glm::vec3 eye{0, 0, 5};
  glm::vec3 target{0, 0, 0};
  glm::vec3 up{0, 1, 0};
  float fov_y_degrees = 45.0f;  // vertical field of view
};

// Frame k of n puts the eye on a circle around `center`: angle = start_degrees + 360 k / n,
// at `radius` from the vertical axis through center and `height` above it, looking at center.
struct Orbit {
  glm::vec3 center{0, 0, 0};
  float radius = 5.0f;
  float height = 1.0f;
  float start_degrees = 0.0f;
};

struct Light {
  glm::vec3 to_light = glm::normalize(glm::vec3(0.4f, 1.0f, 0.3f));  // unit, towards the light
  glm::vec3 color{1, 1, 1};
  float ambient = 0.25f;  // lighting = color * (ambient + (1 - ambient) * max(0, n.l))
};

struct Scene {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<Face> faces;
  Camera camera;
  std::optional<Orbit> orbit;  // needed for --frame
  Light light;
  glm::vec3 background{0.02f, 0.02f, 0.03f};  // linear RGB
  std::optional<Environment> environment;      // what reflective faces (and the skybox) show
  std::vector<glm::vec3> normals;              // per vertex: shading normals of reflective faces
  // The function the textures were baked from, when there is one: texel (i, j) of face f holds
  // albedo(f, the surface point of its centre). The analytic reference evaluates it at every
  // subsample instead of filtering texels. Empty for textures that came from elsewhere (files).
  std::function<glm::vec4(size_t face, glm::vec3 point)> albedo;
  // Per-face displacement maps, read only by renders that ask for a displacement method
  // (docs/displacement.md); null for scenes without them.
  std::shared_ptr<const Displacement> displacement;
  // Makes face f's whole chain (exactly what a stored one would hold) for the faces whose texture
  // is deferred (is_deferred: sizes only). Generators, .ptx files, bare meshes' patterns and
  // explicit scene files (image faces read again from their files) asked to
  // (GeneratorOptions::defer_textures) leave their textures to it, so that no float RGBA copy of every face ever exists: pack_scene
  // makes each face's chain, packs it and drops it, and the packed copy is the only one (the
  // float chains are 4x the packed RGBA8 bytes). Thread-safe; a copy of the scene shares it.
  std::function<MipChain(size_t face)> texture_source;
  // The bytes texture_source keeps to make the faces from (a deferred .ptx's whole file): memory
  // a scene holds beyond its Face records, shared by its copies, for budgets to count.
  size_t texture_source_bytes = 0;
  // Per face (empty: 0 for all), what texture_source holds beside the face's level 0 while it makes
  // the face: an image face's decode buffers (texture_making_bytes counts them).
  std::vector<size_t> texture_source_decode_bytes;
  // The .ptx file whose face i is face i's texture, as resolved (a mesh with a .ptx, or a .ptx that
  // holds its mesh); empty for others. Ptex's own filters (ptex-*) read it again, in its own units.
  std::string ptex_file;

  size_t triangle_count() const { return faces.size() * 2; }
  std::array<glm::vec3, 4> corners(const Face& f) const;
  glm::vec3 face_normal(const Face& f) const;  // unit normal of the quad (cross of diagonals)
  size_t texel_count() const;                  // all levels of all faces, deferred ones included
  size_t stored_texel_count() const;           // the float RGBA texels held in memory (not deferred)
};

// Face f's chain: its stored one, or texture_source's for a deferred face (throws
// std::logic_error when there is no source, or it makes a chain of other sizes).
MipChain face_texture(const Scene& scene, size_t face);
// Bakes every deferred face's texture into the scene (in parallel over faces): for the code that
// reads other faces' texels (guard bands, references). A no-op for a scene without any.
void materialize_textures(Scene& scene);
bool has_deferred_textures(const Scene& scene);

// Runs work(f) for every f in [0, count) on this thread and up to 7 helpers (one fewer than the
// cores), faces handed out one at a time; the first exception thrown is rethrown here once all
// have stopped. Nothing about the result may depend on which thread ran which face.
void for_each_face_in_parallel(size_t count, const std::function<void(size_t face)>& work);

// The camera of frame `frame` of `frames` of the scene's orbit. Throws InputError (field "frame")
// when the scene has no orbit or frame is outside [0, frames).
Camera orbit_camera(const Scene& scene, int frame, int frames);

// Checks every invariant the renderer relies on (indices in range, power-of-two textures with a
// full chain, finite positions and camera, non-degenerate camera); throws InputError naming the
// field on the first violation.
void validate_scene(const Scene& scene);

// The largest magnitude of a colour value a scene may hold: texels (of textures and environment
// images) and the colours of lights, backgrounds and environments. Larger finite values can
// overflow a filter's weighted sum or the light's product to infinity, and infinity times a zero
// weight is NaN in the image. The .ptx reader's bound is the same (PtexLimits::max_texel_magnitude).
inline constexpr float kMaxColorMagnitude = 1e9f;

// Throws InputError(field) unless every component of the colour is finite and in [0, kMaxColorMagnitude]:
// the light's, the background's, a constant environment's.
void check_color(glm::vec3 color, const std::string& field);

// Throws InputError(field) naming the first mip level that holds a NaN, infinite or larger than
// kMaxColorMagnitude texel: what validate_scene checks of a stored chain, and what a deferred
// chain's source checks when it makes one (an image may hold any float).
void check_texel_magnitudes(const MipChain& chain, const std::string& field);

}  // namespace seamcl

namespace seamcl {

// Replaces every face's texture by one of the same size (full chain) filled with `color`: shows
// coverage and lighting without any texture content, and so without any seam.
void set_constant_textures(Scene& scene, glm::vec4 color);

// The colour (linear RGB in [0.05, 0.95], alpha 1) the generators paint at world point p: one
// smooth, colourful function of the 3D point with features 0.2 to 0.5 units wide, so a texture
// baked from it is continuous across every shared edge and any seam error shows. It holds no
// lines (only waves of colour and round light spots), so nothing in it reads as a seam.
glm::vec4 surface_pattern(glm::vec3 p);
// surface_pattern at points[0 .. count) into colors, equal to it at every point, over many points
// at once (the generators' bakes: it evaluates 8 a time on vectors).
void surface_patterns(const glm::vec3* points, size_t count, glm::vec4* colors);

// Texel-scale detail: a colourful function of the 3D point whose features (half a wavelength)
// are 2 to 4 times `texel_spacing` wide, in [0.05, 0.95], alpha 1. Continuous across every
// shared edge like surface_pattern, but with detail that a seam method's filter footprint at a
// seam actually resolves.
glm::vec4 detail_pattern(glm::vec3 p, float texel_spacing);

}  // namespace seamcl
