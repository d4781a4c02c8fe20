/* Cube-map lookups by direction (not a stage of its own: shading calls it, for reflective faces
 * and the skybox).
 *
 * Inputs: the cube's texels (linear RGBA32F, layout in CubeSampler's comment in seamcl_types.h),
 * a CubeSampler, a direction (any length, not zero) and its screen derivatives.
 * Face selection and face coordinates follow the major-axis table of the GL and Vulkan specs;
 * ties go to x, then y. On the selected face, uv = ((sc/|ma| + 1)/2, (tc/|ma| + 1)/2) and its
 * derivatives (quotient rule) make a footprint in level-0 texels, filtered as patch textures are:
 * bilinear (level 0), trilinear (log2 of the longer axis) or anisotropic (N probes along the
 * longer axis, each trilinear at log2(major / N)). A roughness lengthens both axes first (glossy).
 * The seam methods differ only in what a bilinear tap outside the face reads (cube_tap) and, for
 * fixup, fixup-level and fov, in the coordinates (cube_trilinear, cube_level_scale): see
 * SEAMCL_CUBE_* in seamcl_types.h.
 * Host guarantees: size a power of two, level_count = log2(size) + 1, texels of the whole cube
 * (with every level's border for SEAMCL_CUBE_BORDER).
 * Only texels of the cube are read, whatever the direction (NaN and zero included).
 * Twin: host/pipeline/stages/cube_sample_twin.cpp. */

/* The cube path is compiled as calls, not inlined: a fold can run at three taps of four in two
 * levels of up to 16 probes, and inlining every copy into shade_resolve made PoCL's compile of
 * that kernel many times slower. It does not vectorise in any case (its probe loop has a
 * per-item trip count). */
#define CUBE_CALL __attribute__((noinline))

/* A direction on its face. */
typedef struct {
  int face;
  float s, t;                    /* uv on the face, [0, 1] */
  float dsdx, dtdx, dsdy, dtdy;  /* per pixel */
  int valid;                     /* 0 for a zero or non-finite direction */
} CubeUv;

/* The face a direction selects (ties to x, then y) and its sc, tc, ma along any vector v = (v0,
 * v1, v2): the table's components of v for the face of d. */
SEAMCL_INLINE int cube_select_face(float x, float y, float z) {
  const float ax = fabs(x), ay = fabs(y), az = fabs(z);
  if (ax >= ay && ax >= az) return x < 0.0f ? 1 : 0;
  if (ay >= az) return y < 0.0f ? 3 : 2;
  return z < 0.0f ? 5 : 4;
}

SEAMCL_INLINE void cube_face_components(int face, float x, float y, float z, float* ma, float* sc, float* tc) {
  if (face == 0) { *ma = x;  *sc = -z; *tc = -y; }
  else if (face == 1) { *ma = -x; *sc = z;  *tc = -y; }
  else if (face == 2) { *ma = y;  *sc = x;  *tc = z; }
  else if (face == 3) { *ma = -y; *sc = x;  *tc = -z; }
  else if (face == 4) { *ma = z;  *sc = x;  *tc = -y; }
  else { *ma = -z; *sc = -x; *tc = -y; }
}

/* The point of `face` at (sc, tc): the inverse of cube_face_components with ma = 1. */
SEAMCL_INLINE void cube_face_point(int face, float sc, float tc, float* x, float* y, float* z) {
  if (face == 0) { *x = 1.0f;  *y = -tc; *z = -sc; }
  else if (face == 1) { *x = -1.0f; *y = -tc; *z = sc; }
  else if (face == 2) { *x = sc;   *y = 1.0f; *z = tc; }
  else if (face == 3) { *x = sc;   *y = -1.0f; *z = -tc; }
  else if (face == 4) { *x = sc;   *y = -tc; *z = 1.0f; }
  else { *x = -sc;  *y = -tc; *z = -1.0f; }
}

