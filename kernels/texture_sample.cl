/* Texture lookups over the per-face texel buffer (not a stage of its own: shading calls it).
 *
 * Inputs: a FaceGpu (level-0 size, level count, index of its level table), level_offsets (first
 * texel of each level), the texels, and SamplerParams. Texels are RGBA8 with sRGB-encoded RGB
 * (packed r | g << 8 | b << 16 | a << 24, decoded through the host's 256-entry table) or, when
 * the shading or sampling program is built with -DSEAMCL_TEXELS_F32=1, linear RGBA32F. Filtering is in linear RGB.
 * Coordinates: uv in face space; texel (i, j) of a W x H level is centred at ((i+.5)/W, (j+.5)/H);
 * derivatives are d(uv)/d(pixel).
 * Result: a FilterSum, the filtered colour and the summed weight of the taps that read inside the
 * level (1 unless the address mode is border). One place turns it into a colour: resolve_sum.
 * Mip levels: SamplerParams.lod_bias, read at run time (one program serves every bias), is added
 * to the level every filter computes from the footprint (trilinear's, each aniso probe's, EWA's)
 * before the clamp to the chain; bilinear, which has no footprint level, reads the level nearest
 * the bias (floor(lod_bias + 0.5)) clamped to the chain: level 0 for biases below 0.5. A
 * non-finite footprint reads the coarsest level whatever the bias.
 * Host guarantees: full chains down to 1x1, power-of-two sizes, offsets in range. Only texels of
 * the face's own levels are ever read, whatever the coordinates (NaN and infinities included).
 * Written for PoCL's vectoriser: scalar channels, no floor/log2 builtins, no float4 arithmetic.
 * Twin: host/pipeline/stages/texture_sample_twin.cpp. */

#ifndef SEAMCL_TEXELS_F32
#define SEAMCL_TEXELS_F32 0
#endif

/* Build-time specialisation: the host builds one program variant per sampler configuration, so
 * a kernel holds only the code its filter and method run. PoCL will not vectorise a kernel that
 * merely contains a varying-length loop (aniso, ewa), even where that loop is never taken.
 * Without the defines the kernels read the configuration from SamplerParams at run time. */
#ifdef SEAMCL_SAMPLER_FILTER
#define SAMPLER_FILTER(s) SEAMCL_SAMPLER_FILTER
#define SAMPLER_ADDRESS(s) SEAMCL_SAMPLER_ADDRESS
#define SAMPLER_RENORMALIZE(s) SEAMCL_SAMPLER_RENORMALIZE
#define SAMPLER_ZERO_COVERAGE(s) SEAMCL_SAMPLER_ZERO_COVERAGE
#define SAMPLER_TRAVERSE(s) SEAMCL_SAMPLER_TRAVERSE
#else
#define SAMPLER_FILTER(s) ((s).filter)
#define SAMPLER_ADDRESS(s) ((s).address)
#define SAMPLER_RENORMALIZE(s) ((s).renormalize)
#define SAMPLER_ZERO_COVERAGE(s) ((s).zero_coverage)
#define SAMPLER_TRAVERSE(s) ((s).traverse)
#endif

/* Guard bands (McDonald and Burley 2011): with -DSEAMCL_SAMPLER_GUARD_BAND=g every level is
 * stored with a band of g texels on each side, filled from the neighbours at build time; the
 * clamp address mode then clamps to the outside of the band instead of the face's edge texels.
 * A build-time constant of the program variant; 0 (no band) otherwise. */
#ifdef SEAMCL_SAMPLER_GUARD_BAND
#define GUARD SEAMCL_SAMPLER_GUARD_BAND
#else
#define GUARD 0
#endif

/* Ties against LLVM's SLP pass. PoCL vectorises a kernel by running its work-group loop 8 lanes
 * wide, and gives up if the loop body already holds short vectors, which the SLP pass makes out
 * of any two computations of the same shape (u and v, two taps, four channels). TIE(x) is 0 for
 * finite x but makes whatever it is added to depend on x, so the pair is no longer independent.
 * Kernels with a varying-length loop (aniso, ewa) stay scalar anyway; there a tie only costs, so
 * it is compiled out. */
#if defined(SEAMCL_SAMPLER_FILTER) && SEAMCL_SAMPLER_FILTER >= SEAMCL_FILTER_ANISO
#define TIE(x) 0.0f
#define TIED(value, x) (value)
#else
#define TIE(x) ((x) - (x))
/* value, unless x is NaN (then x): a select that orders value after x */
#define TIED(value, x) ((x) == (x) ? (value) : (x))
#endif
/* Build-time switch for the tests that run lookups with and without the early-outs (traverse's
 * neighbor_may_contribute and probes_reach_face, border-addressed aniso's probes past the edge)
 * and require the same bits; 1 (on) everywhere else. */
#ifndef SEAMCL_TRAVERSE_EARLY_OUT
#define SEAMCL_TRAVERSE_EARLY_OUT 1
#endif

/* How far past a face's edge (or its guard band's), in texels of the level read, a bilinear
 * probe can still weigh a texel inside: a tap weighs something only while the point lies less
 * than half a texel past the texel's edge; the 1/16 texel more absorbs the rounding of u * width - 0.5
 * (the value the filter floors) and, for probes_reach_face's whole-line test, of the probes'
 * positions summed step by step (the per-probe skip tests the very position it samples). Twin:
 * kTapReachTexels in host/pipeline/stages/texture_sample_twin.cpp. */
#define TAP_REACH_TEXELS 0.5625f

#if SEAMCL_TEXELS_F32
#define TEXEL_BUFFER __global const float*
#define TEXEL_WORDS 4 /* buffer elements per texel */
#else
#define TEXEL_BUFFER __global const uint*
#define TEXEL_WORDS 1
#endif

typedef struct {
  float r, g, b, a;  /* sum of weight * texel over taps inside */
  float weight;      /* sum of weight over taps inside */
} FilterSum;

