/* Ptex's own separable filters: ptexf_lookup, run by ptex_filter_lookups (ptex_lookup_batch.cl)
 * and by the Ptex variant of the shading stage (shade_resolve.cl).
 *
 * Contract: query q (face, filter, u, v, uw, vw, sharpness) gives what the Ptex library's
 * PtexFilter::eval gives on the same quad-mesh texture (uw1 = uw, vw2 = vw, uw2 = vw1 = 0, width 1,
 * blur 0, no lerp, edge blending on): the kernel built at the resolution the filter width selects,
 * split at face edges into the neighbours, each turned by eid - aeid + 2 quarter turns and read at
 * the kernel's resolution (downres'd to a coarser neighbour's), corners by valence (4: the diagonal
 * face; 5 to 10: the kernel made symmetric and applied to each corner face; 2, 3 and boundaries:
 * dropped, the weight taken back), boundary edges merged by the file's border mode, the sum
 * divided by the kernel's weight and the type's one value. Writes 4 floats per lookup (channels
 * beyond the texture's are 0); a face out of range gives zeros (the host refuses it first).
 * tex.seams other than SEAMCL_PTEX_SEAMS_PTEX (renders with a seam method that reads no neighbour)
 * walks no neighbour: every edge is a boundary of that rule (seamcl_types.h), and with DISCARD the
 * sum is divided by the weight of the taps inside the face instead.
 * Host guarantees (host/ptexfilter/ptex_filter_texture.cpp): every resolution 2^i x 2^j of every
 * face at texels + level_offsets[face.level_base + i * (vlog2 + 1) + j] (texel index; channels
 * interleaved; the element count fits a uint; a constant face's one texel at every offset), then
 * SEAMCL_PTEX_TEXEL_TAIL bytes of padding; at least one face; no subfaces.
 * The shading program compiles this file into its Ptex variant only (SEAMCL_SAMPLER_FILTER =
 * SEAMCL_FILTER_PTEX); the others skip it.
 * Twin: host/pipeline/stages/ptex_filter_twin.cpp. */

#if !defined(SEAMCL_SAMPLER_FILTER) || SEAMCL_SAMPLER_FILTER == SEAMCL_FILTER_PTEX

#define PTEXF_BOTTOM 0
#define PTEXF_RIGHT 1
#define PTEXF_TOP 2
#define PTEXF_LEFT 3
#define PTEXF_BLACK 1
#define PTEXF_PERIODIC 2
/* A kernel row's values as whole vectors of 16 (uw * nchan: at most 40 by the arrays' sizes; Ptex's
 * kernels reach 8 taps, 32 values); rows of at most PTEXF_SCALAR_COLUMNS values (one channel's
 * bilinear and narrow boxes) are summed value by value. */
#define PTEXF_COLUMNS 48
#define PTEXF_SCALAR_COLUMNS 3

typedef struct {
  int ulog2, vlog2;
  int u, v, uw, vw;
  float ku[SEAMCL_PTEX_KMAX];
  float kv[SEAMCL_PTEX_KMAX];
  int rot;
} PtexfKernel;

typedef struct {
  __global const PtexFilterFace* faces;
  __global const uint* level_offsets;
  __global const uchar* texels;
  PtexFilterTexture tex;
  float weight;
  float applied;  /* SEAMCL_PTEX_SEAMS_DISCARD: the weight of the taps read */
  float result[4];
} PtexfState;

SEAMCL_INLINE float ptexf_accumulate(const float* p, int n) {
  float sum = 0.0f;
  for (int i = 0; i < n; ++i) sum += p[i];
  return sum;
}

SEAMCL_INLINE float ptexf_weight(const PtexfKernel* k) {
  return ptexf_accumulate(k->ku, k->uw) * ptexf_accumulate(k->kv, k->vw);
}

SEAMCL_INLINE void ptexf_drop_front(float* a, int n, int by) {
  for (int i = 0; i + by < n; ++i) a[i] = a[i + by];
}

SEAMCL_INLINE void ptexf_reverse(float* a, int n) {
  for (int i = 0, j = n - 1; i < j; ++i, --j) {
    const float t = a[i];
    a[i] = a[j];
    a[j] = t;
  }
}

SEAMCL_INLINE void ptexf_strip_zeros(PtexfKernel* k) {
  while (k->uw > 0 && k->ku[0] == 0.0f) { ptexf_drop_front(k->ku, k->uw, 1); k->u++; k->uw--; }
  while (k->uw > 0 && k->ku[k->uw - 1] == 0.0f) k->uw--;
  while (k->vw > 0 && k->kv[0] == 0.0f) { ptexf_drop_front(k->kv, k->vw, 1); k->v++; k->vw--; }
  while (k->vw > 0 && k->kv[k->vw - 1] == 0.0f) k->vw--;
}

