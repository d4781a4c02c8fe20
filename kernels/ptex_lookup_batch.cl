/* Batches of lookups of Ptex's own filters (`seamcl ptx lookup`, the kernel tests and the Ptex
 * benchmark): ptex_filter_lookups, SEAMCL_PTEX_LOOKUP_LANES queries per work-item, the bilinear and
 * box lookups that stay in their face or cross one edge as vector lanes (ptexf_small_lanes) and
 * the rest by ptexf_lookup of ptex_filter.cl; a batch of point lookups through ptex_point_lookups, one query
 * per work-item. Both keep a core's texel misses of many lookups in flight: the lanes' loads wait
 * on no branch, and the point kernel's loop body is short.
 * Contract: out[4 * id ..] holds query id's 4 floats (channels beyond the texture's 0; a face out of
 * range gives zeros) for id < count. Host guarantees: tex, faces, level_offsets and texels as
 * ptex_filter.cl states; tex.seams 0 (Ptex's own rules); out holds 4 * count floats;
 * ptex_filter_lookups' global size at least count / SEAMCL_PTEX_LOOKUP_LANES rounded up.
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

#define PTEXF_LANES SEAMCL_PTEX_LOOKUP_LANES

/* One axis of a lane's bilinear or box kernel as ptexf_build and ptexf_strip_zeros make it, at most
 * 3 taps: the first texel *first, the tap count *taps and the weights w0, w1, w2 (0 past the
 * count). A lane whose first weight is still 0 has a weight of 0 (the caller leaves it). */
SEAMCL_INLINE void ptexf_small_axis(int16 box, float16 x, float16 width, int16 face_log2, int16* res_log2,
                                    int16* first, int16* taps, float16* w0, float16* w1, float16* w2) {
  width = fmax(fmin(width, 1.0f), as_float16((127 - face_log2) << 23));
  *res_log2 = 127 - ((as_int16(width) >> 23) & 0xff);
  const float16 res = as_float16((127 + *res_log2) << 23);
  /* Bilinear: two taps around x. */
  const float16 pix = x * res - 0.5f;
  const float16 pix_floor = floor(pix);
  const float16 frac = pix - pix_floor;
  /* Box: the texels [x - width / 2, x + width / 2) touches, partly at either end. */
  const float16 centre = x * res, span = width * res;
  const float16 lo = centre - 0.5f * span, hi = centre + 0.5f * span;
  const float16 lo_floor = floor(lo), hi_ceil = ceil(hi);
  const float16 f1 = 1.0f - (lo - lo_floor), f2 = 1.0f - (hi_ceil - hi);
  const int16 box_taps = min(convert_int16(hi_ceil - lo_floor), 3);
  int16 start = convert_int16(select(pix_floor, lo_floor, box));
  int16 count = select((int16)(2), box_taps, box);
  float16 a = select(1.0f - frac, select(f1, f1 + f2 - 1.0f, box_taps == 1), box);
  float16 b = select(frac, select(select(1.0f, f2, box_taps == 2), (float16)(0.0f), box_taps == 1), box);
  float16 c = select((float16)(0.0f), f2, box && box_taps == 3);
  /* ptexf_strip_zeros: a weight of 0 at either end (frac or a box end rounded to a whole texel) is
   * no tap, so it neither crosses an edge nor reads a texel that 0 times itself could make NaN. */
  const int16 lead = a == 0.0f;
  start = select(start, start + 1, lead);
  count = select(count, count - 1, lead);
  a = select(a, b, lead);
  b = select(b, c, lead);
  c = select(c, (float16)(0.0f), lead);
  count = select(count, (int16)(2), count == 3 && c == 0.0f);
  count = select(count, (int16)(1), count == 2 && b == 0.0f);
  *first = start;
  *taps = count;
  *w0 = a;
  *w1 = b;
  *w2 = c;
}

/* The records of faces index[0 ..] (a lane each): resolution, flags and first level offset. */
SEAMCL_INLINE void ptexf_gather_faces(const PtexfState* s, const int* index, int* ulog2, int* vlog2, int* flags,
                                      int* level_base) {
  for (int i = 0; i < PTEXF_LANES; ++i) {
    __global const PtexFilterFace* f = s->faces + index[i];
    ulog2[i] = f->ulog2;
    vlog2[i] = f->vlog2;
    flags[i] = (int)f->flags;
    level_base[i] = (int)f->level_base;
  }
}