typedef struct {
  uint offset;       /* first stored texel (the band's corner when there is a guard band) */
  int width, height; /* the face's texels, without the band */
  int stride;        /* stored texels per row: width + 2 GUARD */
} Level;

SEAMCL_INLINE Level face_level(const FaceGpu* face, __global const uint* level_offsets, int level) {
  Level l;
  l.offset = level_offsets[face->level_table + (uint)level];
  l.width = max(face->width >> level, 1);
  l.height = max(face->height >> level, 1);
  l.stride = l.width + 2 * GUARD;
  return l;
}

/* log2 for x > 0, within 5e-6: a polynomial on the mantissa (the builtin does not vectorise). */
SEAMCL_INLINE float approx_log2(float x) {
  const int bits = as_int(x);
  const float exponent = (float)(((bits >> 23) & 255) - 127);
  const float m = as_float((bits & 0x007fffff) | 0x3f800000) - 1.0f;
  const float p = m * (1.442517034f + m * (-0.7178983813f + m * (0.4568941740f + m * (-0.2773650501f +
                  m * (0.1219141394f + m * -0.02606630148f)))));
  return exponent + p;
}

/* weight * texel into sum, each channel TIED to the one before (see TIE). One fused multiply-add
 * a channel, rounded once as the twin's std::fma is: with FP_CONTRACT off a product and a sum
 * were two instructions and two roundings, and the aniso probe loop, which runs scalar, does
 * 22-26% more lookups a second without them (docs/performance.md, "What was tried"). */
SEAMCL_INLINE void add_texel(FilterSum* sum, TEXEL_BUFFER texels, __global const float* srgb_to_linear, uint index,
                             float weight) {
#if SEAMCL_TEXELS_F32
  const float r = texels[4 * index];
  const float g = texels[4 * index + 1];
  const float b = texels[4 * index + 2];
  const float a = texels[4 * index + 3];
#else
  const uint packed = texels[index];
  const float r = srgb_to_linear[packed & 0xffu];
  const float g = srgb_to_linear[(packed >> 8) & 0xffu];
  const float b = srgb_to_linear[(packed >> 16) & 0xffu];
  const float a = (float)(packed >> 24) * (1.0f / 255.0f);
#endif
  sum->r = fma(weight, r, sum->r);
  sum->g = fma(weight, TIED(g, sum->r), sum->g);
  sum->b = fma(weight, TIED(b, sum->g), sum->b);
  sum->a = fma(weight, TIED(a, sum->b), sum->a);
  sum->weight += weight;
}

/* Stored index along one axis of n texels (plus the guard band) of texel i for address mode
 * `address`; *inside is 0 for a border tap. */
SEAMCL_INLINE int address_texel(int i, int n, int address, float* inside) {
  const int clamped = clamp(i, -GUARD, n - 1 + GUARD);
  *inside = (address != SEAMCL_ADDRESS_BORDER || i == clamped) ? 1.0f : 0.0f;
  return address == SEAMCL_ADDRESS_WRAP ? (i & (n - 1)) : clamped + GUARD;
}

/* The texel after `first` (the addressed texel of raw index i), derived from it rather than
 * addressed afresh (see accumulate_bilinear). */
SEAMCL_INLINE int next_texel(int first, int i, int n, int address, float* inside) {
  *inside = (address != SEAMCL_ADDRESS_BORDER || (i >= -1 && i < n - 1)) ? 1.0f : 0.0f;
  return address == SEAMCL_ADDRESS_WRAP ? ((first + 1) & (n - 1)) : min(first + (i >= -GUARD ? 1 : 0), n - 1 + 2 * GUARD);
}

/* Texel-space coordinate of u on an axis of n texels, finite whatever u is. */
SEAMCL_INLINE float texel_coordinate(float u, int n, int address) {
  if (address == SEAMCL_ADDRESS_WRAP) u = u - __builtin_floorf(u);
  /* Two texels beyond the edge (or the band) is as far as any address mode can tell apart. */
  return fmin(fmax(u * (float)n - 0.5f, -2.0f - (float)GUARD), (float)(n + 1 + GUARD));
}

/* weight * bilinear(level, u, v) into sum.
 * The y side is tied to the x side, the second tap derived from the first and each weight from
 * the one before, so that no two computations have the same shape (see TIE). */
SEAMCL_INLINE void accumulate_bilinear(FilterSum* sum, TEXEL_BUFFER texels, __global const float* srgb_to_linear,
                                       Level level, float u, float v, float weight, int address) {
  const float x = texel_coordinate(u, level.width, address);
  const float x_floor = __builtin_floorf(x);
  const float fx = x - x_floor;
  const float y = texel_coordinate(v + TIE(fx), level.height, address);
  const float y_floor = __builtin_floorf(y);
  const float fy = y - y_floor;
  float in_x0, in_x1, in_y0, in_y1;
  const int ix = (int)x_floor;
  const int iy = (int)y_floor;
  const int x0 = address_texel(ix, level.width, address, &in_x0);
  const int x1 = next_texel(x0, ix, level.width, address, &in_x1);
  const int y0 = address_texel(iy, level.height, address, &in_y0);
  const int y1 = next_texel(y0, iy, level.height, address, &in_y1);
  const uint row0 = level.offset + (uint)(y0 * level.stride);
  const uint row1 = row0 + (uint)((y1 - y0) * level.stride);
  /* Bilinear weights, each derived from the one before. */
  const float w00 = (1.0f - fx) * (1.0f - fy);
  const float w10 = (1.0f - fy) - w00;
  const float w01 = (1.0f - fx) - w00;
  const float w11 = fy - w01;
  add_texel(sum, texels, srgb_to_linear, row0 + (uint)x0, weight * w00 * in_x0 * in_y0);
  add_texel(sum, texels, srgb_to_linear, row0 + (uint)x1, weight * w10 * in_x1 * in_y0);
  add_texel(sum, texels, srgb_to_linear, row1 + (uint)x0, weight * w01 * in_x0 * in_y1);
  add_texel(sum, texels, srgb_to_linear, row1 + (uint)x1, weight * w11 * in_x1 * in_y1);
}