SEAMCL_INLINE void ptexf_merge_left(PtexfKernel* k, int mode) {
  const int w = -k->u;
  if (mode != PTEXF_BLACK) k->ku[w] += ptexf_accumulate(k->ku, w);
  ptexf_drop_front(k->ku, k->uw, w);
  k->uw -= w;
  k->u = 0;
}
SEAMCL_INLINE void ptexf_merge_right(PtexfKernel* k, int mode) {
  const int w = k->uw + k->u - (1 << k->ulog2);
  const int first = k->uw - w;
  if (mode != PTEXF_BLACK) k->ku[first - 1] += ptexf_accumulate(k->ku + first, w);
  k->uw -= w;
}
SEAMCL_INLINE void ptexf_merge_bottom(PtexfKernel* k, int mode) {
  const int w = -k->v;
  if (mode != PTEXF_BLACK) k->kv[w] += ptexf_accumulate(k->kv, w);
  ptexf_drop_front(k->kv, k->vw, w);
  k->vw -= w;
  k->v = 0;
}
SEAMCL_INLINE void ptexf_merge_top(PtexfKernel* k, int mode) {
  const int w = k->vw + k->v - (1 << k->vlog2);
  const int first = k->vw - w;
  if (mode != PTEXF_BLACK) k->kv[first - 1] += ptexf_accumulate(k->kv + first, w);
  k->vw -= w;
}

SEAMCL_INLINE void ptexf_split_left(PtexfKernel* k, PtexfKernel* piece) {
  const int w = -k->u;
  *piece = *k;
  if (w < k->uw) {
    piece->u = (1 << k->ulog2) - w;
    piece->uw = w;
    piece->rot = 0;
    k->u = 0;
    ptexf_drop_front(k->ku, k->uw, w);
    k->uw -= w;
  } else {
    piece->u += 1 << k->ulog2;
    k->u = 0;
    k->uw = 0;
  }
}
SEAMCL_INLINE void ptexf_split_right(PtexfKernel* k, PtexfKernel* piece) {
  const int w = k->u + k->uw - (1 << k->ulog2);
  *piece = *k;
  if (w < k->uw) {
    piece->u = 0;
    piece->uw = w;
    piece->rot = 0;
    ptexf_drop_front(piece->ku, k->uw, k->uw - w);
    k->uw -= w;
  } else {
    piece->u -= 1 << k->ulog2;
    k->u = 0;
    k->uw = 0;
  }
}
SEAMCL_INLINE void ptexf_split_bottom(PtexfKernel* k, PtexfKernel* piece) {
  const int w = -k->v;
  *piece = *k;
  if (w < k->vw) {
    piece->v = (1 << k->vlog2) - w;
    piece->vw = w;
    piece->rot = 0;
    k->v = 0;
    ptexf_drop_front(k->kv, k->vw, w);
    k->vw -= w;
  } else {
    piece->v += 1 << k->vlog2;
    k->v = 0;
    k->vw = 0;
  }
}
SEAMCL_INLINE void ptexf_split_top(PtexfKernel* k, PtexfKernel* piece) {
  const int w = k->v + k->vw - (1 << k->vlog2);
  *piece = *k;
  if (w < k->vw) {
    piece->v = 0;
    piece->vw = w;
    piece->rot = 0;
    ptexf_drop_front(piece->kv, k->vw, k->vw - w);
    k->vw -= w;
  } else {
    piece->v -= 1 << k->vlog2;
    k->v = 0;
    k->vw = 0;
  }
}

SEAMCL_INLINE void ptexf_flip_u(PtexfKernel* k) {
  k->u = (1 << k->ulog2) - k->u - k->uw;
  ptexf_reverse(k->ku, k->uw);
}
SEAMCL_INLINE void ptexf_flip_v(PtexfKernel* k) {
  k->v = (1 << k->vlog2) - k->v - k->vw;
  ptexf_reverse(k->kv, k->vw);
}
SEAMCL_INLINE void ptexf_swap_uv(PtexfKernel* k) {
  int t = k->ulog2; k->ulog2 = k->vlog2; k->vlog2 = t;
  t = k->u; k->u = k->v; k->v = t;
  t = k->uw; k->uw = k->vw; k->vw = t;
  for (int i = 0; i < SEAMCL_PTEX_KMAX; ++i) {
    const float f = k->ku[i];
    k->ku[i] = k->kv[i];
    k->kv[i] = f;
  }
}
SEAMCL_INLINE void ptexf_rotate(PtexfKernel* k, int r) {
  switch (r & 3) {
    case 1: ptexf_flip_u(k); ptexf_swap_uv(k); break;
    case 2: ptexf_flip_u(k); ptexf_flip_v(k); break;
    case 3: ptexf_flip_v(k); ptexf_swap_uv(k); break;
    default: return;
  }
  k->rot = (k->rot + r) & 3;
}

SEAMCL_INLINE void ptexf_downres_u(PtexfKernel* k) {
  int src = 0, dst = 0, uw = k->uw;
  if (k->u & 1) { dst++; src++; uw--; }
  for (int i = uw / 2; i > 0; --i) { k->ku[dst++] = k->ku[src] + k->ku[src + 1]; src += 2; }
  if (uw & 1) k->ku[dst++] = k->ku[src++];
  k->u /= 2;
  k->uw = dst;
  k->ulog2--;
}
SEAMCL_INLINE void ptexf_downres_v(PtexfKernel* k) {
  int src = 0, dst = 0, vw = k->vw;
  if (k->v & 1) { dst++; src++; vw--; }
  for (int i = vw / 2; i > 0; --i) { k->kv[dst++] = k->kv[src] + k->kv[src + 1]; src += 2; }
  if (vw & 1) k->kv[dst++] = k->kv[src++];
  k->v /= 2;
  k->vw = dst;
  k->vlog2--;
}

