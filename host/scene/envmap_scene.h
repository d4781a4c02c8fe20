// The built-in `envmap` scene: reflective surfaces in front of an analytic environment shown as
// a skybox, for the cube-map seam methods (a reflection sweeps across cube edges in the middle of
// a surface, where no geometric edge lies under the seam).
#pragma once
#include <functional>

#include <glm/glm.hpp>

#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

// A mirror sphere, a glossy sphere (roughness 0.15) and a mirror torus ring around them, the
// default AnalyticEnvironment as skybox, on an orbit. options.environment and options.roughness
// replace those; with options.constant_color the environment is that colour everywhere (every
// cube method then renders it exactly). options.tint does not apply.
Scene make_envmap_scene(const GeneratorOptions& options);

// Adds an nu x nv grid of reflective quads over (a, b) in [0, 1]^2: vertices at point(a, b) with
// unit normal normal(a, b) (shared inside the grid), every quad wound counter-clockwise seen from
// the side its normals point to. Textures are 1 x 1 (reflective faces never read them).
void add_reflective_grid(Scene& scene, int nu, int nv, const std::function<glm::vec3(float, float)>& point,
                         const std::function<glm::vec3(float, float)>& normal, float roughness);
void add_reflective_sphere(Scene& scene, glm::vec3 center, float radius, int quads_per_side, float roughness);
// A torus around the vertical axis through center.
void add_reflective_torus(Scene& scene, glm::vec3 center, float major_radius, float minor_radius, int major_segments,
                          int minor_segments, float roughness);

}  // namespace seamcl