/* weight * trilinear at `lod` (clamped to the chain) into sum. */
SEAMCL_INLINE void accumulate_trilinear(FilterSum* sum, const FaceGpu* face, __global const uint* level_offsets,
                                 TEXEL_BUFFER texels, __global const float* srgb_to_linear, float u, float v,
                                 float lod, float weight, int address) {
  lod = fmin(fmax(lod, 0.0f), (float)(face->level_count - 1));
  const int level0 = (int)lod;
  const int level1 = min(level0 + 1, face->level_count - 1);
  const float t = lod - (float)level0;
  accumulate_bilinear(sum, texels, srgb_to_linear, face_level(face, level_offsets, level0), u, v, weight * (1.0f - t), address);
  /* The second level tied to the first; the summed weight is finite. */
  accumulate_bilinear(sum, texels, srgb_to_linear, face_level(face, level_offsets, level1), u + TIE(sum->weight), v,
                      weight * t, address);
}

/* Screen axes of the footprint in level-0 texels, squared lengths. A non-finite footprint
 * (NaN or infinite derivatives) reads as infinitely large: the coarsest level. */
typedef struct {
  float ax_u, ax_v, ay_u, ay_v; /* d(uv)/dx and d(uv)/dy in uv units */
  float len2_x, len2_y;         /* squared lengths in level-0 texels */
  int finite;
  float lod_bias;               /* added to the level the filter makes of the axes */
} Footprint;

SEAMCL_INLINE Footprint footprint(const FaceGpu* face, float lod_bias, float dudx, float dvdx, float dudy, float dvdy) {
  Footprint f;
  f.lod_bias = lod_bias;
  const float w = (float)face->width, h = (float)face->height;
  f.ax_u = dudx;
  f.ax_v = dvdx;
  f.ay_u = dudy;
  f.ay_v = dvdy;
  /* Each term tied to the one before; a tie of a non-finite term is NaN, and a NaN length reads
   * as non-finite just as an infinite one does. */
  const float xu = dudx * w;
  const float xv = dvdx * h + TIE(xu);
  f.len2_x = xu * xu + xv * xv;
  const float yu = dudy * w + TIE(f.len2_x);
  const float yv = dvdy * h + TIE(yu);
  f.len2_y = yu * yu + yv * yv;
  f.finite = f.len2_x < INFINITY && f.len2_y < INFINITY;
  return f;
}

/* lod of a footprint whose longer axis has squared length len2 texels (level 0). */
SEAMCL_INLINE float lod_of(float len2) {
  return 0.5f * approx_log2(fmax(len2, 1e-30f));
}

/* The one level a bilinear lookup reads: the one nearest the bias, within the chain (a NaN bias
 * reads level 0). */
SEAMCL_INLINE int bilinear_level(const FaceGpu* face, float lod_bias) {
  return (int)__builtin_floorf(fmin(fmax(lod_bias + 0.5f, 0.0f), (float)(face->level_count - 1)));
}

/* How many times longer than at bias 0 the texels a lookup reads can be: 2^ceil(lod_bias) for a
 * positive bias, 1 otherwise (a negative bias reads finer texels, whose taps reach less far).
 * A power of two, so the early-outs' bounds multiplied by it round as before and stay monotone. */
SEAMCL_INLINE float bias_coarsening(float lod_bias) {
  const int steps = (int)__builtin_ceilf(fmin(fmax(lod_bias, 0.0f), 64.0f));
  return as_float((127 + steps) << 23);
}

/* The level whose texels are the coarsest a trilinear lookup at `lod` reads (the chain's clamp
 * applied as accumulate_trilinear applies it). */
SEAMCL_INLINE int coarser_level(const FaceGpu* face, float lod) {
  lod = fmin(fmax(lod, 0.0f), (float)(face->level_count - 1));
  return min((int)lod + 1, face->level_count - 1);
}

/* Whether a border-addressed lookup of bilinear probes on `level` of `face`, centred at (u, v) and
 * spread no further than (half_u, half_v) (uv) from it, can put weight on a texel inside the face.
 * A bilinear tap weighs something only while the point lies less than half a texel of its level
 * past the texel's edge (or the guard band's, which border addressing reads as inside); the test
 * allows TAP_REACH_TEXELS (half a texel and a sixteenth) and half a probe step more than the
 * spread, which absorbs the rounding of the probes' positions. Conservative: a lookup it rules out adds exactly nothing, so skipping it
 * changes no bit. A NaN anywhere reads as "may reach". */
SEAMCL_INLINE int probe_reaches_face(float u, float v, float reach_u, float reach_v) {
  return !(u + reach_u <= 0.0f || u - reach_u >= 1.0f || v + reach_v <= 0.0f || v - reach_v >= 1.0f);
}

/* 1 / max(side >> level, 1) for a power-of-two side, made from the exponent rather than divided:
 * the same bits as the division (both exact), without its latency. (A side that is not a power of
 * two, which the host never packs, gets 1 / the power of two below it: a larger reach.) */
SEAMCL_INLINE float inverse_level_side(int side, int level) {
  const int log2_side = 31 - (int)clz(side);
  return as_float((127 - max(log2_side - level, 0)) << 23);
}

SEAMCL_INLINE int probes_reach_face(const FaceGpu* face, int level, float u, float v, float half_u, float half_v) {
  return probe_reaches_face(u, v, half_u + (TAP_REACH_TEXELS + (float)GUARD) * inverse_level_side(face->width, level),
                            half_v + (TAP_REACH_TEXELS + (float)GUARD) * inverse_level_side(face->height, level));
}

