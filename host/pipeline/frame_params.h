// The per-frame constants of the pipeline (FrameParams): camera matrices, clip planes sized so
// that fixed-point arithmetic cannot overflow, tiles, samples and lighting.
#pragma once
#include <cstdint>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

inline constexpr float kNearPlane = 0.01f;
// Clip planes at |x|, |y| <= kGuardBand * w in NDC: one image width (height) beyond each edge.
// It bounds screen coordinates to [-W, 2W] (with sides <= 16384 the edge-function products stay
// far inside 64 bits) and so bounds how far the float attribute planes are extrapolated from
// their reference vertex (a near-plane vertex would otherwise sit millions of pixels away).
inline constexpr float kGuardBand = 3.0f;
// Setup's early cull drops a triangle whose three vertices lie outside one guard plane: a clipped
// sliver could only round back onto that plane, which must lie beyond the image's samples.
static_assert(kGuardBand >= 2.0f, "triangle_setup.cl's cull outside one plane needs the guard planes past the image");
// triangle_setup.cl's vectors add and compare snapped coordinates (within the guard band: at most
// kGuardBand image sides, in 1/SEAMCL_SUBPIXEL_ONE pixels) in 32-bit ints.
static_assert(static_cast<double>(kGuardBand) * kMaxImageSide * SEAMCL_SUBPIXEL_ONE < (1u << 30),
              "the vector setup's int box arithmetic needs snapped coordinates under 2^30");

// Binning's chunks (kernels/binning.cl): runs of about kBinChunkTriangles input triangles, each
// counted by one work-item into chunk_triangles counters of its own. At most kMaxBinChunks, and
// at most kMaxBinCounters counters in all (chunks x tiles), which bin_scan walks one by one.
inline constexpr size_t kBinChunkTriangles = 1024;
inline constexpr size_t kMaxBinChunks = 64;
inline constexpr size_t kMaxBinCounters = size_t{1} << 18;

struct BinChunks {
  size_t chunks = 0;           // 0 when there are no input triangles
  size_t chunk_triangles = 0;  // triangles per chunk, the last one's fewer
};
BinChunks bin_chunks(size_t input_triangles, size_t tiles);

glm::mat4 view_projection(const Camera& camera, int width, int height);

FrameParams make_frame_params(const Scene& scene, const Camera& camera, const RenderOptions& options,
                              uint32_t bin_capacity);

}  // namespace seamcl
