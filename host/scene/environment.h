// The environment a scene's reflective faces and skybox show: an analytic function of direction
// (a sun-like spot, a sharp horizon line, a coloured sky gradient) that the cube maps are baked
// from and the metrics integrate exactly, or a constant.
#pragma once
#include <functional>
#include <optional>

#include <glm/glm.hpp>

namespace seamcl {

// Linear RGBA of a unit direction.
using DirectionFunction = std::function<glm::vec4(glm::vec3)>;

struct AnalyticEnvironment {
  // On the +X/+Z cube edge, above the horizon: the sharpest smooth feature crosses a seam.
  glm::vec3 sun_direction = glm::normalize(glm::vec3(1.0f, 0.45f, 1.0f));
  float sun_radius = 0.1f;                 // radians: the spot's Gaussian width
  glm::vec3 sun_color{1.0f, 0.85f, 0.55f};
  glm::vec3 zenith{0.08f, 0.22f, 0.65f};
  glm::vec3 horizon{0.65f, 0.72f, 0.85f};  // the sky just above the horizon line
  glm::vec3 ground{0.30f, 0.24f, 0.16f};   // below it: a sharp step at y = 0
};

// Linear RGB in [0, 1], alpha 1, of unit direction d.
glm::vec4 environment_radiance(const AnalyticEnvironment& environment, glm::vec3 d);

struct Environment {
  AnalyticEnvironment analytic;
  std::optional<glm::vec3> constant;  // set: the environment is this colour everywhere
  int cube_size = 64;                 // level-0 face size of the baked cube maps (cube_map.h)
  int bake_samples = 2;               // samples x samples per texel when baking (see bake_cube_map)
  bool skybox = true;                 // samples no triangle covers show the environment
};

// The environment as a function of (unit) direction.
DirectionFunction environment_function(const Environment& environment);

// Checks cube_size, bake_samples and the analytic colours; throws InputError naming the field
// (environment.cube_size, ...).
void validate_environment(const Environment& environment);

}  // namespace seamcl