/* log2 of a probe count 1..SEAMCL_MAX_PROBES, index N - 1 (see SEAMCL_LOG2_PROBE_COUNTS). */
__constant float log2_probe_count[SEAMCL_MAX_PROBES] = SEAMCL_LOG2_PROBE_COUNTS;

/* An aniso lookup's probe count N for a footprint's major / minor ratio: its ceiling, at most
 * SEAMCL_MAX_PROBES and max_aniso, and at least 1 whatever max_aniso is (N indexes
 * log2_probe_count). Texture and cube lookups alike. */
SEAMCL_INLINE int probe_count(float ratio, int max_aniso) {
  return max(min((int)__builtin_ceilf(fmin(ratio, (float)SEAMCL_MAX_PROBES)), max_aniso), 1);
}

/* The line of trilinear probes an aniso lookup takes, computed once so that the reach test of
 * traverse (probes_reach_face) and the filter read the same values. */
typedef struct {
  int probes;                 /* N */
  float weight;               /* 1 / N, each probe's */
  float lod;                  /* each probe's, bias included, before the chain's clamp */
  float step_u, step_v;       /* from one probe to the next (uv) */
  float first_u, first_v;     /* probe 0 */
} AnisoProbes;

SEAMCL_INLINE AnisoProbes aniso_probes(const FaceGpu* face, float u, float v, Footprint f, int max_aniso) {
  AnisoProbes p;
  const int x_major = f.len2_x >= f.len2_y;
  const float major2 = x_major ? f.len2_x : f.len2_y;
  const float minor2 = x_major ? f.len2_y : f.len2_x;
  /* N = min(ceil(major / minor), max_aniso) probes; ratio computed on squares, then sqrt. */
  /* A line footprint takes the most probes; a point footprint one. */
  const float ratio = minor2 > 0.0f ? sqrt(major2 / minor2) : major2 > 0.0f ? (float)max_aniso : 1.0f;
  p.probes = f.finite ? probe_count(ratio, max_aniso) : 1;
  p.weight = 1.0f / (float)p.probes;
  /* Each probe is trilinear at log2(major / N), plus the bias. */
  p.lod = f.finite ? lod_of(major2) - log2_probe_count[p.probes - 1] + f.lod_bias : (float)(face->level_count - 1);
  p.step_u = (x_major ? f.ax_u : f.ay_u) * p.weight;
  p.step_v = (x_major ? f.ax_v : f.ay_v) * p.weight;
  /* Probe i sits at (i + 0.5) / N - 0.5 of the major axis from the centre. */
  p.first_u = u + p.step_u * (0.5f - 0.5f * (float)p.probes);
  p.first_v = v + p.step_v * (0.5f - 0.5f * (float)p.probes);
  if (!f.finite) {
    p.first_u = u;
    p.first_v = v;
  }
  return p;
}

/* Border-addressed, a probe whose taps all lie outside the face adds exactly nothing (weight 0
 * times each texel): the probes past an edge are skipped, so that a lookup pays only for the
 * part of its footprint that lies on the face (discard's lookups at an edge, traverse's on a
 * neighbour). The test is probe_reaches_face's; the level is the coarser one the probes read. */
SEAMCL_INLINE void accumulate_probes(FilterSum* sum, const FaceGpu* face, __global const uint* level_offsets,
                                     TEXEL_BUFFER texels, __global const float* srgb_to_linear, AnisoProbes p,
                                     int address) {
  float pu = p.first_u;
  float pv = p.first_v;
  const int level = coarser_level(face, p.lod);
  const float reach_u = (TAP_REACH_TEXELS + (float)GUARD) * inverse_level_side(face->width, level);
  const float reach_v = (TAP_REACH_TEXELS + (float)GUARD) * inverse_level_side(face->height, level);
  for (int i = 0; i < p.probes; ++i) {
    if (!SEAMCL_TRAVERSE_EARLY_OUT || address != SEAMCL_ADDRESS_BORDER || probe_reaches_face(pu, pv, reach_u, reach_v)) {
      accumulate_trilinear(sum, face, level_offsets, texels, srgb_to_linear, pu, pv, p.lod, p.weight, address);
    }
    pu += p.step_u;
    pv += p.step_v;
  }
}

SEAMCL_INLINE void accumulate_aniso(FilterSum* sum, const FaceGpu* face, __global const uint* level_offsets,
                             TEXEL_BUFFER texels, __global const float* srgb_to_linear, float u, float v,
                             Footprint f, int max_aniso, int address) {
  accumulate_probes(sum, face, level_offsets, texels, srgb_to_linear, aniso_probes(face, u, v, f, max_aniso), address);
}

/* The trilinear filter's lod: the footprint's longer axis, plus the bias; a non-finite one reads the
 * coarsest level. */
SEAMCL_INLINE float trilinear_lod(const FaceGpu* face, Footprint f) {
  return f.finite ? lod_of(fmax(f.len2_x, f.len2_y)) + f.lod_bias : (float)(face->level_count - 1);
}

/* EWA over one level (pbrt-v4's MIPMap::EWA, Gaussian alpha = 2): the weights are divided by
 * their total over the whole ellipse, so sum.weight is the fraction of it inside the face. */
