// What a displacement method costs and whether it is watertight: the exact position gap between
// vertices that two patches share, crack pixels on a closed mesh whose back faces are a flag, and the
// samples and bytes each method spends.
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
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
  // The displaced surface's normal at each copy of a point on a patch boundary (the normals
  // given, else displaced_normal), each copy's against the first's (lowest patch): the largest
  // coordinate difference of the unit normals, and the points where any differs.
  double max_normal_gap = 0.0;
  size_t differing_normals = 0;
};
// `normals`: one per vertex, the device's (TessellateLauncher::tessellate_normals, what a
// displaced render's shading interpolates); null: displaced_normal of each copy.
DisplacementGap measure_gap(const PackedDisplacement& packed, const std::vector<TessVertex>& vertices,
                            const std::vector<cl_float4>* normals = nullptr);

// The unit normal of the displaced surface at grid point (i, j) of `patch`, as that patch computes
// it: the area-weighted sum of the micro-triangles around the point, its own and, for a point on
// a shared edge or at a mesh vertex, those of the patches that hold a copy of it (found by
// topology, as measure_gap pairs them), each at its own vertices except the point itself, which is
// this patch's copy. The triangles are summed in one order whichever patch asks (by patch, then
// cell), so two patches whose copies of the point and of its ring agree bit for bit get the same
// bits: a watertight method's normals agree across every edge exactly, and where the positions
// differ (naive) the normals differ with them. Float arithmetic, as the kernel does it: the twin of
// kernels/tessellate.cl's displaced_normals, whose normals light displaced renders.
std::array<float, 3> displaced_normal(const PackedDisplacement& packed, const std::vector<TessVertex>& vertices,
                                      int patch, int i, int j);

// Whether every edge of the mesh is shared by exactly two faces (a closed mesh: crack pixels can
// be counted on it).
bool is_closed_mesh(const Scene& scene);

// The displaced surface as plain faces, for counting cracks on any closed mesh: every micro-quad
// of `vertices` (the tessellator's output, patch-major, (T+1)^2 a patch) as a face split on the
// tessellator's own diagonal, so it rasterises as the displaced render does, the patches'
// vertices not merged, so every gap stays open; then the same quads reversed, in the flag colour.
// Of a quad and its reverse exactly one faces the camera: the render is the surface with its back
// faces drawn as the flag. Along a ray from outside, the nearest surface of a closed watertight
// mesh is a front face whatever its shape (the ray must enter the solid before it can see its
// inside), so a sample whose winner is a flag face looks through a crack. No centre or inside
// point is assumed. The first half of the faces are the surface (patches * T^2 of them, fewer
// when adaptive slots leave cells without area, which are left out of both halves). Front faces are tinted per patch
// (the patches' borders show in an image); no displacement, albedo or environment is kept.
// A back face can also win a sample without a crack, where the displaced surface intersects
// itself or a fold's back face meets a front face on a silhouette edge (equal depths there,
// decided by the 1/w planes' rounding): count_crack_pixels tells those apart.
// `tessellation` is the slot grid's T (PackedDisplacement::params); `adaptive` splits the cells
// the adaptive tessellator splits the other way (PackedDisplacement::adaptive).
Scene with_back_faces_flagged(const Scene& scene, const std::vector<TessVertex>& vertices, int tessellation,
                              bool adaptive = false);
inline const glm::vec3 kFlagColor{1.0f, 0.0f, 1.0f};

// The device's tessellation of `scene` with options.displacement (required), T and level: the
// vertices every render of those options displaces to (patch-major, (T+1)^2 a patch). With
// options.tessellation_pixels, the screen-space factors of `camera` (null: the scene's camera).
std::vector<TessVertex> tessellate_displacement(ClRuntime& runtime, const Scene& scene, const RenderOptions& options,
                                                const Camera* camera = nullptr);

// The options of the crack renders of `options`: its size and samples (the coverage counted),
// no displacement (the scene is already displaced), and the plainest colour lookup, which reads
// no adjacency (the micro-quads have none worth building).
RenderOptions crack_render_options(const RenderOptions& options);