SEAMCL_INLINE CubeUv cube_project(float x, float y, float z, float dxx, float dxy, float dxz, float dyx, float dyy,
                                  float dyz) {
  CubeUv c;
  c.face = cube_select_face(x, y, z);
  float ma, sc, tc, dma_x, dsc_x, dtc_x, dma_y, dsc_y, dtc_y;
  cube_face_components(c.face, x, y, z, &ma, &sc, &tc);
  cube_face_components(c.face, dxx, dxy, dxz, &dma_x, &dsc_x, &dtc_x);
  cube_face_components(c.face, dyx, dyy, dyz, &dma_y, &dsc_y, &dtc_y);
  /* |sc|, |tc| <= ma holds for every finite direction; a NaN component fails it. */
  c.valid = ma > 0.0f && ma < INFINITY && fabs(sc) <= ma && fabs(tc) <= ma;
  if (!c.valid) {
    c.face = 0;
    ma = 1.0f;
    sc = tc = 0.0f;
  }
  const float inv = 1.0f / ma;
  const float u = sc * inv, v = tc * inv;
  c.s = 0.5f * (u + 1.0f);
  c.t = 0.5f * (v + 1.0f);
  /* d(sc/ma) = (dsc - (sc/ma) dma) / ma */
  c.dsdx = 0.5f * (dsc_x - u * dma_x) * inv;
  c.dtdx = 0.5f * (dtc_x - v * dma_x) * inv;
  c.dsdy = 0.5f * (dsc_y - u * dma_y) * inv;
  c.dtdy = 0.5f * (dtc_y - v * dma_y) * inv;
  return c;
}

/* First texel of level `level` of `face`: faces hold (4 n^2 - 1) / 3 texels, and the levels
 * above level l hold 4 (n^2 - m^2) / 3, m = n >> l. */
SEAMCL_INLINE uint cube_texel_index(int size, int face, int level, int i, int j) {
  const uint n = (uint)size;
  const uint m = max(n >> level, 1u);
  const uint face_start = (uint)face * ((4u * n * n - 1u) / 3u);
  const uint level_start = 4u * (n * n - m * m) / 3u;
  return face_start + level_start + (uint)j * m + (uint)i;
}

/* cube-border's layout: every m x m level stored as (m + 2) x (m + 2), i, j in -1..m. */
SEAMCL_INLINE uint cube_border_texel_index(int size, int face, int level, int i, int j) {
  const uint n = (uint)size;
  const uint m = max(n >> level, 1u);
  const uint levels = (uint)(31 - clz(n)) + 1u;
  const uint face_texels = (4u * n * n - 1u) / 3u + 8u * n - 4u + 4u * levels;
  const uint level_start = 4u * (n * n - m * m) / 3u + 8u * (n - m) + 4u * (uint)level;
  return (uint)face * face_texels + level_start + (uint)(j + 1) * (m + 2u) + (uint)(i + 1);
}

SEAMCL_INLINE void cube_add_texel(FilterSum* sum, __global const float* texels, uint index, float weight) {
  sum->r += weight * texels[4 * index];
  sum->g += weight * texels[4 * index + 1];
  sum->b += weight * texels[4 * index + 2];
  sum->a += weight * texels[4 * index + 3];
  sum->weight += weight;
}

/* The texel a seamless tap (i, j) outside an m x m level of `face` in exactly one axis reads:
 * the tap's centre, on the face's plane beyond the edge, is folded about the cube edge onto the
 * adjacent face (the out-of-range component becomes +-1 and the major one shrinks by as much as
 * it went past), where it is a texel centre again: the same texel grid, continued round the edge.
 * Taps at most m texels outside (the caller clamps), so the fold lands inside that face. */