SEAMCL_INLINE void accumulate_ewa_level(FilterSum* sum, const FaceGpu* face, __global const uint* level_offsets,
                                 TEXEL_BUFFER texels, __global const float* srgb_to_linear, int level_index,
                                 float u, float v, float a_u, float a_v, float b_u, float b_v, float weight,
                                 int address) {
  const Level level = face_level(face, level_offsets, level_index);
  const float w = (float)level.width, h = (float)level.height;
  float s = u, t = v;
  if (address == SEAMCL_ADDRESS_WRAP) {
    s = s - __builtin_floorf(s);
    t = t - __builtin_floorf(t);
  }
  /* Centre and axes in texels of this level; the centre kept within two widths of the level. */
  const float cs = fmin(fmax(s * w - 0.5f, -2.0f * w - 2.0f), 3.0f * w + 2.0f);
  const float ct = fmin(fmax(t * h - 0.5f, -2.0f * h - 2.0f), 3.0f * h + 2.0f);
  const float x0 = a_u * w, y0 = a_v * h, x1 = b_u * w, y1 = b_v * h;
  float A = y0 * y0 + y1 * y1 + 1.0f;
  float B = -2.0f * (x0 * y0 + x1 * y1);
  float C = x0 * x0 + x1 * x1 + 1.0f;
  const float inv_f = 1.0f / (A * C - B * B * 0.25f);
  A *= inv_f;
  B *= inv_f;
  C *= inv_f;
  const float det = -B * B + 4.0f * A * C;
  const float inv_det = 1.0f / det;
  const float u_extent = 2.0f * inv_det * sqrt(det * C);
  const float v_extent = 2.0f * inv_det * sqrt(A * det);
  /* Bounded to two level widths around the level: a wider ellipse only repeats what it holds. */
  const int s0 = (int)fmax(__builtin_ceilf(cs - u_extent), -2.0f * w - 2.0f);
  const int s1 = (int)fmin(__builtin_floorf(cs + u_extent), 3.0f * w + 2.0f);
  const int t0 = (int)fmax(__builtin_ceilf(ct - v_extent), -2.0f * h - 2.0f);
  const int t1 = (int)fmin(__builtin_floorf(ct + v_extent), 3.0f * h + 2.0f);
  FilterSum level_sum = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  float total = 0.0f;
  for (int it = t0; it <= t1; ++it) {
    const float tt = (float)it - ct;
    float in_y;
    const int iy = address_texel(it, level.height, address, &in_y);
    for (int is = s0; is <= s1; ++is) {
      const float ss = (float)is - cs;
      const float r2 = A * ss * ss + B * ss * tt + C * tt * tt;
      if (r2 >= 1.0f) continue;
      const float gauss = exp(-2.0f * r2) - exp(-2.0f);
      float in_x;
      const int ix = address_texel(is, level.width, address, &in_x);
      total += gauss;
      add_texel(&level_sum, texels, srgb_to_linear, level.offset + (uint)(iy * level.stride + ix), gauss * in_x * in_y);
    }
  }
  const float scale = total > 0.0f ? weight / total : 0.0f;
  sum->r += level_sum.r * scale;
  sum->g += level_sum.g * scale;
  sum->b += level_sum.b * scale;
  sum->a += level_sum.a * scale;
  sum->weight += level_sum.weight * scale;
}

SEAMCL_INLINE void accumulate_ewa(FilterSum* sum, const FaceGpu* face, __global const uint* level_offsets,
                           TEXEL_BUFFER texels, __global const float* srgb_to_linear, float u, float v,
                           Footprint f, int max_aniso, int address) {
  if (!f.finite) {
    accumulate_trilinear(sum, face, level_offsets, texels, srgb_to_linear, u, v, (float)(face->level_count - 1), 1.0f, address);
    return;
  }
  /* Major axis first; clamp the eccentricity to max_aniso by growing the minor axis. */
  const int x_major = f.len2_x >= f.len2_y;
  float a_u = x_major ? f.ax_u : f.ay_u, a_v = x_major ? f.ax_v : f.ay_v;
  float b_u = x_major ? f.ay_u : f.ax_u, b_v = x_major ? f.ay_v : f.ax_v;
  const float major2 = x_major ? f.len2_x : f.len2_y;
  float minor2 = x_major ? f.len2_y : f.len2_x;
  const float limit = (float)(max_aniso * max_aniso);
  if (minor2 * limit < major2 && minor2 > 0.0f) {
    const float scale = sqrt(major2 / (minor2 * limit));
    b_u *= scale;
    b_v *= scale;
    minor2 = major2 / limit;
  }
  /* A minor axis of length 0 (a point or a line) is a level of minus infinity: no finite bias
   * lifts it off level 0. */
  if (!(minor2 > 0.0f)) {
    accumulate_bilinear(sum, texels, srgb_to_linear, face_level(face, level_offsets, 0), u, v, 1.0f, address);
    return;
  }
  /* The level where the minor axis spans about one texel, plus the bias. */
  const float lod = fmin(fmax(lod_of(minor2) + f.lod_bias, 0.0f), (float)(face->level_count - 1));
  const int level0 = (int)lod;
  const int level1 = min(level0 + 1, face->level_count - 1);
  const float t = lod - (float)level0;
  accumulate_ewa_level(sum, face, level_offsets, texels, srgb_to_linear, level0, u, v, a_u, a_v, b_u, b_v, 1.0f - t, address);
  if (t > 0.0f) {
    accumulate_ewa_level(sum, face, level_offsets, texels, srgb_to_linear, level1, u, v, a_u, a_v, b_u, b_v, t, address);
  }
}

/* The filtered sum of one lookup, before any renormalisation. */
SEAMCL_INLINE FilterSum filter_texture(const FaceGpu* face, __global const uint* level_offsets, TEXEL_BUFFER texels,
                                __global const float* srgb_to_linear, int filter, int address, int max_aniso,
                                float lod_bias, float u, float v, float dudx, float dvdx, float dudy, float dvdy) {
  FilterSum sum = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  const Footprint f = footprint(face, lod_bias, dudx, dvdx, dudy, dvdy);
  if (filter == SEAMCL_FILTER_BILINEAR) {
    accumulate_bilinear(&sum, texels, srgb_to_linear, face_level(face, level_offsets, bilinear_level(face, lod_bias)),
                        u, v, 1.0f, address);
  } else if (filter == SEAMCL_FILTER_TRILINEAR) {
    accumulate_trilinear(&sum, face, level_offsets, texels, srgb_to_linear, u, v, trilinear_lod(face, f), 1.0f, address);
  } else if (filter == SEAMCL_FILTER_ANISO) {
    accumulate_aniso(&sum, face, level_offsets, texels, srgb_to_linear, u, v, f, max_aniso, address);
  } else {
    accumulate_ewa(&sum, face, level_offsets, texels, srgb_to_linear, u, v, f, max_aniso, address);
  }
  return sum;
}

