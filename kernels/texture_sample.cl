/* Texture lookups over the per-face texel buffer (not a stage of its own: the shade stage calls it).
 *
 * Inputs: a FaceGpu (level sizes and the index of its level table), level_offsets (first texel of
 * each level in `texels`), texels as RGBA8 sRGB packed r | g << 8 | b << 16 | a << 24, and a
 * 256-entry table of the sRGB-to-linear decode (the host fills it: one definition of the decode).
 * Coordinates: uv in face space, texel (i, j) of a W x H level centred at ((i+.5)/W, (j+.5)/H);
 * derivatives are d(uv)/d(pixel). Filtering happens in linear RGB.
 * Host guarantees: every face has a full chain down to 1x1; the offsets are in range.
 * Twin: host/texture_sample.cpp. */

inline float4 decode_texel(uint packed, __global const float* srgb_to_linear) {
  return (float4)(srgb_to_linear[packed & 0xffu], srgb_to_linear[(packed >> 8) & 0xffu],
                  srgb_to_linear[(packed >> 16) & 0xffu], (float)(packed >> 24) * (1.0f / 255.0f));
}

/* Bilinear at (u, v) on one level, taps clamped to the level's edge texels. */
inline float4 bilinear_clamp(__global const uint* texels, __global const float* srgb_to_linear,
                             uint level_offset, int width, int height, float u, float v) {
  /* Keep far-away coordinates finite and in int range; clamping makes them equivalent. */
  const float x = fmin(fmax(u * (float)width - 0.5f, -1.0f), (float)width);
  const float y = fmin(fmax(v * (float)height - 0.5f, -1.0f), (float)height);
  const float x_floor = floor(x);
  const float y_floor = floor(y);
  const float fx = x - x_floor;
  const float fy = y - y_floor;
  const int x0 = clamp((int)x_floor, 0, width - 1);
  const int x1 = clamp((int)x_floor + 1, 0, width - 1);
  const int y0 = clamp((int)y_floor, 0, height - 1);
  const int y1 = clamp((int)y_floor + 1, 0, height - 1);
  const float4 t00 = decode_texel(texels[level_offset + (uint)(y0 * width + x0)], srgb_to_linear);
  const float4 t10 = decode_texel(texels[level_offset + (uint)(y0 * width + x1)], srgb_to_linear);
  const float4 t01 = decode_texel(texels[level_offset + (uint)(y1 * width + x0)], srgb_to_linear);
  const float4 t11 = decode_texel(texels[level_offset + (uint)(y1 * width + x1)], srgb_to_linear);
  return (t00 * (1.0f - fx) + t10 * fx) * (1.0f - fy) + (t01 * (1.0f - fx) + t11 * fx) * fy;
}

/* Level of detail of a footprint: log2 of the longer screen axis in level-0 texels, clamped to
 * [0, level_count - 1]. NaN or infinite derivatives select the coarsest level. */
inline float trilinear_lod(const FaceGpu* face, float dudx, float dvdx, float dudy, float dvdy) {
  const float w = (float)face->width;
  const float h = (float)face->height;
  const float len_x = (dudx * w) * (dudx * w) + (dvdx * h) * (dvdx * h);
  const float len_y = (dudy * w) * (dudy * w) + (dvdy * h) * (dvdy * h);
  const float rho_squared = fmax(len_x, len_y);
  const float max_lod = (float)(face->level_count - 1);
  if (!(rho_squared < INFINITY)) return max_lod;
  /* log2(rho) = 0.5 * log2(rho^2) */
  return fmin(fmax(0.5f * log2(fmax(rho_squared, 1e-30f)), 0.0f), max_lod);
}

/* Trilinear lookup with clamp addressing: the baseline the method issue replaces. */
inline float4 sample_trilinear_clamp(const FaceGpu* face, __global const uint* level_offsets,
                                     __global const uint* texels, __global const float* srgb_to_linear,
                                     float u, float v, float dudx, float dvdx, float dudy, float dvdy) {
  const float lod = trilinear_lod(face, dudx, dvdx, dudy, dvdy);
  const int level0 = (int)lod;
  const int level1 = min(level0 + 1, face->level_count - 1);
  const float t = lod - (float)level0;
  const float4 c0 = bilinear_clamp(texels, srgb_to_linear, level_offsets[face->level_table + (uint)level0],
                                   max(face->width >> level0, 1), max(face->height >> level0, 1), u, v);
  if (t == 0.0f) return c0;
  const float4 c1 = bilinear_clamp(texels, srgb_to_linear, level_offsets[face->level_table + (uint)level1],
                                   max(face->width >> level1, 1), max(face->height >> level1, 1), u, v);
  return c0 * (1.0f - t) + c1 * t;
}

/* Batch of lookups for tests and benchmarks: one per work-item.
 * lookups[i] = (face, u, v, dudx, dvdx, dudy, dvdy) as 7 floats (face stored as a float index). */
__kernel void texture_lookup_batch(__global const FaceGpu* faces, __global const uint* level_offsets,
                                   __global const uint* texels, __global const float* srgb_to_linear,
                                   __global const float* lookups, uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  __global const float* q = lookups + 7 * i;
  const FaceGpu face = faces[(uint)q[0]];
  out[i] = sample_trilinear_clamp(&face, level_offsets, texels, srgb_to_linear, q[1], q[2], q[3], q[4], q[5], q[6]);
}