/* The bilinear and box lookups among queries[first ..] (n of them, n <= PTEXF_LANES) whose taps
 * (at most 3x3) lie inside their face or past one of its edges, a lane each, in vectors over the
 * lanes. Returns which lanes it looked up (-1) and their 4 values each in values[4 * lane ..];
 * ptexf_lookup takes the rest: taps past a corner, a boundary or both sides of a face, a coarser
 * neighbour, the tangent-vector edge mode across a turn, a constant face under the point. A lane's
 * kernel is ptexf_build's and its weight ptexf_weight's; taps past an edge are read on the
 * neighbour there, turned into its frame, as ptexf_split_and_apply reads them, and the taps past a
 * kernel's count weigh 0 and read its last texel again. The sums are ptexf_sum_taps's, in its
 * order, over the kernel's taps on both faces at once, so the values are ptexf_lookup's but for
 * rounding (fused multiply-adds; where a kernel crosses an edge, its pieces summed together).
 * Scalar loads gather each lane's query, face records, level offsets and taps; the rest is vector
 * arithmetic that PoCL does not make of ptexf_lookup's branches and loops (its work-group loop
 * stays scalar there), and no branch waits on a lane's texels, so a core keeps many lanes' misses
 * in flight. Width-4 kernels (4 to 8 taps an axis) stay with ptexf_lookup, whose rows are read 16
 * values at a time: gathered tap by tap they were slower (docs/performance.md). */