CUBE_CALL uint cube_fold_texel(int size, int face, int level, int m, int i, int j) {
  const float sc = ((float)i + 0.5f) * 2.0f / (float)m - 1.0f;
  const float tc = ((float)j + 0.5f) * 2.0f / (float)m - 1.0f;
  float x, y, z;
  cube_face_point(face, sc, tc, &x, &y, &z);
  const int major = face >> 1;
  float past = 0.0f;
  if (major != 0 && fabs(x) > 1.0f) {
    past = fabs(x) - 1.0f;
    x = x > 0.0f ? 1.0f : -1.0f;
  } else if (major != 1 && fabs(y) > 1.0f) {
    past = fabs(y) - 1.0f;
    y = y > 0.0f ? 1.0f : -1.0f;
  } else if (major != 2 && fabs(z) > 1.0f) {
    past = fabs(z) - 1.0f;
    z = z > 0.0f ? 1.0f : -1.0f;
  }
  if (major == 0) x *= 1.0f - past;
  else if (major == 1) y *= 1.0f - past;
  else z *= 1.0f - past;
  const int other = cube_select_face(x, y, z);
  float ma, sc2, tc2;
  cube_face_components(other, x, y, z, &ma, &sc2, &tc2);
  const int i2 = clamp((int)__builtin_floorf((sc2 + 1.0f) * 0.5f * (float)m), 0, m - 1);
  const int j2 = clamp((int)__builtin_floorf((tc2 + 1.0f) * 0.5f * (float)m), 0, m - 1);
  return cube_texel_index(size, other, level, i2, j2);
}

/* One bilinear tap (i, j) of an m x m level with weight w, as the method reads it. */
CUBE_CALL void cube_tap(FilterSum* sum, __global const float* texels, int size, int face, int level, int m, int i,
                            int j, float w, int method) {
  const int out_i = i < 0 || i >= m;
  const int out_j = j < 0 || j >= m;
  const int ci = clamp(i, 0, m - 1), cj = clamp(j, 0, m - 1);
  if (method == SEAMCL_CUBE_BORDER) {
    /* The border holds what seamless reads one texel out; further out (aniso probes past the
     * face) clamps to the border. */
    cube_add_texel(sum, texels, cube_border_texel_index(size, face, level, clamp(i, -1, m), clamp(j, -1, m)), w);
  } else if (!out_i && !out_j) {
    cube_add_texel(sum, texels, cube_texel_index(size, face, level, i, j), w);
  } else if (method == SEAMCL_CUBE_DISCARD) {
    /* border zero: neither colour nor weight */
  } else if (method != SEAMCL_CUBE_SEAMLESS) {
    cube_add_texel(sum, texels, cube_texel_index(size, face, level, ci, cj), w);
  } else if (out_i && out_j) {
    /* Past a corner: the mean of the three texels that meet there (this face's corner texel and
     * the two edge neighbours' texels at that corner), as the Vulkan and GLES specs recommend. */
    const float third = w * (1.0f / 3.0f);
    cube_add_texel(sum, texels, cube_texel_index(size, face, level, ci, cj), third);
    cube_add_texel(sum, texels, cube_fold_texel(size, face, level, m, i, cj), third);
    cube_add_texel(sum, texels, cube_fold_texel(size, face, level, m, ci, j), third);
  } else {
    cube_add_texel(sum, texels, cube_fold_texel(size, face, level, m, i, j), w);
  }
}

/* The coordinate scale of an m x m level for the methods that scale per level: fixup-level's
 * (m - 1) / m puts a stretch-baked texel's direction on its texel centre at this level (the
 * post's 1 - exp2(lod) / n at this level's integer lod); fov's (m - 0.5) / m undoes the post's
 * FOV tweak, which spread the texel centres over m / (m - 0.5) of the face. 1 for the others. */
SEAMCL_INLINE float cube_level_scale(int method, int m) {
  if (method == SEAMCL_CUBE_FIXUP_LEVEL) return 1.0f - 1.0f / (float)m;
  if (method == SEAMCL_CUBE_FOV) return 1.0f - 0.5f / (float)m;
  return 1.0f;
}