SEAMCL_INLINE float ptexf_make_symmetric(PtexfKernel* k, float initial_weight) {
  while (k->ulog2 > k->vlog2) ptexf_downres_u(k);
  while (k->vlog2 > k->ulog2) ptexf_downres_v(k);
  k->uw = k->vw = min(k->uw, k->vw);
  float new_weight = 0.0f;
  for (int i = 0; i < k->uw; ++i) {
    const float sum = k->ku[i] + k->kv[i];
    k->ku[i] = k->kv[i] = sum;
    new_weight += sum;
  }
  new_weight *= new_weight;
  const float scale = new_weight == 0.0f ? 1.0f : initial_weight / new_weight;
  if (scale < 1.0f) {
    if (scale < -1.0f) {
      for (int i = 0; i < k->uw; ++i) k->ku[i] *= -1.0f;
      new_weight = -new_weight;
    } else {
      for (int i = 0; i < k->uw; ++i) k->ku[i] *= scale;
      new_weight = initial_weight;
    }
  }
  return new_weight;
}

SEAMCL_INLINE int ptexf_res_from_width(float w) { return 127 - ((as_int(w) >> 23) & 0xff); }
SEAMCL_INLINE float ptexf_reciprocal_pow2(int power) { return as_float((127 - power) << 23); }

/* e^y for the gaussian's y = -2x^2 as 2^n e^z: n = y log2 e rounded, z = y - n ln 2 in two steps
 * (Cody and Waite), |z| <= ln 2 / 2, e^z by its Taylor series to z^6 (truncation under 2e-7
 * relative, about 3e-7 with rounding). y is clamped to -87 so that n >= -126 and 2^n is a normal
 * float made of exponent bits (the lanes past a kernel's taps reach |x| of about 13). The
 * library's float16 exp was no faster on PoCL than 16 scalar ones (docs/performance.md); this is
 * one vector of arithmetic. */
SEAMCL_INLINE float16 ptexf_exp16(float16 y) {
  y = fmax(y, -87.0f);
  /* y log2 e rounded to an integer by adding 1.5 * 2^23: the sum's low mantissa bits are n. */
  const int16 n_bits = as_int16(y * 1.44269504088896f + 12582912.0f) - 0x4b400000;
  const float16 n = convert_float16(n_bits);
  /* ln 2's high part has 15 significant bits, so its product with |n| <= 126 (7 bits) is exact. */
  const float16 z = (y - n * 0.693145751953125f) - n * 1.42860682028622680e-6f;
  const float16 p =
      ((((((1.0f / 720.0f) * z + 1.0f / 120.0f) * z + 1.0f / 24.0f) * z + 1.0f / 6.0f) * z + 0.5f) * z + 1.0f) * z +
      1.0f;
  return p * as_float16((n_bits + 127) << 23);
}

/* A width-4 filter's weights at x1, x1 + step, ... into all SEAMCL_PTEX_KMAX entries of k (the
 * caller keeps as many as its kernel has taps), computed as one vector. */
SEAMCL_INLINE void ptexf_width4_weights(int filter, const float* c, float* k, float x1, float step) {
  const float16 x = x1 + (float16)(0.0f, 1.0f, 2.0f, 3.0f, 4.0f, 5.0f, 6.0f, 7.0f, 8.0f, 9.0f, 10.0f, 11.0f, 12.0f,
                                   13.0f, 14.0f, 15.0f) * step;
  float16 w;
  if (filter == SEAMCL_PTEX_GAUSSIAN) {
    w = ptexf_exp16(-2.0f * x * x);
  } else {
    const float16 a = fabs(x);
    const float16 inner = (c[0] * a + c[1]) * a * a + c[2];
    const float16 outer = ((c[3] * a + c[4]) * a + c[5]) * a + c[6];
    w = select(select((float16)(0.0f), outer, a < 2.0f), inner, a < 1.0f);
  }
  vstore8(w.lo, 0, k);
  k[8] = w.s8;
  k[9] = w.s9;
}

/* ceil(x) as an int, for |x| < 2^31 (a kernel's texel coordinates): PoCL's ceil is a library
 * routine with range checks and branches. */
SEAMCL_INLINE int ptexf_ceil_int(float x) {
  const int t = (int)x;
  return t + ((float)t < x ? 1 : 0);
}

SEAMCL_INLINE float ptexf_blur(float x) {
  x = fabs(x);
  return x < 1.0f ? (2.0f * x - 3.0f) * x * x + 1.0f : 0.0f;
}

