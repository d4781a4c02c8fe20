/* Batches of lookups of Ptex's own filters (`seamcl ptx lookup`, the kernel tests and the Ptex
 * benchmark): one work-item per query, ptexf_lookup of ptex_filter.cl; a batch of point lookups
 * through ptex_point_lookups, whose short loop body lets a core keep more lookups' texel misses in
 * flight.
 * Contract: out[4 * id ..] holds query id's 4 floats (channels beyond the texture's 0; a face out of
 * range gives zeros) for id < count. Host guarantees: tex, faces, level_offsets and texels as
 * ptex_filter.cl states; tex.seams 0 (Ptex's own rules); out holds 4 * count floats.
 * Twin: ptex_filter_twin in host/pipeline/stages/ptex_filter_twin.cpp. */

/* Only where ptex_filter.cl compiles: the ptex-filter program, built with no sampler variant. */
#if !defined(SEAMCL_SAMPLER_FILTER) || SEAMCL_SAMPLER_FILTER == SEAMCL_FILTER_PTEX
/* What a batch's lookups read: the texture and its buffers. */
SEAMCL_INLINE PtexfState ptexf_batch_state(PtexFilterTexture tex, __global const PtexFilterFace* faces,
                                           __global const uint* level_offsets, __global const uchar* texels) {
  PtexfState s;
  s.faces = faces;
  s.level_offsets = level_offsets;
  s.texels = texels;
  s.tex = tex;
  return s;
}

__kernel void ptex_filter_lookups(PtexFilterTexture tex, __global const PtexFilterFace* faces,
                                  __global const uint* level_offsets, __global const uchar* texels,
                                  __global const PtexFilterQuery* queries, int count, __global float* out) {
  const int id = (int)get_global_id(0);
  if (id >= count) return;
  const PtexFilterQuery q = queries[id];
  PtexfState s = ptexf_batch_state(tex, faces, level_offsets, texels);
  float value[4];
  ptexf_lookup(&s, &q, value);
  __global float* dst = out + 4 * id;
  /* Copied value by value: ptexf_lookup stores them one at a time, and one 16-byte load of them
   * would wait for those stores to leave the core (a store-to-load forward that fails), and with
   * them for every cache miss before (15% of this function's samples on a bilinear batch). */
#pragma clang loop vectorize(disable) unroll(disable)
  for (int c = 0; c < 4; ++c) dst[c] = value[c];
}

/* ptex_filter_lookups for a batch of point lookups: ptexf_point alone. A query of another filter
 * sets *not_point to 1 (atomically: many work-items may), and its 4 floats are not its lookup's:
 * the host, which runs this kernel when a batch's first query is a point lookup instead of reading
 * every query first, then runs ptex_filter_lookups over the batch.
 * Host guarantees: *not_point 0 before the launch. */
__kernel void ptex_point_lookups(PtexFilterTexture tex, __global const PtexFilterFace* faces,
                                 __global const uint* level_offsets, __global const uchar* texels,
                                 __global const PtexFilterQuery* queries, int count, __global float* out,
                                 __global int* not_point) {
  const int id = (int)get_global_id(0);
  if (id >= count) return;
  const PtexFilterQuery q = queries[id];
  if (q.filter != SEAMCL_PTEX_POINT) atomic_xchg(not_point, 1);
  const PtexfState s = ptexf_batch_state(tex, faces, level_offsets, texels);
  vstore4(ptexf_point(&s, &q), id, out);
}
#endif