SEAMCL_INLINE int16 ptexf_small_lanes(const PtexfState* s, __global const PtexFilterQuery* queries, int first, int n,
                                      float* values) {
  int face_a[PTEXF_LANES], filter_a[PTEXF_LANES];
  float u_a[PTEXF_LANES], v_a[PTEXF_LANES], uw_a[PTEXF_LANES], vw_a[PTEXF_LANES];
  for (int i = 0; i < PTEXF_LANES; ++i) {
    __global const PtexFilterQuery* q = queries + first + min(i, n - 1);
    face_a[i] = q->face;
    filter_a[i] = q->filter;
    u_a[i] = q->u;
    v_a[i] = q->v;
    uw_a[i] = q->uw;
    vw_a[i] = q->vw;
  }
  const int16 lane = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  const int16 face = vload16(0, face_a), filter = vload16(0, filter_a);
  const int16 in_range = face >= 0 && face < s->tex.face_count;
  const int16 box = filter == SEAMCL_PTEX_BOX;
  /* In [0, 1) every border mode leaves (u, v) as it is. */
  const float16 u = vload16(0, u_a), v = vload16(0, v_a);
  int16 inside = lane < n && in_range && (filter == SEAMCL_PTEX_BILINEAR || box) && u >= 0.0f && u < 1.0f &&
                 v >= 0.0f && v < 1.0f;
  /* Under a render's seam methods (not the batch's) every edge is a boundary: ptexf_lookup's. */
  if (s->tex.seams != SEAMCL_PTEX_SEAMS_PTEX || !any(inside)) return inside && s->tex.seams == SEAMCL_PTEX_SEAMS_PTEX;
  int face_index_a[PTEXF_LANES];
  vstore16(select((int16)(0), face, inside), 0, face_index_a);
  int ulog2_a[PTEXF_LANES], vlog2_a[PTEXF_LANES], flags_a[PTEXF_LANES], base_a[PTEXF_LANES];
  ptexf_gather_faces(s, face_index_a, ulog2_a, vlog2_a, flags_a, base_a);
  const int16 face_vlog2 = vload16(0, vlog2_a);
  inside = inside && (vload16(0, flags_a) & (int)(SEAMCL_PTEX_FLAG_CONSTANT | SEAMCL_PTEX_FLAG_NEIGHBORHOOD_CONSTANT)) == 0;
  int16 ulog2, vlog2, utaps, vtaps, ufirst, vfirst;
  float16 ku0, ku1, ku2, kv0, kv1, kv2;
  /* The other lanes' coordinates may be anything (NaN, infinite): 0.5 keeps their conversions to
   * integers defined. */
  ptexf_small_axis(box, select((float16)(0.5f), u, inside), fabs(vload16(0, uw_a)), vload16(0, ulog2_a), &ulog2,
                   &ufirst, &utaps, &ku0, &ku1, &ku2);
  ptexf_small_axis(box, select((float16)(0.5f), v, inside), fabs(vload16(0, vw_a)), face_vlog2, &vlog2, &vfirst, &vtaps,
                   &kv0, &kv1, &kv2);
  const int16 ku = select((int16)(0), ufirst, inside), kv = select((int16)(0), vfirst, inside);
  const int16 resu = (int16)(1) << ulog2, resv = (int16)(1) << vlog2;
  /* Taps past one edge are read on the neighbour there, turned into its frame, as ptexf_split_and_apply
   * reads them; past two edges (a corner, or both sides of a face narrower than the kernel) or past
   * a boundary, the lane is ptexf_lookup's. */
  const int16 past_left = ku < 0, past_right = ku + utaps > resu, past_bottom = kv < 0, past_top = kv + vtaps > resv;
  const int16 across_u = past_left || past_right, across_v = past_bottom || past_top;
  inside = inside && !(past_left && past_right) && !(past_bottom && past_top) && !(across_u && across_v);
  const int16 crossing = inside && (across_u || across_v);
  int16 edge = select((int16)(PTEXF_BOTTOM), (int16)(PTEXF_LEFT), past_left);
  edge = select(select(edge, (int16)(PTEXF_TOP), past_top), (int16)(PTEXF_RIGHT), past_right);
  int next_a[PTEXF_LANES], next_edge_a[PTEXF_LANES], edge_a[PTEXF_LANES];
  vstore16(edge, 0, edge_a);
  for (int i = 0; i < PTEXF_LANES; ++i) {
    const PtexFilterFace f = s->faces[face_index_a[i]];
    next_a[i] = ptexf_adj_face(f, edge_a[i]);
    next_edge_a[i] = ptexf_adj_edge(f, edge_a[i]);
  }
  const int16 next = vload16(0, next_a);
  inside = inside && (!crossing || next >= 0);
  int next_index_a[PTEXF_LANES];
  vstore16(select((int16)(0), next, crossing && inside), 0, next_index_a);
  ptexf_gather_faces(s, next_index_a, ulog2_a, vlog2_a, flags_a, next_a);
  /* ptexf_rotate's quarter turns: the kernel's resolution in the neighbour's frame. */
  const int16 turns = (edge - vload16(0, next_edge_a) + 2) & 3;
  const int16 odd = (turns & 1) != 0;
  const int16 next_ulog2 = select(ulog2, vlog2, odd), next_vlog2 = select(vlog2, ulog2, odd);
  const int16 next_face_vlog2 = vload16(0, vlog2_a);
  /* A constant neighbour holds one texel, read by every tap there (ptexf_apply's constant case). */
  const int16 next_constant = (vload16(0, flags_a) & (int)SEAMCL_PTEX_FLAG_CONSTANT) != 0;
  inside = inside && (!crossing || next_constant || (vload16(0, ulog2_a) >= next_ulog2 && next_face_vlog2 >= next_vlog2));
  /* The tangent-vector edge mode turns two channels with the kernel. */
  if (s->tex.edge_filter_mode == 1 && s->tex.channels >= 2) inside = inside && (!crossing || turns == 0);
  /* ptexf_weight's sums, in its order. */
  const float16 weight = (ku0 + ku1 + ku2) * (kv0 + kv1 + kv2) * s->tex.one_value;
  inside = inside && weight != 0.0f && !isinf(weight);
  if (!any(inside)) return inside;
  /* Lanes left to ptexf_lookup read their texture's first texels, which are there. */
  const int nchan = s->tex.channels;
  int level_index_a[PTEXF_LANES], next_level_index_a[PTEXF_LANES];
  vstore16(select((int16)(0), vload16(0, base_a) + ulog2 * (face_vlog2 + 1) + vlog2, inside), 0, level_index_a);
  vstore16(select((int16)(0), vload16(0, next_a) + select(next_ulog2 * (next_face_vlog2 + 1) + next_vlog2, (int16)(0), next_constant),
                  inside && crossing),
           0, next_level_index_a);
  /* Texel indices are uints, as in ptexf_sum_taps: a texture may hold up to 2^32 - 1 values. */
  uint level_a[PTEXF_LANES], next_level_a[PTEXF_LANES];
  for (int i = 0; i < PTEXF_LANES; ++i) {
    level_a[i] = s->level_offsets[level_index_a[i]];
    next_level_a[i] = s->level_offsets[next_level_index_a[i]];
  }
  const uint16 level = vload16(0, level_a), next_level = vload16(0, next_level_a);
  const int16 next_row = select((int16)(1) << next_ulog2, (int16)(0), next_constant);
  const int taps = any(inside && (utaps == 3 || vtaps == 3)) ? 3 : 2;
  /* Tap (i, j) at address_a[i][j], a tap past the kernel's count on its last texel. */
  uint address_a[3][3][PTEXF_LANES];
  for (int i = 0; i < taps; ++i)
    for (int j = 0; j < taps; ++j) {
      const int16 x = ku + min((int16)(i), utaps - 1), y = kv + min((int16)(j), vtaps - 1);
      const int16 beyond = x < 0 || x >= resu || y < 0 || y >= resv;
      /* Past the edge, in the face's frame moved by its size, then turned. */
      const int16 xt = x & (resu - 1), yt = y & (resv - 1);
      const int16 xf = resu - 1 - xt, yf = resv - 1 - yt;
      const int16 next_x = select(select(select(xt, yt, turns == 1), xf, turns == 2), yf, turns == 3);
      const int16 next_y = select(select(select(yt, xf, turns == 1), yf, turns == 2), xt, turns == 3);
      /* Every offset within a level is a valid texel of a face that fits, so at least 0 for the lanes. */
      const uint16 at = select(level + as_uint16(y * resu + x),
                               next_level + as_uint16(next_y * next_row + select(next_x, (int16)(0), next_constant)),
                               as_uint16(beyond));
      vstore16(select((uint16)(0), at * (uint)nchan, as_uint16(inside)), 0, address_a[i][j]);
    }
  const float16 kus[3] = {ku0, ku1, ku2}, kvs[3] = {kv0, kv1, kv2};
  const float16 scale = 1.0f / weight;
  for (int c = 0; c < 4; ++c) {
    float16 sum = (float16)(0.0f);
    if (c < nchan) {
      for (int i = 0; i < taps; ++i) {
        float16 column = (float16)(0.0f);
        for (int j = 0; j < taps; ++j) {
          float tap_a[PTEXF_LANES];
          for (int l = 0; l < PTEXF_LANES; ++l) tap_a[l] = ptexf_texel(s, address_a[i][j][l] + (uint)c);
          column += vload16(0, tap_a) * kvs[j];
        }
        sum += column * kus[i];
      }
      sum *= scale;
    }
    float sum_a[PTEXF_LANES];
    vstore16(sum, 0, sum_a);
    for (int l = 0; l < PTEXF_LANES; ++l) values[4 * l + c] = sum_a[l];
  }
  return inside;
}