/* One axis of a width-4 kernel (gaussian, bicubic), without Ptex's optional lerp. */
SEAMCL_INLINE void ptexf_width4_axis(int filter, const float* c, int* res_log2, int* k_u, int* k_uw, float* ku,
                                     float u, float uw, int face_log2) {
  uw = fmax(uw, ptexf_reciprocal_pow2(face_log2));
  *res_log2 = ptexf_res_from_width(uw);
  const int resu = 1 << *res_log2;
  if (uw >= 0.25f) {
    if (uw < 0.5f) {
      *res_log2 = 2;
      const float upix = u * 4.0f - 0.5f;
      int u1 = (int)ceil(upix - 2), u2 = (int)ceil(upix + 2);
      u1 = u1 & ~1;
      u2 = (u2 + 1) & ~1;
      *k_u = u1;
      *k_uw = min(u2 - u1, SEAMCL_PTEX_KMAX);
      ptexf_width4_weights(filter, c, ku, (float)u1 - upix, 1.0f);
      return;
    }
    if (uw < 1.0f) {
      *res_log2 = 1;
      const float upix = u * 2.0f - 0.5f;
      *k_u = (int)floor(u - 0.5f) * 2;
      *k_uw = 4;
      const float x1 = (float)*k_u - upix;
      const float s = 1.0f / (uw * 1.5f + 0.5f);
      for (int i = 0; i < 4; i += 2) {
        const float xa = x1 + (float)i, xb = xa + 1.0f;
        ku[i] = ptexf_blur(xa * s);
        ku[i + 1] = ptexf_blur(xb * s);
      }
      return;
    }
    *res_log2 = 0;
    const float upix = u - 0.5f;
    *k_uw = 2;
    const float ui = floor(upix);
    *k_u = (int)ui;
    ku[0] = ptexf_blur(upix - ui);
    ku[1] = 1.0f - ku[0];
    return;
  }
  const float upix = u * (float)resu - 0.5f;
  const float uwpix = uw * (float)resu;
  const float dupix = 2.0f * uwpix;
  const int u1 = ptexf_ceil_int(upix - dupix), u2 = ptexf_ceil_int(upix + dupix);
  *k_u = u1;
  *k_uw = min(u2 - u1, SEAMCL_PTEX_KMAX);
  /* Divided as the library divides: with one reciprocal instead, a tap's position moves by an ulp,
   * which near a kernel's zero ends changed some bspline values by 3.5e-3
   * (tests/ptex_golden/cube_text_fixed.txt). */
  ptexf_width4_weights(filter, c, ku, ((float)u1 - upix) / uwpix, 1.0f / uwpix);
}

SEAMCL_INLINE void ptexf_box_weights(float* weights, int size, float f1, float f2) {
  if (size == 1) {
    weights[0] = f1 + f2 - 1.0f;
  } else {
    weights[0] = f1;
    for (int i = 1; i < size - 1; ++i) weights[i] = 1.0f;
    weights[size - 1] = f2;
  }
}

SEAMCL_INLINE void ptexf_build(PtexfKernel* k, const PtexFilterQuery* q, float u, float v, float uw, float vw,
                               int face_ulog2, int face_vlog2) {
  if (q->filter == SEAMCL_PTEX_BILINEAR || q->filter == SEAMCL_PTEX_BOX) {
    uw = fmax(fmin(uw, 1.0f), ptexf_reciprocal_pow2(face_ulog2));
    vw = fmax(fmin(vw, 1.0f), ptexf_reciprocal_pow2(face_vlog2));
    k->ulog2 = ptexf_res_from_width(uw);
    k->vlog2 = ptexf_res_from_width(vw);
    const float resu = (float)(1 << k->ulog2), resv = (float)(1 << k->vlog2);
    if (q->filter == SEAMCL_PTEX_BILINEAR) {
      const float upix = u * resu - 0.5f, vpix = v * resv - 0.5f;
      const float ufloor = floor(upix), vfloor = floor(vpix);
      k->u = (int)ufloor;
      k->v = (int)vfloor;
      k->uw = 2;
      k->vw = 2;
      k->ku[0] = 1.0f - (upix - ufloor);
      k->ku[1] = upix - ufloor;
      k->kv[0] = 1.0f - (vpix - vfloor);
      k->kv[1] = vpix - vfloor;
      return;
    }
    u = u * resu;
    v = v * resv;
    uw *= resu;
    vw *= resv;
    const float u1 = u - 0.5f * uw, u2 = u + 0.5f * uw;
    const float v1 = v - 0.5f * vw, v2 = v + 0.5f * vw;
    const float u1floor = floor(u1), u2ceil = ceil(u2);
    const float v1floor = floor(v1), v2ceil = ceil(v2);
    k->u = (int)u1floor;
    k->v = (int)v1floor;
    k->uw = min((int)u2ceil - k->u, 3);
    k->vw = min((int)v2ceil - k->v, 3);
    ptexf_box_weights(k->ku, k->uw, 1.0f - (u1 - u1floor), 1.0f - (u2ceil - u2));
    ptexf_box_weights(k->kv, k->vw, 1.0f - (v1 - v1floor), 1.0f - (v2ceil - v2));
    return;
  }
  float c[7] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  if (q->filter == SEAMCL_PTEX_BICUBIC) {
    const float B = 1.0f - q->sharpness;
    c[0] = 1.5f - B;
    c[1] = 1.5f * B - 2.5f;
    c[2] = 1.0f - (float)(1.0f / 3.0f) * B;
    c[3] = (float)(1.0f / 3.0f) * B - 0.5f;
    c[4] = 2.5f - 1.5f * B;
    c[5] = 2.0f * B - 4.0f;
    c[6] = 2.0f - (float)(2.0f / 3.0f) * B;
  }
  ptexf_width4_axis(q->filter, c, &k->ulog2, &k->u, &k->uw, k->ku, u, uw, face_ulog2);
  ptexf_width4_axis(q->filter, c, &k->vlog2, &k->v, &k->vw, k->kv, v, vw, face_vlog2);
}

