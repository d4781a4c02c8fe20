/* Batch lookups: the samplers of texture_sample.cl and cube_sample.cl run on a list of lookups,
 * one per work-item, outside any render. The kernel tests compare them with the scalar twins
 * (host/pipeline/stages/texture_sample_twin.cpp, cube_sample_twin.cpp), and the lookup
 * benchmarks time them (host/pipeline/texture_lookups.cpp, cube_lookups.cpp run them). A file of
 * their own so that the shading program, built once per sampler variant, does not compile them.
 * Built as the sampling program, after texture_sample.cl and cube_sample.cl. */

/* FaceNeighbors' bytes as the kernels decode them, for the test against the host's decoding:
 * out[7 b ..] = decode_uv_map(b)'s six coefficients, reach_side(b), for every byte b. */
__kernel void neighbor_bytes_decoded(__global float* out) {
  const uint b = get_global_id(0);
  if (b > 255u) return;
  const UvMap m = decode_uv_map(b);
  for (int k = 0; k < 6; ++k) out[7 * b + (uint)k] = m.t[k];
  out[7 * b + 6] = reach_side(b);
}

/* Lookups for tests and benchmarks, one per work-item: lookups[7 i ..] = face (as a float), u, v,
 * dudx, dvdx, dudy, dvdy; out[i] = the lookup's colour. */
__kernel void texture_lookup_batch(__global const FaceGpu* faces, __global const FaceNeighbors* neighbors,
                                   __global const uint* level_offsets, TEXEL_BUFFER texels,
                                   __global const float* srgb_to_linear, SamplerParams sampler,
                                   __global const float* lookups, uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  __global const float* q = lookups + 7 * i;
  const float4 c = sample_texture(faces, neighbors, (uint)q[0], level_offsets, texels, srgb_to_linear, sampler, q[1], q[2],
                                  q[3], q[4], q[5], q[6]);
  __global float* o = (__global float*)out + 4 * i;
  o[0] = c.x;
  o[1] = c.y;
  o[2] = c.z;
  o[3] = c.w;
}

/* The same lookups' FilterSum before renormalisation (neighbours included for traverse):
 * (r, g, b, a) and the weight of the taps read. */
__kernel void texture_filter_batch(__global const FaceGpu* faces, __global const FaceNeighbors* neighbors,
                                   __global const uint* level_offsets, TEXEL_BUFFER texels,
                                   __global const float* srgb_to_linear, SamplerParams sampler,
                                   __global const float* lookups, uint count, __global float4* out,
                                   __global float* weights) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  __global const float* q = lookups + 7 * i;
  const uint face_index = (uint)q[0];
  const FaceGpu face = faces[face_index];
  FilterSum sum = filter_texture(&face, level_offsets, texels, srgb_to_linear, SAMPLER_FILTER(sampler),
                                 SAMPLER_ADDRESS(sampler), sampler.max_aniso, sampler.lod_bias, q[1], q[2], q[3], q[4],
                                 q[5], q[6]);
  if (SAMPLER_TRAVERSE(sampler) != SEAMCL_TRAVERSE_NONE) {
    accumulate_neighbors(&sum, faces, neighbors, face_index, level_offsets, texels, srgb_to_linear,
                         SAMPLER_FILTER(sampler), sampler.max_aniso, sampler.lod_bias,
                         SAMPLER_TRAVERSE(sampler) == SEAMCL_TRAVERSE_CORNERS, q[1], q[2], q[3], q[4], q[5], q[6]);
  }
  out[i] = (float4)(sum.r, sum.g, sum.b, sum.a);
  weights[i] = sum.weight;
}

/* Lookups for tests and measurements, one per work-item: lookups[11 i ..] = direction (3),
 * d/dx (3), d/dy (3), roughness, explicit lod (< 0: from the footprint); out[i] = the colour. */
__kernel void cube_lookup_batch(__global const float* texels, CubeSampler cube, __global const float* lookups,
                                uint count, __global float4* out) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  __global const float* q = lookups + 11 * i;
  const float4 c = sample_cube(texels, cube, q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7], q[8], q[9], q[10]);
  __global float* o = (__global float*)out + 4 * i;
  o[0] = c.x;
  o[1] = c.y;
  o[2] = c.z;
  o[3] = c.w;
}
