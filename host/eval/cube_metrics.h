// How the cube-map seam methods do, measured against the analytic environment itself (never
// against another method): the seam step at the 12 edges per mip level, the first-order jump
// across them, and the error of rendered frames against the environment integrated over each
// pixel's footprint.
#pragma once
#include <cstdint>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/environment.h>

namespace seamcl {

// Along each of the 12 edges at `points` evenly spaced places, lookups (one trilinear lookup at
// an explicit lod) just inside each of the two faces, 1e-4 face widths from the edge.
struct EdgeMeasures {
  int size = 0;
  // The method's cube on the host: bake (every level of every face from the environment), edge
  // averaging and packing, in ms on this machine; and the packed cube's bytes.
  double bake_ms = 0;
  size_t cube_bytes = 0;
  std::vector<double> seam_step_mean;  // per lod 0..log2(n): mean |f(face A) - f(face B)| (RGB 2-norm)
  std::vector<double> seam_step_max;
  std::vector<double> seam_step_half_lod;  // the mean at lod 0.5, 1.5, .., log2(n) - 0.5
  // At lod 0: the one-sided slopes (per level-0 texel) from points 0.25 and 0.75 texel inside
  // each face; the jump is slope_B - slope_A (oriented from A to B) minus the environment's own
  // jump there, mean of its RGB 2-norm. Stretch and warp trade the zero-order seam for this.
  double first_order_jump = 0;
  double environment_first_order_jump = 0;  // the analytic environment's own mean |jump|
  // At lod 0, the first-order error of the band one level-0 texel either side of the edge, where
  // clamped taps flatten the lookup (every method that clamps: a slope of zero over the last half
  // texel of each face): lookups 1/8 texel apart on a path straight across the edge, and the mean
  // RGB 2-norm of (lookup slope - environment slope) per level-0 texel over the steps within each
  // face. The jump above compares two slopes and misses the flat band; this sees it.
  double first_order_band = 0;
  double environment_band_slope = 0;  // the environment's own mean |slope| over the same steps
};
EdgeMeasures measure_cube_edges(ClRuntime& runtime, const Environment& environment, CubeMethod method, int size,
                                int points = 32);

// The analytic reference of a frame of a scene with an environment: rendered at `scale` times
// the width and height with 1 sample per pixel, each sample the environment along its lookup
// direction (a mirror's exactly; a glossy one's averaged over a disk of half-angle roughness / 2,
// the footprint the lookup widens by), then box-averaged over scale x scale. `cube_edge` marks the
// pixels whose samples select more than one cube face (their footprint crosses a cube edge) and
// lie within 0.25 radians of each other (not a silhouette, whose error is not the seam's).
struct CubeReference {
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;
  std::vector<uint8_t> cube_edge;
  size_t edge_pixels = 0;
};
CubeReference cube_reference(Renderer& renderer, const Camera& camera, const RenderOptions& options, int scale = 8);

// Each pixel's environment lookup direction at its centre, unit length, rows top first: a frame of
// the loaded scene (which has an environment) at `camera` and options' size through
// render_directions at one sample, pixel shading; a reflective face's reflected view ray, the
// skybox's view ray. Zero for a pixel that looks nothing up: a diffuse face, or no triangle and
// no skybox.
std::vector<glm::vec3> lookup_directions(Renderer& renderer, const Camera& camera, const RenderOptions& options);

// The pixels a cube edge crosses: per pixel of a width x height image of lookup directions (rows
// top first; zero: no lookup), 1 where the pixel and its right or its lower neighbour both look
// up, their directions select different cube faces (cube_coords) and lie within 0.25 radians of
// each other (the same as cube_reference's cube_edge: a silhouette between a reflection and the
// sky is not a cube edge), 0 elsewhere.
std::vector<uint8_t> cube_edge_pixels(const std::vector<glm::vec3>& directions, int width, int height);

}  // namespace seamcl
