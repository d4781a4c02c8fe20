// The built-in scenes. Every texture is baked from surface_pattern at the face's own surface
// points, so the content is continuous across every shared edge: a seam method that is right
// shows no seam, and any seam that shows is the method's fault.
#pragma once
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <seamcl/scene/scene.h>

namespace seamcl {

// What a generated texture holds: `surface`, the smooth surface_pattern (features of 0.2 to 0.5
// units); `detail`, detail_pattern with features of 2 to 4 texels of the scene's median face
// (median_texel_spacing), the texel-scale regime in which seam methods differ most.
enum class TextureContent { Surface, Detail };
std::optional<TextureContent> parse_texture_content(std::string_view name);
std::string to_string(TextureContent content);
std::vector<std::string> texture_content_names();

struct GeneratorOptions {
  bool tint = false;                        // multiply each face by its own pastel (face_tint)
  std::optional<glm::vec3> constant_color;  // paint this colour instead of the content
  std::optional<TextureContent> content;    // unset: the generator's own (GeneratorInfo)
  // envmap only: its environment (constant_color then makes it constant) and the roughness of
  // its mirror sphere, glossy sphere and torus.
  std::optional<Environment> environment;
  std::optional<glm::vec3> roughness;
  // Leave the generator's baked textures to Scene::texture_source (deferred_mip_chain sizes
  // only): a render that packs the scene once never holds the float copy of every texture.
  // The texels are the same either way.
  bool defer_textures = false;
  // paper only, for scaling measurements (seamcl bench --sweep). faces: about this many faces
  // (kMinPaperFaces..kMaxPaperFaces; the torus and the ground subdivided in proportion, within 2%
  // of it or 5 faces), each texture's area divided by the power of two nearest faces / 2,474 so that the
  // scene keeps about the original's texels (sides stop at 1). texture_scale_log2: every texture
  // side times 2^k (kMinTextureScaleLog2..kMaxTextureScaleLog2), after the face count's scaling.
  // Unset (or 2,474 and 0): the paper scene itself.
  std::optional<int> faces;
  std::optional<int> texture_scale_log2;
};

inline constexpr int kPaperFaces = 2474;          // 50 x 29 torus quads and 32 x 32 ground quads
inline constexpr int kMinPaperFaces = 100;
inline constexpr int kMaxPaperFaces = 250000;     // about 100 MB of scene and packed tables
inline constexpr int kMinTextureScaleLog2 = -4;   // sides 16..128 become 1..8
inline constexpr int kMaxTextureScaleLog2 = 1;    // 4x the texels: about 150 MB packed RGBA8

// InputError ("faces" / "texture_scale_log2", prefixed by `path` when not empty) for a value out
// of its range or a scene other than paper.
void check_paper_scaling(const std::string& scene, const GeneratorOptions& options, const std::string& path = {});

struct GeneratorInfo {
  std::string name;
  std::string description;
  TextureContent content = TextureContent::Surface;  // its content unless options say otherwise
};

// paper, quad2, plane, cube, closeup-seam, closeup-corner, mixed, displaced; the first is the default scene.
const std::vector<GeneratorInfo>& scene_generators();

// Throws InputError (field "scene") for an unknown name.
Scene generate_scene(const std::string& name, const GeneratorOptions& options);

// The median over faces of sqrt(area / texels): the world size of a typical texel, the unit of
// detail_pattern's features.
float median_texel_spacing(const Scene& scene);

// A light, distinct-looking colour for face `face_index`, the same on every run.
glm::vec3 face_tint(size_t face_index);

// Repaints the textures of an existing scene (e.g. one loaded from a file) as the options say:
// content repaints every texture with it (sizes kept), constant_color replaces every texture
// (sizes kept), tint multiplies each face by face_tint; scene.albedo follows. Content painted by
// a generator is unchanged by an empty options.
void apply_generator_options(Scene& scene, const GeneratorOptions& options);

}  // namespace seamcl
