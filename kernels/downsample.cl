/* The downsample stage: a high-resolution image (the reference's 8x frame, already resolved on
 * the device) reduced by an integer factor with a separable filter, so that only the small image
 * is read back. Two kernels, one pass per axis.
 *
 * Taps: output pixel o of an axis reads source pixels o * factor + first + k, k = 0..taps-1, each
 * clamped into [0, size-1] (taps beyond the edge read the edge pixel), weighted by weights[k]: the
 * same weights for every output pixel (the filter is centred on the output pixel's centre, and the
 * factor is an integer). The host computes the weights (normalised to sum 1) once:
 * host/pipeline/stages/downsample_twin.cpp, separable_taps.
 *
 * downsample_rows: one work-item per (output column ox, source row y), ox fastest: the row's taps
 *   summed into mid[y * out_width + ox].
 * downsample_columns: one work-item per output pixel (ox, oy): mid's column taps summed into
 *   out[oy * out_width + ox].
 * Each sum runs k = 0..taps-1 in order, each channel in float, a multiply then an add (no
 * contraction: seamcl_types.h), so the twin (downsample_twin) gives the same bits.
 * Host guarantees: image is width x height RGBA floats, mid out_width x height, out out_width x
 * out_height; 1 <= taps <= SEAMCL_MAX_DOWNSAMPLE_TAPS; global sizes at least the counts above
 * (rounded up to whole work-groups: the items past them return at once). */

#define SEAMCL_MAX_DOWNSAMPLE_TAPS 64

__kernel void downsample_rows(__global const float* image, int width, int height, int out_width, int factor,
                              int first, int taps, __constant float* weights, __global float* mid) {
  const int ox = (int)get_global_id(0);
  const int y = (int)get_global_id(1);
  if (ox >= out_width || y >= height) return;
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;
  const int start = ox * factor + first;
  __global const float* row = image + (size_t)y * (size_t)width * 4;
  for (int k = 0; k < taps; ++k) {
    int x = start + k;
    x = x < 0 ? 0 : (x > width - 1 ? width - 1 : x);
    const float w = weights[k];
    __global const float* p = row + (size_t)x * 4;
    r = r + w * p[0];
    g = g + w * p[1];
    b = b + w * p[2];
    a = a + w * p[3];
  }
  __global float* o = mid + ((size_t)y * (size_t)out_width + (size_t)ox) * 4;
  o[0] = r;
  o[1] = g;
  o[2] = b;
  o[3] = a;
}

__kernel void downsample_columns(__global const float* mid, int height, int out_width, int out_height, int factor,
                                 int first, int taps, __constant float* weights, __global float* out) {
  const int ox = (int)get_global_id(0);
  const int oy = (int)get_global_id(1);
  if (ox >= out_width || oy >= out_height) return;
  float r = 0.0f, g = 0.0f, b = 0.0f, a = 0.0f;
  const int start = oy * factor + first;
  for (int k = 0; k < taps; ++k) {
    int y = start + k;
    y = y < 0 ? 0 : (y > height - 1 ? height - 1 : y);
    const float w = weights[k];
    __global const float* p = mid + ((size_t)y * (size_t)out_width + (size_t)ox) * 4;
    r = r + w * p[0];
    g = g + w * p[1];
    b = b + w * p[2];
    a = a + w * p[3];
  }
  __global float* o = out + ((size_t)oy * (size_t)out_width + (size_t)ox) * 4;
  o[0] = r;
  o[1] = g;
  o[2] = b;
  o[3] = a;
}
