// What a displacement method costs and whether it is watertight: the exact position gap between
// vertices that two patches share, crack pixels on a closed mesh whose inside is a flag, and the
// samples and bytes each method spends.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

struct PackedDisplacement;  // pipeline/displacement_packing.h

// Vertices that two patches (or all patches at a mesh vertex) make for the same surface point:
// found by topology (the same step along a shared edge, seen from either side; the same mesh
// vertex), never by distance, so nothing is hidden by a tolerance.
struct DisplacementGap {
  double max_gap = 0.0;        // largest |a - b| over coordinates of such pairs (exact: float differences held in double)
  size_t compared_pairs = 0;   // pairs compared
  size_t differing_pairs = 0;  // pairs whose positions are not equal coordinate by coordinate
  double max_edge_gap = 0.0;   // max_gap over the pairs inside shared edges (not at their ends)
  double max_corner_gap = 0.0; // max_gap over the pairs at mesh vertices
};
DisplacementGap measure_gap(const PackedDisplacement& packed, const std::vector<TessVertex>& vertices);

// Whether every edge of the mesh is shared by exactly two faces (a closed mesh: crack pixels can
// be counted on it).
bool is_closed_mesh(const Scene& scene);

// The scene plus its flag: a copy of the mesh shrunk by `shrink` about the mean of its
// positions, with reversed faces (so their inside faces the camera) in a constant flag colour and
// without displacement. Seen from outside, the flag is hidden by any watertight surface around it;
// every sample that shows it looks through a crack. The flag's faces come after the scene's.
Scene with_flag_shell(const Scene& scene, float shrink = 0.5f);
inline const glm::vec3 kFlagColor{1.0f, 0.0f, 1.0f};

// Pixels (of width x height, sample_count samples each) where some sample's winning slot belongs
// to a patch >= first_flag_patch, with T the render's tessellation.
size_t count_flag_pixels(const std::vector<uint32_t>& sample_triangles, int width, int height, int sample_count,
                         int tessellation, size_t first_flag_patch);

struct DisplacementReport {
  std::string method;
  int tessellation = 0;
  int level = 0;
  DisplacementGap gap;
  std::optional<size_t> crack_pixels;  // summed over crack_frames; empty for an open mesh
  int crack_frames = 0;
  size_t samples = 0;          // displacement samples per frame (all vertices)
  size_t vertices = 0;
  size_t triangles = 0;
  size_t extra_bytes = 0;      // the method's per-patch data (PackedDisplacement::method_bytes)
  size_t matched_samples = 0;  // fixed: samples its edge matching changed
  size_t unmatched_edges = 0;
  double tessellate_ms = 0.0;  // per frame, median
  double frame_ms = 0.0;       // whole frame, median
  nlohmann::json to_json() const;
};

// Every level of a run checked before its first render: InputError("tessellation") for a T outside
// 1..64 or one whose micro-triangles (patches * 2 * T^2, the patches doubled for a closed mesh,
// whose crack renders add the flag shell) exceed the renderer's bound.
void check_tessellation_levels(const Scene& scene, const std::vector<int>& levels);

// Measures options.displacement (required) on `scene` at `camera`, or over `frames` frames of
// its orbit when frames > 0: the gap from the device's tessellation, crack pixels from renders
// of with_flag_shell(scene) (closed meshes only), time per frame from `repeat` renders of the
// scene itself (median; repeat 0 leaves the times 0 for a caller that times its own renders).
// Its Renderers are held to `device_byte_limit` (Renderer::set_device_byte_limit; 0: none).
DisplacementReport measure_displacement(ClRuntime& runtime, const Scene& scene, const Camera& camera,
                                        const RenderOptions& options, int orbit_frames = 0, int repeat = 1,
                                        size_t device_byte_limit = 0);

}  // namespace seamcl
