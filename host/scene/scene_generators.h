// The built-in scenes. Every texture is baked from surface_pattern at the face's own surface
// points, so the content is continuous across every shared edge: a seam method that is right
// shows no seam, and any seam that shows is the method's fault.
#pragma once
#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include <seamcl/scene/scene.h>

namespace seamcl {

struct GeneratorOptions {
  bool tint = false;                        // multiply each face by its own pastel (face_tint)
  std::optional<glm::vec3> constant_color;  // paint this colour instead of surface_pattern
  // envmap only: its environment (constant_color then makes it constant) and the roughness of
  // its mirror sphere, glossy sphere and torus.
  std::optional<Environment> environment;
  std::optional<glm::vec3> roughness;
};

struct GeneratorInfo {
  std::string name;
  std::string description;
};

// paper, quad2, plane, cube; the first is the default scene.
const std::vector<GeneratorInfo>& scene_generators();

// Throws InputError (field "scene") for an unknown name.
Scene generate_scene(const std::string& name, const GeneratorOptions& options);

// A light, distinct-looking colour for face `face_index`, the same on every run.
glm::vec3 face_tint(size_t face_index);

// Repaints the textures of an existing scene (e.g. one loaded from a file) as the options say:
// constant_color replaces every texture (sizes kept), tint multiplies each face by face_tint.
// Content painted from surface_pattern by a generator is unchanged by an empty options.
void apply_generator_options(Scene& scene, const GeneratorOptions& options);

}  // namespace seamcl