CUBE_CALL void cube_bilinear(FilterSum* sum, __global const float* texels, int size, int face, int level, float s,
                                 float t, float weight, int method) {
  const int m = max(size >> level, 1);
  /* fixup-level and fov: this level's own scale about the face centre (see cube_level_scale). */
  const float scale = cube_level_scale(method, m);
  s = 0.5f + (s - 0.5f) * scale;
  t = 0.5f + (t - 0.5f) * scale;
  /* Seamless taps may reach one face width round an edge; for the others two texels out is as
   * far as clamp and border can tell apart. fmax also turns NaN into the bound. */
  const float lo = method == SEAMCL_CUBE_SEAMLESS ? -(float)m : -2.0f;
  const float hi = method == SEAMCL_CUBE_SEAMLESS ? 2.0f * (float)m - 2.0f : (float)m + 1.0f;
  const float x = fmin(fmax(s * (float)m - 0.5f, lo), hi);
  const float y = fmin(fmax(t * (float)m - 0.5f, lo), hi);
  const float x_floor = __builtin_floorf(x), y_floor = __builtin_floorf(y);
  const float fx = x - x_floor, fy = y - y_floor;
  const int ix = (int)x_floor, iy = (int)y_floor;
  const float w00 = (1.0f - fx) * (1.0f - fy);
  const float w10 = (1.0f - fy) - w00;
  const float w01 = (1.0f - fx) - w00;
  const float w11 = fy - w01;
  cube_tap(sum, texels, size, face, level, m, ix, iy, weight * w00, method);
  cube_tap(sum, texels, size, face, level, m, ix + 1, iy, weight * w10, method);
  cube_tap(sum, texels, size, face, level, m, ix, iy + 1, weight * w01, method);
  cube_tap(sum, texels, size, face, level, m, ix + 1, iy + 1, weight * w11, method);
}

/* The runtime fix of the post: on stretch-baked faces, the coordinates scaled about the face
 * centre by 1 - exp2(lod)/n = (m - 1)/m at an integer lod (m = n >> lod), which puts a direction
 * whose stretch-baked texel is i at texel coordinate i exactly. Fractional lods use the same
 * formula for both levels, as the post does. */
SEAMCL_INLINE float cube_fixup_scale(float lod, int size) { return 1.0f - exp2(lod) / (float)size; }

SEAMCL_INLINE void cube_trilinear(FilterSum* sum, __global const float* texels, CubeSampler cube, int face, float s,
                                  float t, float lod, float weight, int method) {
  lod = fmin(fmax(lod, 0.0f), (float)(cube.level_count - 1));
  if (method == SEAMCL_CUBE_FIXUP) {
    const float scale = cube_fixup_scale(lod, cube.size);
    s = 0.5f + (s - 0.5f) * scale;
    t = 0.5f + (t - 0.5f) * scale;
  }
  const int level0 = (int)lod;
  const int level1 = min(level0 + 1, cube.level_count - 1);
  const float f = lod - (float)level0;
  cube_bilinear(sum, texels, cube.size, face, level0, s, t, weight * (1.0f - f), method);
  cube_bilinear(sum, texels, cube.size, face, level1, s, t, weight * f, method);
}

/* The filtered sum on the selected face, before discard's renormalisation. explicit_lod >= 0:
 * one trilinear lookup at that lod (tests and seam measurements), whatever the filter. Every
 * filter is N probes along the footprint's longer axis, trilinear at one lod: one probe at the
 * centre except for aniso. */