/* Whether any tap of a face whose shorter side is min_side texels and longer max_side (or of any
 * face no shorter and of no larger aspect: the bound only grows as min_side shrinks and max_side /
 * min_side grows) can weigh anything in an EWA lookup (derivatives in this face's uv) whose point
 * must travel at least distance_u along u and distance_v along v (uv, this face's frame; a
 * negative distance never decides) to reach the other face's square. Conservative: a neighbour
 * it rules out would add exactly nothing, so skipping it changes no bit of the result; it spares
 * interior lookups the neighbours' filters, with no division (the sides are powers of two, so
 * multiplying by them is exact). The bound, term by term, is argued in the twin
 * (host/pipeline/stages/texture_sample_twin.cpp, ewa_sides_may_contribute). min_side 0: never rules out. */
SEAMCL_INLINE int ewa_sides_may_contribute(float min_side, float max_side, float lod_bias, float distance_u,
                                           float distance_v, float dudx, float dvdx, float dudy, float dvdy) {
  const float axis_x = fabs(dudx) + fabs(dvdx);
  const float axis_y = fabs(dudy) + fabs(dvdy);
  const float axes = axis_x + axis_y;
  if (!(axes < INFINITY)) return 1;
  /* texel * min_side */
  const float texel_sides = fmin(min_side, fmax(2.0f, 2.01f * max_side * fmax(axis_x, axis_y) * bias_coarsening(lod_bias)));
  const float spread = (1.0f + max_side / min_side) * axes;
  /* The ellipse is widened by about a texel: it keeps a whole texel. */
  const float texel_reach = texel_sides * (1.0f + (float)GUARD);
  const float counted_u = distance_u > 2.0f ? 2.0f : distance_u;
  const float counted_v = distance_v > 2.0f ? 2.0f : distance_v;
  return !(min_side > 0.0f && (counted_u * min_side >= spread * min_side + texel_reach ||
                               counted_v * min_side >= spread * min_side + texel_reach));
}

/* The same for a bilinear, trilinear or aniso lookup, along one axis of this face's uv: whether
 * its point, `distance` (uv) inside the edge across that axis, is too far from a face whose side
 * along that axis is `side` texels and along the other axis `cross_side` texels for any tap to
 * reach it. x_a, y_a: the screen axes' components along this axis (d(uv)/dx and /dy, absolute,
 * finite), x_b, y_b: along the other. The same holds for any face whose side along this axis is
 * no shorter and whose cross_side / side is no larger (the bound grows as side shrinks and the
 * ratio grows), which is what the per-edge records of FaceNeighbors store. No division by a side
 * (powers of two: multiplying by them is exact). Argued term by term in the twin
 * (host/pipeline/stages/texture_sample_twin.cpp, axis_rules_out). side 0: never rules out. */
SEAMCL_INLINE int axis_rules_out(float side, float cross_side, int filter, int max_aniso, float lod_bias,
                                 float distance, float x_a, float x_b, float y_a, float y_b) {
  const float len_x = x_a * side + x_b * cross_side;
  const float len_y = y_a * side + y_b * cross_side;
  const float probe_len = filter == SEAMCL_FILTER_ANISO ? fmax(fmin(len_x, len_y), fmax(len_x, len_y) / (float)max_aniso)
                                                        : fmax(len_x, len_y);
  /* the coarsest texel read, in level-0 texels, at most the whole side */
  const float coarsening = bias_coarsening(lod_bias);
  const float texel_sides = filter == SEAMCL_FILTER_BILINEAR ? fmin(side, coarsening)
                                                             : fmin(side, fmax(2.0f, 2.01f * probe_len * coarsening));
  const float spread = filter == SEAMCL_FILTER_ANISO ? 0.5f * fmax(x_a, y_a) : 0.0f;
  const float texel_reach = texel_sides * (TAP_REACH_TEXELS + (float)GUARD);
  const float counted = distance > 2.0f ? 2.0f : distance;
  return side > 0.0f && counted * side >= spread * side + texel_reach;
}

/* Whether face `other` can receive weight from a lookup at distance_u / distance_v (as above) of
 * it; `swapped`: its uv axes run along this face's v and u (the map's linear part swaps them). */
SEAMCL_INLINE int neighbor_may_contribute(const FaceGpu* other, int swapped, int filter, int max_aniso, float lod_bias,
                                          float distance_u, float distance_v, float dudx, float dvdx, float dudy,
                                          float dvdy) {
  if (filter == SEAMCL_FILTER_EWA) {
    return ewa_sides_may_contribute((float)min(other->width, other->height), (float)max(other->width, other->height),
                                    lod_bias, distance_u, distance_v, dudx, dvdx, dudy, dvdy);
  }
  const float x_u = fabs(dudx), x_v = fabs(dvdx), y_u = fabs(dudy), y_v = fabs(dvdy);
  if (!(x_u + x_v + y_u + y_v < INFINITY)) return 1;
  const float side_u = (float)(swapped ? other->height : other->width);
  const float side_v = (float)(swapped ? other->width : other->height);
  return !(axis_rules_out(side_u, side_v, filter, max_aniso, lod_bias, distance_u, x_u, x_v, y_u, y_v) ||
           axis_rules_out(side_v, side_u, filter, max_aniso, lod_bias, distance_v, x_v, x_u, y_v, y_u));
}

/* A FaceNeighbors map byte as its coefficients: (u', v') = (t[0] u + t[1] v + t[2], t[3] u + t[4] v
 * + t[5]) (SEAMCL_MAP_* in seamcl_types.h; the host decodes it to the same floats). */
typedef struct {
  float t[6];
} UvMap;

