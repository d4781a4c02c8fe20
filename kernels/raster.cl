/* Stage 3: raster. One work-item per pixel, work-groups of one tile (SEAMCL_TILE_SIZE^2): every
 * work-item of a group walks the same tile list, which keeps the loop uniform for the vectoriser.
 *
 * For each sample of the pixel (D3D11 standard positions, below), a triangle covers it iff all
 * three edge functions are >= 0 at the sample's fixed-point position (top-left rule folded into
 * edge_c by setup). Depth is 1/w from the plane: nearer is larger. The sample keeps the covering
 * triangle of largest 1/w, ties going to the lower slot index, so the result does not depend on
 * the order of the tile list. Output: sample_triangle[(y * width + x) * sample_count + s], the
 * winning slot or SEAMCL_NO_TRIANGLE.
 * Host guarantees: bin lists built for this frame; bin_entries <= bin_capacity (else it re-runs).
 * Twin: host/raster.cpp. */

/* D3D11 standard sample positions in 1/16 pixel from the pixel centre, y down; rows for 1, 2,
 * 4, 8 and 16 samples (row = log2(count)). */
__constant char sample_offsets[5][SEAMCL_MAX_SAMPLES][2] = {
    {{0, 0}},
    {{4, 4}, {-4, -4}},
    {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}},
    {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}},
    {{1, 1}, {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5}, {5, 3}, {3, -5},
     {-2, 6}, {0, -7}, {-4, -6}, {-6, 4}, {-8, 0}, {7, -4}, {6, 7}, {-7, -8}}};

SEAMCL_INLINE int sample_pattern_row(int sample_count) {
  return sample_count == 1 ? 0 : sample_count == 2 ? 1 : sample_count == 4 ? 2 : sample_count == 8 ? 3 : 4;
}

/* Fixed-point position of sample s of pixel (x, y). */
SEAMCL_INLINE long sample_fixed_x(int x, int row, int s) {
  return (long)x * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2 + sample_offsets[row][s][0] * (SEAMCL_SUBPIXEL_ONE / 16);
}
SEAMCL_INLINE long sample_fixed_y(int y, int row, int s) {
  return (long)y * SEAMCL_SUBPIXEL_ONE + SEAMCL_SUBPIXEL_ONE / 2 + sample_offsets[row][s][1] * (SEAMCL_SUBPIXEL_ONE / 16);
}

__kernel void raster(__constant FrameParams* frame, __global const TriangleSetup* setups,
                     __global const uint* tile_counts, __global const uint* tile_offsets,
                     __global const uint* tile_lists, __global uint* sample_triangle) {
  const int x = (int)get_global_id(0);
  const int y = (int)get_global_id(1);
  if (x >= frame->width || y >= frame->height) return;
  const int samples = frame->sample_count;
  const int row = sample_pattern_row(samples);
  const int tile = (y / SEAMCL_TILE_SIZE) * frame->tiles_x + x / SEAMCL_TILE_SIZE;
  const uint begin = tile_offsets[tile];
  const uint end = min(begin + tile_counts[tile], frame->bin_capacity);

  float best_depth[SEAMCL_MAX_SAMPLES];
  uint best_slot[SEAMCL_MAX_SAMPLES];
  for (int s = 0; s < samples; ++s) {
    best_depth[s] = -INFINITY;
    best_slot[s] = SEAMCL_NO_TRIANGLE;
  }
  for (uint entry = begin; entry < end; ++entry) {
    const uint slot = tile_lists[entry];
    __global const TriangleSetup* t = setups + slot;
    if (x < t->bbox_min_x || x > t->bbox_max_x || y < t->bbox_min_y || y > t->bbox_max_y) continue;
    for (int s = 0; s < samples; ++s) {
      const long px = sample_fixed_x(x, row, s);
      const long py = sample_fixed_y(y, row, s);
      const long e0 = t->edge_a[0] * px + t->edge_b[0] * py + t->edge_c[0];
      const long e1 = t->edge_a[1] * px + t->edge_b[1] * py + t->edge_c[1];
      const long e2 = t->edge_a[2] * px + t->edge_b[2] * py + t->edge_c[2];
      if ((e0 | e1 | e2) < 0) continue;
      const float fx = (float)px * (1.0f / SEAMCL_SUBPIXEL_ONE);
      const float fy = (float)py * (1.0f / SEAMCL_SUBPIXEL_ONE);
      const float depth = t->inv_w[0] + t->inv_w[1] * (fx - t->ref_x) + t->inv_w[2] * (fy - t->ref_y);
      if (depth > best_depth[s] || (depth == best_depth[s] && slot < best_slot[s])) {
        best_depth[s] = depth;
        best_slot[s] = slot;
      }
    }
  }
  __global uint* out = sample_triangle + ((size_t)y * (size_t)frame->width + (size_t)x) * (size_t)samples;
  for (int s = 0; s < samples; ++s) out[s] = best_slot[s];
}

/* The sample pattern as the raster stage uses it, for the test against the D3D11 tables. */
__kernel void sample_pattern(int sample_count, __global int* offsets_out) {
  if (get_global_id(0) != 0) return;
  const int row = sample_pattern_row(sample_count);
  for (int s = 0; s < sample_count; ++s) {
    offsets_out[2 * s] = sample_offsets[row][s][0];
    offsets_out[2 * s + 1] = sample_offsets[row][s][1];
  }
}
