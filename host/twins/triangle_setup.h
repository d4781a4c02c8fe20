// Scalar twin of kernels/triangle_setup.cl: the same clipping, snapping, culling, edge functions
// and attribute planes, one triangle at a time.
#pragma once
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/packed_scene.h>

namespace seamcl {

// All SEAMCL_CLIP_SLOTS records of every input triangle, in the kernel's order.
std::vector<TriangleSetup> setup_triangles_reference(const PackedScene& scene, const FrameParams& frame);

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