SEAMCL_INLINE UvMap decode_uv_map(uint code) {
  const int swap = (code & SEAMCL_MAP_SWAP) != 0;
  const float su = (code & SEAMCL_MAP_NEGATE_U) != 0 ? -1.0f : 1.0f;
  const float sv = (code & SEAMCL_MAP_NEGATE_V) != 0 ? -1.0f : 1.0f;
  UvMap m;
  m.t[0] = swap ? 0.0f : su;
  m.t[1] = swap ? su : 0.0f;
  m.t[2] = (float)((int)((code >> SEAMCL_MAP_OFFSET_U_SHIFT) & 3u) - 1);
  m.t[3] = swap ? sv : 0.0f;
  m.t[4] = swap ? 0.0f : sv;
  m.t[5] = (float)((int)((code >> SEAMCL_MAP_OFFSET_V_SHIFT) & 3u) - 1);
  return m;
}

/* A FaceNeighbors reach side: 2^(stored - SEAMCL_SIDE_BIAS) built from its exponent bits (exact),
 * 0 for SEAMCL_SIDE_NONE. */
SEAMCL_INLINE float reach_side(uint stored) {
  return stored == SEAMCL_SIDE_NONE ? 0.0f : as_float((int)(stored - SEAMCL_SIDE_BIAS + 127u) << 23);
}

/* The same filter, border-addressed, on face `other` at this lookup's point and footprint carried
 * into its uv by the map t, added to `sum`: the taps that fall inside `other`. Most lookups lie
 * too far inside their own face to reach it: first a test on the footprint's size against the
 * distance (neighbor_may_contribute, no footprint in the other face's texels needed), then one on
 * the very probes the filter would take (their line and the coarser level's texel); either
 * skips the filter. EWA has only the first. */
SEAMCL_INLINE void accumulate_across(FilterSum* sum, __global const FaceGpu* faces, int other,
                                     uint map, float distance_u, float distance_v,
                                     __global const uint* level_offsets,
                                     TEXEL_BUFFER texels, __global const float* srgb_to_linear, int filter,
                                     int max_aniso, float lod_bias, float u, float v, float dudx, float dvdx,
                                     float dudy, float dvdy) {
  if (other < 0) return;
  const FaceGpu g = faces[other];
  const int early_out = SEAMCL_TRAVERSE_EARLY_OUT;
  if (early_out && !neighbor_may_contribute(&g, (map & SEAMCL_MAP_SWAP) != 0, filter, max_aniso, lod_bias, distance_u,
                                            distance_v, dudx, dvdx, dudy, dvdy)) {
    return;
  }
  const UvMap m = decode_uv_map(map);
  const float* t = m.t;
  const float gu = t[0] * u + t[1] * v + t[2];
  const float gv = t[3] * u + t[4] * v + t[5];
  const float gdudx = t[0] * dudx + t[1] * dvdx, gdvdx = t[3] * dudx + t[4] * dvdx;
  const float gdudy = t[0] * dudy + t[1] * dvdy, gdvdy = t[3] * dudy + t[4] * dvdy;
  FilterSum s = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  if (filter == SEAMCL_FILTER_BILINEAR) {
    const int level = bilinear_level(&g, lod_bias);
    if (early_out && !probes_reach_face(&g, level, gu, gv, 0.0f, 0.0f)) return;
    accumulate_bilinear(&s, texels, srgb_to_linear, face_level(&g, level_offsets, level), gu, gv, 1.0f,
                        SEAMCL_ADDRESS_BORDER);
  } else if (filter == SEAMCL_FILTER_TRILINEAR) {
    const float lod = trilinear_lod(&g, footprint(&g, lod_bias, gdudx, gdvdx, gdudy, gdvdy));
    if (early_out && !probes_reach_face(&g, coarser_level(&g, lod), gu, gv, 0.0f, 0.0f)) return;
    accumulate_trilinear(&s, &g, level_offsets, texels, srgb_to_linear, gu, gv, lod, 1.0f, SEAMCL_ADDRESS_BORDER);
  } else if (filter == SEAMCL_FILTER_ANISO) {
    const AnisoProbes p = aniso_probes(&g, gu, gv, footprint(&g, lod_bias, gdudx, gdvdx, gdudy, gdvdy), max_aniso);
    /* The probes lie within (N - 1) / 2 steps of the centre; N / 2 leaves half a step spare. */
    const float spread = 0.5f * (float)p.probes;
    if (early_out && !probes_reach_face(&g, coarser_level(&g, p.lod), gu, gv, spread * fabs(p.step_u),
                                        spread * fabs(p.step_v))) {
      return;
    }
    accumulate_probes(&s, &g, level_offsets, texels, srgb_to_linear, p, SEAMCL_ADDRESS_BORDER);
  } else {
    s = filter_texture(&g, level_offsets, texels, srgb_to_linear, filter, SEAMCL_ADDRESS_BORDER, max_aniso, lod_bias,
                       gu, gv, gdudx, gdvdx, gdudy, gdvdy);
  }
  sum->r += s.r;
  sum->g += s.g;
  sum->b += s.b;
  sum->a += s.a;
  sum->weight += s.weight;
}

/* Traverse (McDonald 2013, the paper's Listing 1): the same filter, border-addressed, on each
 * edge neighbour at this lookup's point and footprint carried into the neighbour's uv, summed
 * into `sum`. With `corners` (traverse; traverse-edges leaves them out), also on the diagonal
 * face past each valence-4 corner, as Ptex's filter does, so the 3x3 faces around are read.
 * Taps past a corner of any other valence, or past a mesh boundary, are not read and weigh zero:
 * the final renormalisation spreads their weight over the rest, as Discard does everywhere. */
