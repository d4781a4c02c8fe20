// The overlay job: the debug layers of a frame the viewer draws over its images, from the
// library's own outputs: the seam mask (pixels whose texture footprints cross an edge shared by two
// faces, or a mesh boundary only; kernels/shade_resolve.cl built with SEAMCL_SEAM_MASK), the
// face edges (pixels whose samples, or whose right or lower neighbour's, belong to another face;
// from the frame's sample winners and setups), the crack pixels of a displaced closed mesh (the
// pixels the displacement metrics count for this frame: eval/displacement_metrics.h,
// frame_crack_pixels) and the cube edges of a scene with an environment (pixels whose lookup
// direction selects another cube face than their right or lower neighbour's:
// eval/cube_metrics.h, cube_edge_pixels). What POST /v1/overlays runs.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/jobs/job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Per pixel, a byte of these bits.
constexpr uint8_t kOverlaySeam = 1;       // the seam mask's seam pixels
constexpr uint8_t kOverlayBoundary = 2;   // the seam mask's boundary-only pixels
constexpr uint8_t kOverlayFaceEdge = 4;   // a face edge crosses the pixel or its right or lower side
constexpr uint8_t kOverlayCrack = 8;      // the background or a back face shows through a crack
constexpr uint8_t kOverlayCubeEdge = 16;  // a cube edge crosses the pixel or its right or lower side

// Face edges of a frame from its sample winners (sample_count per pixel) and the winners' setups:
// kOverlayFaceEdge where the pixel's covered samples lie on more than one face, or where its face
// (its first covered sample's) differs from its right or lower neighbour's and both are covered.
std::vector<uint8_t> face_edge_pixels(const FrameParams& frame, const std::vector<TriangleSetup>& setups,
                                      const std::vector<uint32_t>& sample_triangles);

class OverlayJob {
 public:
  // A render request (no repeat, crack_orbit, export_mesh); InputError naming the field. The seam
  // mask is measured on the faces' own texels: method guardband is refused (field "method").
  explicit OverlayJob(const nlohmann::json& request);

  const RenderJob& render_job() const { return render_; }
  const RenderOptions& options() const { return render_.options(); }
  // The render's plan; where the crack layer applies (crack_pixels_apply), its crack render's
  // Renderer added (held beside the render's: with_back_faces_flagged's micro-quads at the
  // request's T, crack_render_options).
  JobPlan plan(const Scene& scene, size_t held_scene_bytes = 0) const;

  // Whether a layer applies to the frame of `scene`: crack pixels to a closed mesh with
  // displacement maps rendered with a displacement_method, cube edges to a scene with an
  // environment. A layer that does not apply is all zeros, its count 0.
  bool crack_pixels_apply(const Scene& scene) const;
  static bool cube_edges_apply(const Scene& scene) { return scene.environment.has_value(); }

  // {"width", "height", "layers": {"seam": 1, "boundary": 2, "face_edge": 4, "crack": 8, "cube_edge": 16},
  //  "counts": {layer: pixels}, "pixels": base64 of width * height bytes, rows top first, each the
  //  OR of its layers' bits}. `runtime` makes the crack render's Renderer.
  nlohmann::json run(ClRuntime& runtime, Renderer& renderer, const Scene& scene, const JobControl& control) const;

 private:
  RenderJob render_;
};

}  // namespace seamcl