/* Half texels are decoded from their bits: vload_half is core OpenCL C, but some offline compilers
 * (clang 14 with every extension disabled) leave it undeclared. */
SEAMCL_INLINE float ptexf_half_to_float(uint h) {
  const uint sign = (h & 0x8000u) << 16;
  const uint exponent = (h >> 10) & 0x1fu;
  const uint mantissa = h & 0x3ffu;
  float magnitude;
  if (exponent == 0u) {
    magnitude = (float)mantissa * 5.9604644775390625e-8f; /* 2^-24 */
  } else {
    magnitude = as_float(exponent == 31u ? (0xffu << 23) | (mantissa << 13) : ((exponent + 112u) << 23) | (mantissa << 13));
  }
  return sign ? -magnitude : magnitude;
}

SEAMCL_INLINE float ptexf_texel(const PtexfState* s, uint index) {
  switch (s->tex.data_type) {
    case 0: return (float)s->texels[index];
    case 1: return (float)((__global const ushort*)s->texels)[index];
    case 2: return ptexf_half_to_float(((__global const ushort*)s->texels)[index]);
    default: return ((__global const float*)s->texels)[index];
  }
}

SEAMCL_INLINE float16 ptexf_halves_to_float16(ushort16 h) {
  const uint16 bits = convert_uint16(h);
  const uint16 sign = (bits & 0x8000u) << 16;
  const uint16 exponent = (bits >> 10) & 0x1fu;
  const uint16 mantissa = bits & 0x3ffu;
  const float16 subnormal = convert_float16(mantissa) * 5.9604644775390625e-8f; /* 2^-24 */
  const uint16 normal = select(((exponent + 112u) << 23) | (mantissa << 13), (0xffu << 23) | (mantissa << 13),
                               exponent == 31u);
  const float16 magnitude = select(as_float16(normal), subnormal, exponent == 0u);
  return as_float16(as_uint16(magnitude) | sign);
}

/* 16 consecutive values of type data_type from index on, as floats; past a row's end they are
 * whatever follows (the host pads the buffer by SEAMCL_PTEX_TEXEL_TAIL bytes, so they may be NaN),
 * and the callers discard those lanes. */
SEAMCL_INLINE float16 ptexf_texels16(const PtexfState* s, uint index, int data_type) {
  switch (data_type) {
    case 0: return convert_float16(vload16(0, s->texels + index));
    case 1: return convert_float16(vload16(0, (__global const ushort*)s->texels + index));
    case 2: return ptexf_halves_to_float16(vload16(0, (__global const ushort*)s->texels + index));
    default: return vload16(0, (__global const float*)s->texels + index);
  }
}

/* The kernel's vw rows, each 16 values from `first` on (rows `stride` values apart) of type
 * data_type, weighted by kv and summed down the rows. */
SEAMCL_INLINE float16 ptexf_sum_down16_of_type(const PtexfState* s, const PtexfKernel* k, uint first, uint stride,
                                              int data_type) {
  float16 column = (float16)(0.0f);
  for (int j = 0; j < k->vw; ++j) column += ptexf_texels16(s, first + (uint)j * stride, data_type) * k->kv[j];
  return column;
}

/* ptexf_sum_down16_of_type for the texture's type, each type's loop compiled apart (the type a
 * constant in each call) so that no row switches on it. */
SEAMCL_INLINE float16 ptexf_sum_down16(const PtexfState* s, const PtexfKernel* k, uint first, uint stride) {
  switch (s->tex.data_type) {
    case 0: return ptexf_sum_down16_of_type(s, k, first, stride, 0);
    case 1: return ptexf_sum_down16_of_type(s, k, first, stride, 1);
    case 2: return ptexf_sum_down16_of_type(s, k, first, stride, 2);
    default: return ptexf_sum_down16_of_type(s, k, first, stride, 3);
  }
}

SEAMCL_INLINE int ptexf_adj_face(PtexFilterFace f, int e) { return f.adj_faces[e & 3]; }
SEAMCL_INLINE int ptexf_adj_edge(PtexFilterFace f, int e) { return (int)((f.adj_edges >> (2 * (e & 3))) & 3u); }

SEAMCL_INLINE uint ptexf_level(const PtexfState* s, PtexFilterFace f, int ulog2, int vlog2) {
  return s->level_offsets[f.level_base + (uint)(ulog2 * (f.vlog2 + 1) + vlog2)];
}

/* acc[c] += sum over the kernel's columns i of ku[i] * columns[i * nchan + c]. */
SEAMCL_INLINE void ptexf_sum_across_of(const float* columns, const PtexfKernel* k, int nchan, float* acc) {
  for (int i = 0; i < k->uw; ++i)
    for (int c = 0; c < nchan; ++c) acc[c] += columns[i * nchan + c] * k->ku[i];
}

