/* The D3D11 standard sample pattern, shared by the stages that place samples: setup's cull,
 * raster's coverage and shade_resolve's shading positions. A header of its own so that each of
 * their programs holds the one table (host twin: host/pipeline/stages/sample_pattern.cpp). */
#ifndef SEAMCL_SAMPLE_PATTERN_H
#define SEAMCL_SAMPLE_PATTERN_H

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

#endif