// Pixels (of width x height, sample_count samples each) where some sample's winner (read back in
// input order, 2 triangles a face) belongs to a face >= first_flag_face.
size_t count_flag_pixels(const std::vector<uint32_t>& sample_triangles, int width, int height, int sample_count,
                         size_t first_flag_face);

// Of the pixels count_flag_pixels finds in a render of `flagged` (with_back_faces_flagged) at
// `frame` (Renderer::last_frame_params), those where the surface is open: some flag-won sample
// is covered by a different number of front faces than of flag (back) faces. Along any ray from
// outside, a closed surface is entered as often as it is left, even where it folds or intersects
// itself (where a back face can win a sample without a crack); with shared edges rasterised from
// the same snapped vertices the top-left rule keeps that balance sample by sample, so only a gap
// breaks it. Coverage from the setup twin (setup_triangles_reference) of the faces near those
// pixels, the same records the device made.
size_t count_crack_pixels(const Scene& flagged, const FrameParams& frame, const std::vector<uint32_t>& sample_triangles,
                          size_t first_flag_face);
// The same pixels as a mask: per pixel (rows top first), 1 where count_crack_pixels counts one,
// 0 elsewhere; count_crack_pixels is its sum.
std::vector<uint8_t> crack_pixel_mask(const Scene& flagged, const FrameParams& frame,
                                      const std::vector<uint32_t>& sample_triangles, size_t first_flag_face);

// The crack pixels of one frame, as measure_displacement counts them for `camera` (orbit_frames
// 0): `scene` (a closed mesh, is_closed_mesh) tessellated by the device with
// options.displacement (required; adaptive factors from `camera`), drawn with its back faces
// flagged (with_back_faces_flagged) at crack_render_options(options), crack_pixel_mask of that
// frame. Its Renderer is held to `device_byte_limit` (0: none). InputError("scene") for an open
// mesh, whose background shows past its boundary without any crack.
std::vector<uint8_t> frame_crack_pixels(ClRuntime& runtime, const Scene& scene, const Camera& camera,
                                        const RenderOptions& options, size_t device_byte_limit = 0);

struct DisplacementReport {
  std::string method;
  int tessellation = 0;
  int level = 0;
  DisplacementGap gap;
  std::optional<size_t> crack_pixels;  // summed over crack_frames; empty for an open mesh
  int crack_frames = 0;
  size_t samples = 0;          // displacement samples per frame (all vertices)
  size_t vertices = 0;
  size_t triangles = 0;          // micro-triangles set up: patches * 2 * slots^2
  size_t surface_triangles = 0;  // of those, not degenerate (fewer with adaptive factors)
  int slots = 0;                 // the slot grid's T: tessellation, or adaptive the largest factor
  std::optional<float> tessellation_pixels;  // adaptive: the target; empty: uniform
  size_t extra_bytes = 0;      // the method's per-patch data (PackedDisplacement::method_bytes)
  size_t matched_samples = 0;  // fixed: samples its edge matching changed
  size_t unmatched_edges = 0;
  double tessellate_ms = 0.0;  // per frame, median
  double frame_ms = 0.0;       // whole frame, median
  nlohmann::json to_json() const;
};

// Every level of a run checked before its first render: InputError("tessellation") for a T outside
// 1..64 or one whose micro-triangles (patches * 2 * T^2, the patches doubled for a closed mesh,
// whose crack renders add the reversed copy: with_back_faces_flagged) exceed the renderer's bound.
void check_tessellation_levels(const Scene& scene, const std::vector<int>& levels);

// Measures options.displacement (required) on `scene` at `camera`, or over `frames` frames of
// its orbit when frames > 0: the gap (and the normal gap, of the device's displaced_normals) from
// the device's tessellation, crack pixels from renders
// of with_back_faces_flagged on those same vertices (closed meshes only; count_crack_pixels),
// time per frame from `repeat` renders of the scene itself (median; repeat 0 leaves the times 0
// for a caller that times its own renders).
// Its Renderers are held to `device_byte_limit` (Renderer::set_device_byte_limit; 0: none).
DisplacementReport measure_displacement(ClRuntime& runtime, const Scene& scene, const Camera& camera,
                                        const RenderOptions& options, int orbit_frames = 0, int repeat = 1,
                                        size_t device_byte_limit = 0);

}  // namespace seamcl