CUBE_CALL FilterSum cube_filter(__global const float* texels, CubeSampler cube, CubeUv c, float roughness,
                                float explicit_lod, int method) {
  FilterSum sum = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  const float n = (float)cube.size;
  float ax_u = c.dsdx, ax_v = c.dtdx, ay_u = c.dsdy, ay_v = c.dtdy;
  float len2_x = (ax_u * ax_u + ax_v * ax_v) * (n * n);
  float len2_y = (ay_u * ay_u + ay_v * ay_v) * (n * n);
  if (roughness > 0.0f) {
    /* Glossy: each axis lengthened by a blur of roughness / 2 face widths (roughness 1: a
     * quarter of the cube's circumference), in quadrature with its own length. */
    const float blur = 0.5f * roughness;
    const float blur2 = blur * blur * n * n;
    if (len2_x > 0.0f) {
      const float k = sqrt((len2_x + blur2) / len2_x);
      ax_u *= k;
      ax_v *= k;
    } else {
      ax_u = blur;
      ax_v = 0.0f;
    }
    if (len2_y > 0.0f) {
      const float k = sqrt((len2_y + blur2) / len2_y);
      ay_u *= k;
      ay_v *= k;
    } else {
      ay_u = 0.0f;
      ay_v = blur;
    }
    len2_x += blur2;
    len2_y += blur2;
  }
  const int finite = c.valid && len2_x < INFINITY && len2_y < INFINITY;
  int probes = 1;
  float lod = (float)(cube.level_count - 1);
  float step_u = 0.0f, step_v = 0.0f;
  if (explicit_lod >= 0.0f) {
    lod = explicit_lod;
  } else if (!finite) {
    /* the coarsest level */
  } else if (cube.filter == SEAMCL_FILTER_BILINEAR) {
    lod = 0.0f;
  } else if (cube.filter == SEAMCL_FILTER_TRILINEAR) {
    lod = lod_of(fmax(len2_x, len2_y));
  } else {
    const int x_major = len2_x >= len2_y;
    const float major2 = x_major ? len2_x : len2_y;
    const float minor2 = x_major ? len2_y : len2_x;
    const float ratio = minor2 > 0.0f ? sqrt(major2 / minor2) : major2 > 0.0f ? (float)cube.max_aniso : 1.0f;
    probes = probe_count(ratio, cube.max_aniso);
    lod = lod_of(major2) - log2_probe_count[probes - 1];
    step_u = (x_major ? ax_u : ay_u) / (float)probes;
    step_v = (x_major ? ax_v : ay_v) / (float)probes;
  }
  const float inv_probes = 1.0f / (float)probes;
  float pu = c.s + step_u * (0.5f - 0.5f * (float)probes);
  float pv = c.t + step_v * (0.5f - 0.5f * (float)probes);
  for (int i = 0; i < probes; ++i) {
    cube_trilinear(&sum, texels, cube, c.face, pu, pv, lod, inv_probes, method);
    pu += step_u;
    pv += step_v;
  }
  return sum;
}

/* One cube-map lookup as the method asks for it: the one place where a cube FilterSum becomes a
 * colour. Discard divides by the weight of the taps inside the face; with none inside (a
 * footprint far wider than the face) it falls back to the clamped lookup, as patch discard does. */
SEAMCL_INLINE float4 sample_cube(__global const float* texels, CubeSampler cube, float x, float y, float z, float dxx,
                                 float dxy, float dxz, float dyx, float dyy, float dyz, float roughness,
                                 float explicit_lod) {
  const CubeUv c = cube_project(x, y, z, dxx, dxy, dxz, dyx, dyy, dyz);
  FilterSum sum = cube_filter(texels, cube, c, roughness, explicit_lod, cube.method);
  if (cube.method != SEAMCL_CUBE_DISCARD) return (float4)(sum.r, sum.g, sum.b, sum.a);
  if (sum.weight == 0.0f) sum = cube_filter(texels, cube, c, roughness, explicit_lod, SEAMCL_CUBE_CLAMP);
  const float inv_weight = 1.0f / sum.weight;
  return (float4)(sum.r * inv_weight, sum.g * inv_weight, sum.b * inv_weight, sum.a * inv_weight);
}
