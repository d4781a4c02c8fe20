// Scalar twin of kernels/triangle_setup.cl: the same clipping, snapping, culling, edge functions
// and attribute planes, one triangle at a time.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/packed_scene.h>

namespace seamcl {

// All SEAMCL_CLIP_SLOTS records of every input triangle in input order (record t * SEAMCL_CLIP_SLOTS
// + k), the order Renderer::read_setups returns; the device stores them slot-major. cull_sampleless
// false keeps the triangles whose bounding box holds no sample (the kernel culls them), for the
// test that they cover none.
std::vector<TriangleSetup> setup_triangles_reference(const PackedScene& scene, const FrameParams& frame,
                                                     bool cull_sampleless = true);

// How many input triangles triangle_setup.cl's early cull stops before the
// full setup, by rule. FrameStats.early_culled must equal their total.
struct EarlyCullCounts {
  size_t unclipped = 0;        // inside the near plane and the guard band, whose snapped vertices
                               // face away, have zero area, or lie all past one image side
  size_t outside_a_plane = 0;  // all three vertices outside one clip plane
  size_t total() const { return unclipped + outside_a_plane; }
};
EarlyCullCounts early_culled_reference(const PackedScene& scene, const FrameParams& frame);

// Whether the fixed-point box [min_x, max_x] x [min_y, max_y] holds a position of one of the
// frame's samples (sample_count's pattern) in the image: setup culls triangles whose box holds none.
bool box_holds_sample(int64_t min_x, int64_t max_x, int64_t min_y, int64_t max_y, const FrameParams& frame);

inline bool setup_is_empty(const TriangleSetup& s) {
  return s.bbox_max_x < s.bbox_min_x || s.bbox_max_y < s.bbox_min_y;
}

// Whether the fixed-point point (x, y) is inside (edge functions all >= 0; top-left rule included).
inline bool setup_covers(const TriangleSetup& s, int64_t x, int64_t y) {
  for (int i = 0; i < 3; ++i) {
    if (int64_t{s.edge_a[i]} * x + int64_t{s.edge_b[i]} * y + s.edge_c[i] < 0) return false;
  }
  return true;
}

}  // namespace seamcl