/* Work-item g looks up queries g * PTEXF_LANES .. (the last one fewer). */
__kernel void ptex_filter_lookups(PtexFilterTexture tex, __global const PtexFilterFace* faces,
                                  __global const uint* level_offsets, __global const uchar* texels,
                                  __global const PtexFilterQuery* queries, int count, __global float* out) {
  const int first = PTEXF_LANES * (int)get_global_id(0);
  if (first >= count) return;
  const int n = min(PTEXF_LANES, count - first);
  PtexfState s = ptexf_batch_state(tex, faces, level_offsets, texels);
  float values[4 * PTEXF_LANES];
  int inside_a[PTEXF_LANES];
  vstore16(ptexf_small_lanes(&s, queries, first, n, values), 0, inside_a);
  for (int i = 0; i < n; ++i) {
    __global float* dst = out + 4 * (first + i);
    if (inside_a[i] != 0) {
#pragma clang loop vectorize(disable) unroll(disable)
      for (int c = 0; c < 4; ++c) dst[c] = values[4 * i + c];
      continue;
    }
    const PtexFilterQuery q = queries[first + i];
    float value[4];
    ptexf_lookup(&s, &q, value);
    /* Copied value by value: ptexf_lookup stores them one at a time, and one 16-byte load of them
     * would wait for those stores to leave the core (a store-to-load forward that fails), and with
     * them for every cache miss before (15% of this function's samples on a bilinear batch). */
#pragma clang loop vectorize(disable) unroll(disable)
    for (int c = 0; c < 4; ++c) dst[c] = value[c];
  }
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