SEAMCL_INLINE void accumulate_neighbors(FilterSum* sum, __global const FaceGpu* faces,
                                        __global const FaceNeighbors* neighbors, uint face_index,
                                        __global const uint* level_offsets, TEXEL_BUFFER texels,
                                        __global const float* srgb_to_linear, int filter, int max_aniso,
                                        float lod_bias, int corners, float u, float v, float dudx, float dvdx,
                                        float dudy, float dvdy) {
  __global const FaceNeighbors* n = neighbors + face_index;
  /* How far the point lies inside each edge: the least distance to the face across it, along v
   * (edges 0 and 2) or u (1 and 3); the other axis never decides (-1). */
  const float inside[4] = {v, 1.0f - u, 1.0f - v, u};
  /* First, from this face's record alone, whether the lookup lies too far inside edge k for any
   * face across it or past its ends (the sides stored per edge bound theirs: the smallest min
   * side and the largest aspect give the largest reach), so that an interior lookup decides with
   * four tests and reads no other face's record. A bit set: edge k may reach something. */
  const int early_out = SEAMCL_TRAVERSE_EARLY_OUT;
  int edge_may_reach = 15;
  const float x_u = fabs(dudx), x_v = fabs(dvdx), y_u = fabs(dudy), y_v = fabs(dvdy);
  if (early_out && filter != SEAMCL_FILTER_EWA && x_u + x_v + y_u + y_v < INFINITY) {
    edge_may_reach = 0;
    for (int k = 0; k < 4; ++k) {
      const int along_v = (k & 1) == 0;
      const int ruled_out = axis_rules_out(reach_side(n->reach_min_side[k]), reach_side(n->reach_max_side[k]), filter,
                                           max_aniso, lod_bias, inside[k],
                                           along_v ? x_v : x_u, along_v ? x_u : x_v, along_v ? y_v : y_u,
                                           along_v ? y_u : y_v);
      edge_may_reach |= (ruled_out ? 0 : 1) << k;
    }
  }
  if (edge_may_reach == 0) return;
  for (int k = 0; k < 4; ++k) {
    if (((edge_may_reach >> k) & 1) == 0) continue;
    const int along_v = (k & 1) == 0;
    accumulate_across(sum, faces, n->neighbor[k], n->edge_map[k], along_v ? -1.0f : inside[k],
                      along_v ? inside[k] : -1.0f, level_offsets, texels, srgb_to_linear, filter, max_aniso, lod_bias,
                      u, v, dudx, dvdx, dudy, dvdy);
  }
  if (!corners) return;
  /* Corner k lies between edges k-1 and k: past both; either edge's test rules it out. */
  for (int k = 0; k < 4; ++k) {
    if (((edge_may_reach >> k) & (edge_may_reach >> ((k + 3) & 3)) & 1) == 0) continue;
    const float a = inside[(k + 3) & 3], b = inside[k];
    const int b_along_v = (k & 1) == 0;
    accumulate_across(sum, faces, n->corner[k], n->corner_map[k], b_along_v ? a : b, b_along_v ? b : a,
                      level_offsets, texels, srgb_to_linear, filter, max_aniso, lod_bias, u, v, dudx, dvdx, dudy,
                      dvdy);
  }
}

/* One texture lookup as a seam method asks for it: the one place where a FilterSum becomes a
 * colour. Without renormalisation the sum is the colour (border taps added black). With it
 * (discard, traverse), colour = sum / weight over the taps read; when none was, zero_coverage
 * decides: a clamped trilinear lookup at the centre clamped to the face, or the raw 0/0. */
/* The colour of a lookup's FilterSum as the seam method asks for it (see sample_texture). */
SEAMCL_INLINE float4 resolve_sum(FilterSum sum, const FaceGpu* face, __global const uint* level_offsets,
                                 TEXEL_BUFFER texels, __global const float* srgb_to_linear, SamplerParams sampler,
                                 float u, float v, float dudx, float dvdx, float dudy, float dvdy) {
  if (!SAMPLER_RENORMALIZE(sampler)) return (float4)(sum.r, sum.g, sum.b, sum.a);
  const int clamp_when_uncovered = SAMPLER_ZERO_COVERAGE(sampler) == SEAMCL_ZERO_COVERAGE_CLAMP;
  if (clamp_when_uncovered && sum.weight == 0.0f) {
    sum = filter_texture(face, level_offsets, texels, srgb_to_linear, SEAMCL_FILTER_TRILINEAR, SEAMCL_ADDRESS_CLAMP,
                         sampler.max_aniso, sampler.lod_bias, fmin(fmax(u, 0.0f), 1.0f), fmin(fmax(v, 0.0f), 1.0f),
                         dudx, dvdx, dudy, dvdy);
  }
  const float inv_weight = 1.0f / sum.weight;
  return (float4)(sum.r * inv_weight, sum.g * inv_weight, sum.b * inv_weight, sum.a * inv_weight);
}

SEAMCL_INLINE float4 sample_texture(__global const FaceGpu* faces, __global const FaceNeighbors* neighbors,
                                    uint face_index, __global const uint* level_offsets, TEXEL_BUFFER texels,
                                    __global const float* srgb_to_linear, SamplerParams sampler,
                                    float u, float v, float dudx, float dvdx, float dudy, float dvdy) {
  const FaceGpu face = faces[face_index];
  FilterSum sum = filter_texture(&face, level_offsets, texels, srgb_to_linear, SAMPLER_FILTER(sampler),
                                 SAMPLER_ADDRESS(sampler), sampler.max_aniso, sampler.lod_bias, u, v, dudx, dvdx, dudy,
                                 dvdy);
  if (SAMPLER_TRAVERSE(sampler) != SEAMCL_TRAVERSE_NONE) {
    accumulate_neighbors(&sum, faces, neighbors, face_index, level_offsets, texels, srgb_to_linear,
                         SAMPLER_FILTER(sampler), sampler.max_aniso, sampler.lod_bias,
                         SAMPLER_TRAVERSE(sampler) == SEAMCL_TRAVERSE_CORNERS, u, v, dudx, dvdx, dudy, dvdy);
  }
  return resolve_sum(sum, &face, level_offsets, texels, srgb_to_linear, sampler, u, v, dudx, dvdx, dudy, dvdy);
}