/* ptexf_sum_across for 1 to 4 channels, each count's loop compiled apart, so that the channels are
 * unrolled (a runtime count kept an inner loop per column). */
SEAMCL_INLINE void ptexf_sum_across(const float* columns, const PtexfKernel* k, int nchan, float* acc) {
  switch (nchan) {
    case 1: ptexf_sum_across_of(columns, k, 1, acc); break;
    case 2: ptexf_sum_across_of(columns, k, 2, acc); break;
    case 3: ptexf_sum_across_of(columns, k, 3, acc); break;
    default: ptexf_sum_across_of(columns, k, 4, acc); break;
  }
}

/* The kernel's taps on face f, at a resolution the face stores, summed into acc (one per channel).
 * Columns first: each of a row's uw * nchan values summed down the rows (kv), then the columns
 * across (ku). A row's values are contiguous, so a row of more than PTEXF_SCALAR_COLUMNS values is
 * read as vectors of 16, which keeps the taps in SIMD registers and issues every row's load at
 * once. The twin sums in this order; the one-channel tree sum across, multiply-adds fused or not,
 * and Ptex's rows-first order differ from it by float rounding only. */
SEAMCL_INLINE void ptexf_sum_taps(const PtexfState* s, const PtexfKernel* k, PtexFilterFace f, float* acc) {
  const int nchan = s->tex.channels;
  const uint rowlen = 1u << k->ulog2;
  const int count = k->uw * nchan;
  const uint first = (ptexf_level(s, f, k->ulog2, k->vlog2) + (uint)k->v * rowlen + (uint)k->u) * (uint)nchan;
  const uint stride = rowlen * (uint)nchan;
  float columns[PTEXF_COLUMNS];
  if (count <= PTEXF_SCALAR_COLUMNS) {
    for (int l = 0; l < count; ++l) columns[l] = 0.0f;
    for (int j = 0; j < k->vw; ++j)
      for (int l = 0; l < count; ++l) columns[l] += ptexf_texel(s, first + (uint)j * stride + (uint)l) * k->kv[j];
    ptexf_sum_across(columns, k, nchan, acc);
  } else if (nchan == 1) {
    /* One channel: the columns across as one 16-lane product, summed as a tree. */
    const float16 column = ptexf_sum_down16(s, k, first, stride);
    const int16 lane = (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const float16 ku = (float16)(k->ku[0], k->ku[1], k->ku[2], k->ku[3], k->ku[4], k->ku[5], k->ku[6], k->ku[7],
                                 k->ku[8], k->ku[9], 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
    const float16 p = select((float16)(0.0f), column * ku, lane < (int16)(k->uw));
    const float8 p8 = p.lo + p.hi;
    const float4 p4 = p8.lo + p8.hi;
    const float2 p2 = p4.lo + p4.hi;
    acc[0] = p2.x + p2.y;
  } else {
    for (int chunk = 0; 16 * chunk < count; ++chunk)
      vstore16(ptexf_sum_down16(s, k, first + (uint)(16 * chunk), stride), chunk, columns);
    ptexf_sum_across(columns, k, nchan, acc);
  }
}

SEAMCL_CALLED void ptexf_apply(PtexfState* s, PtexfKernel* k, int face) {
  const PtexFilterFace f = s->faces[face];
  const int nchan = s->tex.channels;
  /* Taps past the far side of a face (a kernel wider than the neighbour) are dropped. */
  if (k->u < 0) { const int w = min(-k->u, k->uw); ptexf_drop_front(k->ku, k->uw, w); k->uw -= w; k->u = 0; }
  if (k->v < 0) { const int w = min(-k->v, k->vw); ptexf_drop_front(k->kv, k->vw, w); k->vw -= w; k->v = 0; }
  if (k->u + k->uw > (1 << k->ulog2)) k->uw = max(0, (1 << k->ulog2) - k->u);
  if (k->v + k->vw > (1 << k->vlog2)) k->vw = max(0, (1 << k->vlog2) - k->v);
  if (k->uw <= 0 || k->vw <= 0) return;
  if (s->tex.seams == SEAMCL_PTEX_SEAMS_DISCARD) s->applied += ptexf_weight(k);
  while (k->ulog2 > f.ulog2) ptexf_downres_u(k);
  while (k->vlog2 > f.vlog2) ptexf_downres_v(k);
  float acc[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  if ((f.flags & SEAMCL_PTEX_FLAG_CONSTANT) != 0u || (k->ulog2 == 0 && k->vlog2 == 0)) {
    const float w = ptexf_weight(k);
    const uint base = ptexf_level(s, f, 0, 0) * (uint)nchan;
    for (int c = 0; c < nchan; ++c) acc[c] = ptexf_texel(s, base + (uint)c) * w;
  } else {
    ptexf_sum_taps(s, k, f, acc);
  }
  if (s->tex.edge_filter_mode == 1 && nchan >= 2 && k->rot > 0) {
    if (k->rot == 1) { s->result[0] -= acc[1]; s->result[1] += acc[0]; }
    else if (k->rot == 2) { s->result[0] -= acc[0]; s->result[1] -= acc[1]; }
    else { s->result[0] += acc[1]; s->result[1] -= acc[0]; }
    for (int c = 2; c < nchan; ++c) s->result[c] += acc[c];
  } else {
    for (int c = 0; c < nchan; ++c) s->result[c] += acc[c];
  }
}

SEAMCL_INLINE void ptexf_across_edge(PtexfState* s, PtexfKernel* k, PtexFilterFace f, int eid) {
  ptexf_rotate(k, eid - ptexf_adj_edge(f, eid) + 2);
  ptexf_apply(s, k, ptexf_adj_face(f, eid));
}

SEAMCL_CALLED void ptexf_corner(PtexfState* s, PtexfKernel* k, int faceid, PtexFilterFace f, int eid) {
  int aeid = eid;
  PtexFilterFace af = f;
  int cface[SEAMCL_PTEX_MAX_VALENCE];
  int cedge[SEAMCL_PTEX_MAX_VALENCE];
  int corners = 0;
  for (int i = 0; i < SEAMCL_PTEX_MAX_VALENCE; ++i) {
    const int afid = ptexf_adj_face(af, aeid);
    aeid = (ptexf_adj_edge(af, aeid) + 1) % 4;
    if (afid < 0 || (afid == faceid && aeid == eid)) {
      corners = i - 2;
      break;
    }
    af = s->faces[afid];
    cface[i] = afid;
    cedge[i] = aeid;
  }
  if (corners == 1) {
    ptexf_rotate(k, eid - cedge[1] + 2);
    ptexf_apply(s, k, cface[1]);
  } else if (corners > 1) {
    ptexf_rotate(k, eid + 2);
    const float initial_weight = ptexf_weight(k);
    const float new_weight = ptexf_make_symmetric(k, initial_weight);
    for (int i = 1; i <= corners; ++i) {
      PtexfKernel kc = *k;
      ptexf_rotate(&kc, 2 - cedge[i] + 2);
      ptexf_apply(s, &kc, cface[i]);
    }
    s->weight += new_weight * (float)corners - initial_weight;
  } else {
    s->weight -= ptexf_weight(k);
  }
}

/* Whether edge e leads to a neighbour the filter walks to. */
SEAMCL_INLINE bool ptexf_walks(const PtexfState* s, PtexFilterFace f, int e) {
  return s->tex.seams == SEAMCL_PTEX_SEAMS_PTEX && ptexf_adj_face(f, e) >= 0;
}

SEAMCL_INLINE void ptexf_split_and_apply(PtexfState* s, PtexfKernel* k, int faceid) {
  const PtexFilterFace f = s->faces[faceid];
  const bool split_r = k->u + k->uw > (1 << k->ulog2), split_l = k->u < 0;
  const bool split_t = k->v + k->vw > (1 << k->vlog2), split_b = k->v < 0;
  const int seams = s->tex.seams;
  const int umode = seams == SEAMCL_PTEX_SEAMS_PTEX ? s->tex.u_border_mode : seams == SEAMCL_PTEX_SEAMS_CLAMP ? 0 : PTEXF_BLACK;
  const int vmode = seams == SEAMCL_PTEX_SEAMS_PTEX ? s->tex.v_border_mode : seams == SEAMCL_PTEX_SEAMS_CLAMP ? 0 : PTEXF_BLACK;
  PtexfKernel ka, kc;
  if (split_r) {
    if (ptexf_walks(s, f, PTEXF_RIGHT)) {
      ptexf_split_right(k, &ka);
      if (split_t) {
        if (ptexf_walks(s, f, PTEXF_TOP)) { ptexf_split_top(&ka, &kc); ptexf_corner(s, &kc, faceid, f, PTEXF_TOP); }
        else ptexf_merge_top(&ka, vmode);
      }
      if (split_b) {
        if (ptexf_walks(s, f, PTEXF_BOTTOM)) { ptexf_split_bottom(&ka, &kc); ptexf_corner(s, &kc, faceid, f, PTEXF_RIGHT); }
        else ptexf_merge_bottom(&ka, vmode);
      }
      ptexf_across_edge(s, &ka, f, PTEXF_RIGHT);
    } else {
      ptexf_merge_right(k, umode);
    }
  }
  if (split_l) {
    if (ptexf_walks(s, f, PTEXF_LEFT)) {
      ptexf_split_left(k, &ka);
      if (split_t) {
        if (ptexf_walks(s, f, PTEXF_TOP)) { ptexf_split_top(&ka, &kc); ptexf_corner(s, &kc, faceid, f, PTEXF_LEFT); }
        else ptexf_merge_top(&ka, vmode);
      }
      if (split_b) {
        if (ptexf_walks(s, f, PTEXF_BOTTOM)) { ptexf_split_bottom(&ka, &kc); ptexf_corner(s, &kc, faceid, f, PTEXF_BOTTOM); }
        else ptexf_merge_bottom(&ka, vmode);
      }
      ptexf_across_edge(s, &ka, f, PTEXF_LEFT);
    } else {
      ptexf_merge_left(k, umode);
    }
  }
  if (split_t) {
    if (ptexf_walks(s, f, PTEXF_TOP)) { ptexf_split_top(k, &ka); ptexf_across_edge(s, &ka, f, PTEXF_TOP); }
    else ptexf_merge_top(k, vmode);
  }
  if (split_b) {
    if (ptexf_walks(s, f, PTEXF_BOTTOM)) { ptexf_split_bottom(k, &ka); ptexf_across_edge(s, &ka, f, PTEXF_BOTTOM); }
    else ptexf_merge_bottom(k, vmode);
  }
  ptexf_apply(s, k, faceid);
}

/* Point lookup q: the texel under (u, v) at the face's own resolution (a constant face's one value,
 * as the library's point filter gives it) divided by the type's one value; channels beyond the
 * texture's 0, a face out of range zeros (the texture has at least one face: the reader refuses a
 * file without). Nothing branches on the query, which keeps ptex_point_lookups' work-item loop short
 * (PoCL does not vectorise it: the loop holds the switch on the type and vector types); the
 * 4-value read (16 for halves) stays within SEAMCL_PTEX_TEXEL_TAIL. */
SEAMCL_INLINE float4 ptexf_point(const PtexfState* s, const PtexFilterQuery* q) {
  const PtexFilterFace f = s->faces[clamp(q->face, 0, s->tex.face_count - 1)];
  const bool flat = (f.flags & (SEAMCL_PTEX_FLAG_CONSTANT | SEAMCL_PTEX_FLAG_NEIGHBORHOOD_CONSTANT)) != 0u;
  const int ulog2 = flat ? 0 : f.ulog2, vlog2 = flat ? 0 : f.vlog2;
  const int resu = 1 << ulog2, resv = 1 << vlog2;
  const int ui = clamp((int)(q->u * (float)resu), 0, resu - 1);
  const int vi = clamp((int)(q->v * (float)resv), 0, resv - 1);
  const uint index = (ptexf_level(s, f, ulog2, vlog2) + (uint)(vi * resu + ui)) * (uint)s->tex.channels;
  float4 value;
  switch (s->tex.data_type) {
    case 0: value = convert_float4(vload4(0, s->texels + index)); break;
    case 1: value = convert_float4(vload4(0, (__global const ushort*)s->texels + index)); break;
    case 2: value = ptexf_halves_to_float16(vload16(0, (__global const ushort*)s->texels + index)).s0123; break;
    default: value = vload4(0, (__global const float*)s->texels + index); break;
  }
  const int channels = q->face >= 0 && q->face < s->tex.face_count ? s->tex.channels : 0;
  return select((float4)(0.0f), value / s->tex.one_value, (int4)(0, 1, 2, 3) < (int4)(channels));
}

/* Lookup q on the texture s reads (s->tex, faces, level_offsets, texels): 4 floats into out,
 * channels beyond the texture's 0. */
SEAMCL_INLINE void ptexf_lookup(PtexfState* s, const PtexFilterQuery* q, float* out) {
  for (int c = 0; c < 4; ++c) out[c] = 0.0f;
  /* Before any coordinate is used: a fragment without a finite (u, v) comes with face -1. */
  if (q->face < 0 || q->face >= s->tex.face_count) return;
  const PtexFilterFace f = s->faces[q->face];
  if (q->filter == SEAMCL_PTEX_POINT || (f.flags & SEAMCL_PTEX_FLAG_NEIGHBORHOOD_CONSTANT) != 0u) {
    vstore4(ptexf_point(s, q), 0, out);
    return;
  }
  s->weight = 0.0f;
  s->applied = 0.0f;
  for (int c = 0; c < 4; ++c) s->result[c] = 0.0f;
  const int nchan = s->tex.channels;
  float u = q->u, v = q->v;
  const int umode = s->tex.seams == SEAMCL_PTEX_SEAMS_PTEX ? s->tex.u_border_mode : 0;
  const int vmode = s->tex.seams == SEAMCL_PTEX_SEAMS_PTEX ? s->tex.v_border_mode : 0;
  bool black = false;
  if (umode == PTEXF_PERIODIC) u = u - floor(u);
  else if (umode == PTEXF_BLACK) black = u <= -1.0f || u >= 2.0f;
  else u = clamp(u, 0.0f, 1.0f);
  if (vmode == PTEXF_PERIODIC) v = v - floor(v);
  else if (vmode == PTEXF_BLACK) black = black || v <= -1.0f || v >= 2.0f;
  else v = clamp(v, 0.0f, 1.0f);
  if (black) return;
  PtexfKernel k;
  k.rot = 0;
  ptexf_build(&k, q, u, v, fabs(q->uw), fabs(q->vw), f.ulog2, f.vlog2);
  ptexf_strip_zeros(&k);
  if (k.uw <= 0 || k.vw <= 0) return;
  s->weight = ptexf_weight(&k);
  ptexf_split_and_apply(s, &k, q->face);
  const float w = (s->tex.seams == SEAMCL_PTEX_SEAMS_DISCARD ? s->applied : s->weight) * s->tex.one_value;
  if (!(w != 0.0f) || isinf(w) || isnan(w)) return;
  const float scale = 1.0f / w;
  for (int c = 0; c < nchan; ++c) out[c] = s->result[c] * scale;
}

#endif
