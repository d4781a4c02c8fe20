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

#if SEAMCL_ANISO_GROUPED
/* Aniso lookups grouped by probe count (built with -DSEAMCL_ANISO_GROUPED=1, SEAMCL_SAMPLER_FILTER
 * aniso and no traverse; host/pipeline/texture_lookups.cpp runs them). PoCL leaves a loop whose
 * trip count varies per work-item scalar, and with it the whole lookup; with one kernel per
 * probe count the loop is uniform, and the work-items run side by side. Pass 1 plans every
 * lookup (aniso_probes: first probe, step, lod, N); the host orders the lookups by N; pass 2
 * runs each group through the kernel of its N, which takes the same probes from the plan.
 * plans[6 i ..] = first_u, first_v, step_u, step_v, lod, weight; probe_counts[i] = N. */
__kernel void aniso_plan_batch(__global const FaceGpu* faces, SamplerParams sampler, __global const float* lookups,
                               uint count, __global float* plans, __global uchar* probe_counts) {
  const uint i = get_global_id(0);
  if (i >= count) return;
  __global const float* q = lookups + 7 * i;
  const FaceGpu face = faces[(uint)q[0]];
  const AnisoProbes p =
      aniso_probes(&face, q[1], q[2], footprint(&face, sampler.lod_bias, q[3], q[4], q[5], q[6]), sampler.max_aniso);
  __global float* o = plans + 6 * i;
  o[0] = p.first_u;
  o[1] = p.first_v;
  o[2] = p.step_u;
  o[3] = p.step_v;
  o[4] = p.lod;
  o[5] = p.weight;
  probe_counts[i] = (uchar)p.probes;
}

SEAMCL_INLINE void aniso_group_lookup(__global const FaceGpu* faces, __global const uint* level_offsets,
                                      TEXEL_BUFFER texels, __global const float* srgb_to_linear, SamplerParams sampler,
                                      __global const float* lookups, __global const float* plans,
                                      __global const uint* order, uint first, uint count, __global float4* out,
                                      int probes) {
  const uint j = get_global_id(0);
  if (j >= count) return;
  const uint i = order[first + j];
  __global const float* q = lookups + 7 * i;
  __global const float* plan = plans + 6 * i;
  const FaceGpu face = faces[(uint)q[0]];
  AnisoProbes p;
  p.probes = probes;
  p.first_u = plan[0];
  p.first_v = plan[1];
  p.step_u = plan[2];
  p.step_v = plan[3];
  p.lod = plan[4];
  p.weight = plan[5];
  FilterSum sum = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  /* Unrolled, and without accumulate_probes' skipping of probes past a border (they add zero):
   * straight-line code is what PoCL vectorises across work-items. */
  float pu = p.first_u;
  float pv = p.first_v;
#pragma unroll
  for (int k = 0; k < probes; ++k) {
    accumulate_trilinear(&sum, &face, level_offsets, texels, srgb_to_linear, pu, pv, p.lod, p.weight,
                         SAMPLER_ADDRESS(sampler));
    pu += p.step_u;
    pv += p.step_v;
  }
  const float4 c = resolve_sum(sum, &face, level_offsets, texels, srgb_to_linear, sampler, q[1], q[2], q[3], q[4],
                               q[5], q[6]);
  __global float* o = (__global float*)out + 4 * i;
  o[0] = c.x;
  o[1] = c.y;
  o[2] = c.z;
  o[3] = c.w;
}

#define SEAMCL_ANISO_GROUP_KERNEL(N)                                                                              \
  __kernel void aniso_group_batch_##N(__global const FaceGpu* faces, __global const uint* level_offsets,          \
                                      TEXEL_BUFFER texels, __global const float* srgb_to_linear,                  \
                                      SamplerParams sampler, __global const float* lookups,                       \
                                      __global const float* plans, __global const uint* order, uint first,        \
                                      uint count, __global float4* out) {                                         \
    aniso_group_lookup(faces, level_offsets, texels, srgb_to_linear, sampler, lookups, plans, order, first, count, \
                       out, N);                                                                                   \
  }
#if SEAMCL_MAX_PROBES != 16
#error "one aniso_group_batch_N kernel per probe count 1..SEAMCL_MAX_PROBES"
#endif
SEAMCL_ANISO_GROUP_KERNEL(1)
SEAMCL_ANISO_GROUP_KERNEL(2)
SEAMCL_ANISO_GROUP_KERNEL(3)
SEAMCL_ANISO_GROUP_KERNEL(4)
SEAMCL_ANISO_GROUP_KERNEL(5)
SEAMCL_ANISO_GROUP_KERNEL(6)
SEAMCL_ANISO_GROUP_KERNEL(7)
SEAMCL_ANISO_GROUP_KERNEL(8)
SEAMCL_ANISO_GROUP_KERNEL(9)
SEAMCL_ANISO_GROUP_KERNEL(10)
SEAMCL_ANISO_GROUP_KERNEL(11)
SEAMCL_ANISO_GROUP_KERNEL(12)
SEAMCL_ANISO_GROUP_KERNEL(13)
SEAMCL_ANISO_GROUP_KERNEL(14)
SEAMCL_ANISO_GROUP_KERNEL(15)
SEAMCL_ANISO_GROUP_KERNEL(16)
#endif

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
