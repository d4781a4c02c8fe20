/* Stage 4: shade and resolve. One work-item per pixel, work-groups of one tile (16 x 16).
 *
 * SEAMCL_SHADE_PIXEL / _CENTROID: each distinct triangle among the pixel's samples is shaded once,
 * at the pixel centre (or, when it covers some but not all of them, the mean of the positions of
 * the samples it covers), and its colour
 * counts for the samples it covers; samples no triangle covers count the background. A centre
 * where the triangle's plane has 1/w <= 0 (extrapolated past the horizon) falls back to the
 * centroid, whose samples lie inside the triangle. SEAMCL_SHADE_SAMPLE shades every sample at its
 * own position. Resolve: box filter (mean over samples) into linear RGBA float, alpha 1.
 * Shading: uv and d(uv)/d(pixel) analytically from the 1/w, u/w, v/w planes, one texture lookup
 * (sample_texture with frame->sampler: the seam method), and lighting = light_color * (ambient + (1 - ambient) * max(0, n.l)) with the face normal.
 * Displaced renders (displaced.tessellation > 0, displacement_normals=displaced): n is the
 * displaced surface's normal instead (displaced_shading_normal): the micro-triangle's three
 * vertices' normals (tessellate.cl's displaced_normals, the same bits on both sides of a watertight
 * edge) weighted by the shading point's barycentrics in the triangle's domain uv (clamped to the
 * triangle), renormalised; where that has no length, the face normal.
 * Reflective faces (FaceGpu.reflective >= 0, scenes with an environment, built with
 * -DSEAMCL_CUBE=1 only) look the reflected view ray up in the cube map instead (shade_reflection),
 * and uncovered samples show the environment when frame->environment.skybox is set.
 * Seam mask (only in programs built with -DSEAMCL_SEAM_MASK=1, so that renders without it pay
 * nothing): per pixel, over its fragments (each sample's with SEAMCL_SHADE_SAMPLE), whether a
 * texture footprint crosses a face edge. A fragment's own filter (same point, footprint, filter
 * and anisotropy, border-addressed) crosses edge k when the same filter at the point mirrored
 * across edge k weighs more than SEAMCL_SEAM_WEIGHT_TOLERANCE inside the face (the filters are
 * symmetric, so this is the weight it puts beyond edge k); the same filter carried onto an edge
 * neighbour as traverse reads it (at the neighbour's own resolution, so a coarser neighbour's
 * taps reach further back) crosses when it weighs more than the tolerance inside the neighbour;
 * likewise carried onto the diagonal face past a valence-4 corner (what traverse reads there).
 * Each of these weighs 0 unevaluated where traverse's bound (neighbor_may_contribute) shows that
 * no tap can fall inside the face it is evaluated on; the own filter's weight (whether taps leave
 * the face past a corner only) is evaluated only where some edge's bound did not rule its mirror
 * out: elsewhere every tap lies inside.
 * With frame->mask_only the fragments are not shaded (they add black): a render for its mask alone.
 * SEAMCL_MASK_SEAM: some footprint crosses an edge shared with a neighbour (or leaves the face
 * past a corner only); else SEAMCL_MASK_BOUNDARY: some footprint crosses a mesh boundary edge
 * only; else SEAMCL_MASK_NONE, and there every seam method returns the same colour.
 * Without guard bands only (GUARD 0): a band would count as inside.
 * Ptex variant (SEAMCL_SAMPLER_FILTER = SEAMCL_FILTER_PTEX): the lookup is Ptex's own filter
 * (ptexf_lookup of ptex_filter.cl) on the .ptx's faces: (face, u, v, uw, vw) with uw = (|du/dx| +
 * |du/dy|) * width_scale, vw = (|dv/dx| + |dv/dy|) * width_scale (PtexFilter::eval's sums of a
 * renderer's derivatives), the seam rule in ptex.texture.seams; its channels shown through
 * ptex.rgb_source. A non-finite point shades black, a non-finite width reads a whole face.
 * Host guarantees: sample_triangle from raster of this frame; with displaced.tessellation > 0,
 * tess_vertices and tess_normals are this frame's tessellation (tessellate, displaced_normals) and
 * input triangle t of the setups is micro-triangle t (null buffers otherwise, never read);
 * seam_mask holds width * height
 * bytes when SEAMCL_SEAM_MASK is 1 (unused otherwise); in the Ptex variant, face i of the scene is
 * face i of ptex_faces (the other variants never read the ptex arguments; they may be null) and
 * no seam mask.
 * Twin: host/pipeline/stages/shade_resolve_twin.cpp (reflections:
 * host/pipeline/stages/shade_resolve_reflection_twin.cpp). */

#ifndef SEAMCL_CUBE
#define SEAMCL_CUBE 0
#endif

#ifndef SEAMCL_SEAM_MASK
#define SEAMCL_SEAM_MASK 0
#endif

#if defined(SEAMCL_SAMPLER_FILTER) && SEAMCL_SAMPLER_FILTER == SEAMCL_FILTER_PTEX
#define SEAMCL_SHADE_PTEX 1
typedef struct {
  PtexfState state;     /* the .ptx's buffers and texture record (seams: the render's rule) */
  PtexShading shading;
} PtexSource;
#else
#define SEAMCL_SHADE_PTEX 0
typedef int PtexSource; /* unused */
#endif

typedef struct {
  float u, v, dudx, dvdx, dudy, dvdy;
} SurfaceUv;

/* A displaced render's shading normals: the tessellated vertices (their domain uv) and
 * displaced_normals' unit normals; params.tessellation 0: none, the face normal lights. */
typedef struct {
  DisplacedShading params;
  __global const TessVertex* vertices;
  __global const float4* normals;
} DisplacedSource;

/* The lighting normal at domain point (u, v) of micro-triangle `tri`: the barycentrics of (u, v)
 * in the triangle's vertices' uv, each clamped to >= 0 (a shading point extrapolated past an edge
 * takes the normal of the triangle's nearest part), weighting the vertices' normals; renormalised.
 * (0, 0, 0) where that has no finite length (the caller falls back to the face normal).
 * Twin: displaced_shading_normal_reference (host/pipeline/stages/shade_resolve_twin.cpp). */
SEAMCL_INLINE float3 displaced_shading_normal(const DisplacedSource* d, int tri, float u, float v) {
  int id[3];
  tess_triangle_vertices(tri, d->params.tessellation, d->params.adaptive, id);
  const TessVertex a = d->vertices[id[0]], b = d->vertices[id[1]], c = d->vertices[id[2]];
  const float e1u = b.u - a.u, e1v = b.v - a.v, e2u = c.u - a.u, e2v = c.v - a.v;
  const float det = e1u * e2v - e2u * e1v;
  const float pu = u - a.u, pv = v - a.v;
  const float wb = (pu * e2v - e2u * pv) / det;
  const float wc = (e1u * pv - pu * e1v) / det;
  const float wa = 1.0f - wb - wc;
  const float ka = wa > 0.0f ? wa : 0.0f, kb = wb > 0.0f ? wb : 0.0f, kc = wc > 0.0f ? wc : 0.0f;
  const float4 na = d->normals[id[0]], nb = d->normals[id[1]], nc = d->normals[id[2]];
  const float nx = ka * na.x + kb * nb.x + kc * nc.x;
  const float ny = ka * na.y + kb * nb.y + kc * nc.y;
  const float nz = ka * na.z + kb * nb.z + kc * nc.z;
  const float length = sqrt(nx * nx + ny * ny + nz * nz);
  if (!(length > 0.0f) || !isfinite(length)) return (float3)(0.0f);
  return (float3)(nx / length, ny / length, nz / length);
}

SEAMCL_INLINE SurfaceUv interpolate_uv(__global const TriangleSetup* t, float x, float y) {
  const float dx = x - t->ref_x;
  const float dy = y - t->ref_y;
  const float inv_w = t->inv_w[0] + t->inv_w[1] * dx + t->inv_w[2] * dy;
  const float u_w = t->u_over_w[0] + t->u_over_w[1] * dx + t->u_over_w[2] * dy;
  const float v_w = t->v_over_w[0] + t->v_over_w[1] * dx + t->v_over_w[2] * dy;
  const float w = 1.0f / inv_w;
  SurfaceUv r;
  r.u = u_w * w;
  r.v = v_w * w;
  /* quotient rule: d(a/b) = (da - (a/b) db) / b */
  r.dudx = (t->u_over_w[1] - r.u * t->inv_w[1]) * w;
  r.dudy = (t->u_over_w[2] - r.u * t->inv_w[2]) * w;
  r.dvdx = (t->v_over_w[1] - r.v * t->inv_w[1]) * w;
  r.dvdy = (t->v_over_w[2] - r.v * t->inv_w[2]) * w;
  return r;
}

SEAMCL_INLINE float plane_inv_w(__global const TriangleSetup* t, float x, float y) {
  return t->inv_w[0] + t->inv_w[1] * (x - t->ref_x) + t->inv_w[2] * (y - t->ref_y);
}

#if SEAMCL_CUBE
/* The environment branch: compiled only into the programs of scenes with an environment, so that
 * the patch-texture path of the others keeps vectorising (the cube lookup does not). */
SEAMCL_INLINE float dot3(float3 a, float3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
SEAMCL_INLINE float3 load3(__global const float* p) { return (float3)(p[0], p[1], p[2]); }

/* The environment along direction d (its screen derivatives dx, dy), or, for the analytic
 * reference (SEAMCL_CUBE_DIRECTION), the unit direction scaled by 1 + roughness. */
__attribute__((noinline)) float3 environment_lookup(__constant FrameParams* frame, __global const float* cube_texels, float3 d,
                                        float3 dx, float3 dy, float roughness) {
  if (frame->environment.sampler.method == SEAMCL_CUBE_DIRECTION) {
    return d * ((1.0f + roughness) / sqrt(dot3(d, d)));
  }
  const float4 c = sample_cube(cube_texels, frame->environment.sampler, d.x, d.y, d.z, dx.x, dx.y, dx.z, dy.x, dy.y,
                               dy.z, roughness, -1.0f);
  return (float3)(c.x, c.y, c.z);
}

/* A reflective face at uv: the point (piecewise linear over the two triangles, as rasterised),
 * the normal (bilinear over the corners' normals, normalised), the view ray I from the eye and
 * R = I - 2 (N.I) N, with screen derivatives by the chain rule through d(uv)/d(pixel). */
__attribute__((noinline)) float3 shade_reflection(__constant FrameParams* frame, __global const ReflectiveFace* rf,
                                      __global const float* cube_texels, SurfaceUv s) {
  const float u = s.u, v = s.v;
  const float3 p0 = load3(rf->position[0]), p1 = load3(rf->position[1]);
  const float3 p2 = load3(rf->position[2]), p3 = load3(rf->position[3]);
  const float3 n0 = load3(rf->normal[0]), n1 = load3(rf->normal[1]);
  const float3 n2 = load3(rf->normal[2]), n3 = load3(rf->normal[3]);
  const int first_triangle = u >= v;
  const float3 pu = first_triangle ? p1 - p0 : p2 - p3;
  const float3 pv = first_triangle ? p2 - p1 : p3 - p0;
  const float3 eye = (float3)(frame->environment.eye[0], frame->environment.eye[1], frame->environment.eye[2]);
  const float3 view = p0 + pu * u + pv * v - eye;
  const float3 n = n0 * ((1.0f - u) * (1.0f - v)) + n1 * (u * (1.0f - v)) + n2 * (u * v) + n3 * ((1.0f - u) * v);
  const float3 nu = (n1 - n0) * (1.0f - v) + (n2 - n3) * v;
  const float3 nv = (n3 - n0) * (1.0f - u) + (n2 - n1) * u;
  const float inv_length = 1.0f / sqrt(dot3(n, n));
  const float3 normal = n * inv_length;
  /* d(n/|n|) = (dn - N (N.dn)) / |n| */
  const float3 dn_x = nu * s.dudx + nv * s.dvdx;
  const float3 dn_y = nu * s.dudy + nv * s.dvdy;
  const float3 dnormal_x = (dn_x - normal * dot3(normal, dn_x)) * inv_length;
  const float3 dnormal_y = (dn_y - normal * dot3(normal, dn_y)) * inv_length;
  const float3 dview_x = pu * s.dudx + pv * s.dvdx;
  const float3 dview_y = pu * s.dudy + pv * s.dvdy;
  const float n_dot_i = dot3(normal, view);
  const float3 r = view - normal * (2.0f * n_dot_i);
  const float3 dr_x = dview_x - (normal * (dot3(dnormal_x, view) + dot3(normal, dview_x)) + dnormal_x * n_dot_i) * 2.0f;
  const float3 dr_y = dview_y - (normal * (dot3(dnormal_y, view) + dot3(normal, dview_y)) + dnormal_y * n_dot_i) * 2.0f;
  return environment_lookup(frame, cube_texels, r, dr_x, dr_y, rf->roughness);
}

/* The skybox: the environment along the view ray through pixel-space point (x, y). */
SEAMCL_INLINE float3 shade_sky(__constant FrameParams* frame, __global const float* cube_texels, float x, float y) {
  __constant const EnvironmentParams* e = &frame->environment;
  const float3 dx = (float3)(e->ray_dx[0], e->ray_dx[1], e->ray_dx[2]);
  const float3 dy = (float3)(e->ray_dy[0], e->ray_dy[1], e->ray_dy[2]);
  const float3 d = (float3)(e->ray_corner[0], e->ray_corner[1], e->ray_corner[2]) + dx * x + dy * y;
  return environment_lookup(frame, cube_texels, d, dx, dy, 0.0f);
}
#endif

/* Shading a fragment reads its record, its face, the face's level table and then texels, each
 * found through the one before: at 99,037 faces every pixel's are new to the cache, and the misses
 * came one after another. So each work-item starts them for the pixels after it in its row, one
 * step of the chain each: the line at offset 64 of pixel x + 4's record (its face, and the planes
 * or part of them: a 112-byte record starts 0, 16, 32 or 48 bytes into a line), pixel x + 3's face
 * (whose record that line brought), pixel x + 2's level table (whose face), and the first line of
 * each of pixel x + 1's four finest levels (whose table). The lod is not known yet; at 99,037 faces
 * a face's levels are a few lines each (8x16 texels at level 0), so the lines a lookup reads are
 * mostly these. PoCL runs a group's work-items in x order. Prefetches change no result; the first
 * three steps pay on paper at both face counts, less at 16x and not with traverse; the texel step
 * only at 99,037 faces, whose small faces make these lines most of what a lookup reads
 * (docs/performance.md, "traverse" and "faces" rows). */
SEAMCL_INLINE void prefetch_ahead(__constant FrameParams* frame, __global const TriangleSetup* setups,
                                  __global const FaceGpu* faces, __global const uint* level_offsets,
                                  TEXEL_BUFFER texels, __global const uint* ids, int x) {
  const int samples = frame->sample_count;
  if (x + 4 < frame->width) {
    const uint slot = ids[4 * samples];
    if (slot != SEAMCL_NO_TRIANGLE) SEAMCL_PREFETCH((__global const char*)(setups + slot) + 64);
  }
  if (x + 3 < frame->width) {
    const uint slot = ids[3 * samples];
    if (slot != SEAMCL_NO_TRIANGLE) SEAMCL_PREFETCH(faces + setups[slot].face);
  }
  if (x + 2 < frame->width) {
    const uint slot = ids[2 * samples];
    if (slot != SEAMCL_NO_TRIANGLE) SEAMCL_PREFETCH(level_offsets + faces[setups[slot].face].level_table);
  }
  if (x + 1 < frame->width) {
    const uint slot = ids[samples];
    if (slot != SEAMCL_NO_TRIANGLE) {
      __global const FaceGpu* face = faces + setups[slot].face;
      const int levels = min(face->level_count, 4);
      for (int l = 0; l < levels; ++l) SEAMCL_PREFETCH(texels + TEXEL_WORDS * level_offsets[face->level_table + (uint)l]);
    }
  }
}

/* A pixel's sample slots in a 16-lane vector (lanes past `samples` repeat the first ones; the
 * masks below drop them). */
SEAMCL_INLINE uint16 pixel_sample_ids(__global const uint* ids, int samples) {
  uint16 v;
  if (samples == 16) {
    v = vload16(0, ids);
  } else if (samples == 8) {
    const uint8 h = vload8(0, ids);
    v = (uint16)(h, h);
  } else if (samples == 4) {
    const uint4 q = vload4(0, ids);
    v = (uint16)(q, q, q, q);
  } else {
    v = (uint16)(ids[0]);
    if (samples == 2) v.s1 = ids[1];
  }
  return v;
}

/* Bit l set where lane l of v equals value: an OR tree over disjoint bits. */
SEAMCL_INLINE uint lanes_equal(uint16 v, uint value) {
  const uint16 bits = select((uint16)(0u), (uint16)(1u, 2u, 4u, 8u, 16u, 32u, 64u, 128u, 256u, 512u, 1024u, 2048u,
                                                    4096u, 8192u, 16384u, 32768u),
                             v == (uint16)(value));
  const uint8 b8 = bits.lo | bits.hi;
  const uint4 b4 = b8.lo | b8.hi;
  const uint2 b2 = b4.lo | b4.hi;
  return b2.x | b2.y;
}

/* The index of the lowest set bit of x != 0. */
SEAMCL_INLINE int lowest_bit(uint x) { return (int)popcount((x & (0u - x)) - 1u); }

#if SEAMCL_SHADE_PTEX
/* Not inlined: the lookup is large, and the kernel calls shade_fragment twice (per sample, per
 * triangle); one copy keeps the variant's build short, as environment_lookup does. */
__attribute__((noinline)) float4 ptex_albedo(const PtexSource* ptex, int face, SurfaceUv s) {
  const PtexShading* p = &ptex->shading;
  PtexFilterQuery q;
  q.face = isfinite(s.u) && isfinite(s.v) ? face : -1;
  q.filter = p->filter;
  q.u = s.u;
  q.v = s.v;
  const float uw = (fabs(s.dudx) + fabs(s.dudy)) * p->width_scale;
  const float vw = (fabs(s.dvdx) + fabs(s.dvdy)) * p->width_scale;
  q.uw = isfinite(uw) ? uw : 1.0f;
  q.vw = isfinite(vw) ? vw : 1.0f;
  q.sharpness = p->sharpness;
  q.pad0 = 0;
  PtexfState state = ptex->state;
  float value[4];
  ptexf_lookup(&state, &q, value);
  float rgb[3];
  for (int o = 0; o < 3; ++o) rgb[o] = p->rgb_source[o] >= 0 ? value[p->rgb_source[o]] : 0.0f;
  return (float4)(rgb[0], rgb[1], rgb[2], 1.0f);
}
#endif

/* A call, not inlined: the kernel calls it from two loops (per sample; per pixel and triangle), and
 * each inlined copy holds the whole sampler, most of a variant's compile time. Shade time stayed
 * within 4% of the inlined kernel's either way (docs/performance.md, "What was tried"). */
SEAMCL_CALLED float3 shade_fragment(__constant FrameParams* frame, __global const TriangleSetup* t,
                             __global const FaceGpu* faces, __global const FaceNeighbors* neighbors,
                             __global const uint* level_offsets, TEXEL_BUFFER texels,
                             __global const float* srgb_to_linear, __global const ReflectiveFace* reflective_faces,
                             __global const float* cube_texels, const PtexSource* ptex, const DisplacedSource* displaced,
                             uint slot, float x, float y) {
  const SurfaceUv s = interpolate_uv(t, x, y);
#if SEAMCL_CUBE
  const int reflective = faces[t->face].reflective;
  if (reflective >= 0) return shade_reflection(frame, reflective_faces + reflective, cube_texels, s);
#endif
#if SEAMCL_SHADE_PTEX
  const float4 albedo = ptex_albedo(ptex, t->face, s);
#else
  (void)ptex;
  const float4 albedo = sample_texture(faces, neighbors, t->face, level_offsets, texels, srgb_to_linear, frame->sampler,
                                       s.u, s.v, s.dudx, s.dvdx, s.dudy, s.dvdy);
#endif
  __global const FaceGpu* face = faces + t->face;
  float3 n = (float3)(face->normal[0], face->normal[1], face->normal[2]);
  if (displaced->params.tessellation > 0) {
    /* Records are slot-major: slot k of input triangle t at k * input_triangles + t. */
    const float3 smooth = displaced_shading_normal(displaced, (int)(slot % (uint)frame->input_triangles), s.u, s.v);
    if (smooth.x != 0.0f || smooth.y != 0.0f || smooth.z != 0.0f) n = smooth;
  }
  const float n_dot_l = n.x * frame->light_dir[0] + n.y * frame->light_dir[1] + n.z * frame->light_dir[2];
  const float lighting = frame->ambient + (1.0f - frame->ambient) * fmax(n_dot_l, 0.0f);
  return (float3)(albedo.x * frame->light_color[0], albedo.y * frame->light_color[1],
                  albedo.z * frame->light_color[2]) * lighting;
}

#if SEAMCL_SEAM_MASK
/* A pixel's class over its fragments: seam over boundary over none. */
SEAMCL_INLINE uchar merge_mask(uchar a, uchar b) {
  return a == SEAMCL_MASK_SEAM || b == SEAMCL_MASK_SEAM ? (uchar)SEAMCL_MASK_SEAM
         : a == SEAMCL_MASK_BOUNDARY || b == SEAMCL_MASK_BOUNDARY ? (uchar)SEAMCL_MASK_BOUNDARY
                                                                  : (uchar)SEAMCL_MASK_NONE;
}

/* The weight the filter of `face` at (u, v) puts inside the face, border-addressed. A call: the
 * mask asks it up to 13 times per fragment, and each inlined copy is a whole filter. */
SEAMCL_CALLED float weight_inside(__constant FrameParams* frame, const FaceGpu* face, __global const uint* level_offsets,
                                  TEXEL_BUFFER texels, __global const float* srgb_to_linear, float u, float v,
                                  float dudx, float dvdx, float dudy, float dvdy) {
  return filter_texture(face, level_offsets, texels, srgb_to_linear, SAMPLER_FILTER(frame->sampler),
                        SEAMCL_ADDRESS_BORDER, frame->sampler.max_aniso, frame->sampler.lod_bias, u, v, dudx, dvdx,
                        dudy, dvdy)
      .weight;
}

/* Traverse's bound (neighbor_may_contribute): false when no tap of this frame's filter at a point
 * distance_u / distance_v outside face `g` (-1: the other axis, which never decides) can fall
 * inside it, so that its weight there is exactly 0 and need not be evaluated. */
SEAMCL_INLINE int may_weigh_inside(__constant FrameParams* frame, const FaceGpu* g, int swapped, float distance_u,
                                   float distance_v, const SurfaceUv* s) {
  return !SEAMCL_TRAVERSE_EARLY_OUT ||
         neighbor_may_contribute(g, swapped, SAMPLER_FILTER(frame->sampler), frame->sampler.max_aniso,
                                 frame->sampler.lod_bias, distance_u, distance_v, s->dudx, s->dvdx, s->dudy, s->dvdy);
}

/* The weight the same filter puts inside face `other` at this point and footprint carried into its
 * uv by the map (an edge's or a corner's), as traverse reads it there: 0 where traverse's bound
 * rules the face out (distance_u / distance_v from it, as may_weigh_inside). */
SEAMCL_INLINE float weight_carried(__constant FrameParams* frame, __global const FaceGpu* faces, int other,
                                   uint map, float distance_u, float distance_v, __global const uint* level_offsets,
                                   TEXEL_BUFFER texels, __global const float* srgb_to_linear, const SurfaceUv* s) {
  const FaceGpu g = faces[other];
  if (!may_weigh_inside(frame, &g, (map & SEAMCL_MAP_SWAP) != 0, distance_u, distance_v, s)) return 0.0f;
  const UvMap decoded = decode_uv_map(map);
  const float* m = decoded.t;
  return weight_inside(frame, &g, level_offsets, texels, srgb_to_linear, m[0] * s->u + m[1] * s->v + m[2],
                       m[3] * s->u + m[4] * s->v + m[5], m[0] * s->dudx + m[1] * s->dvdx,
                       m[3] * s->dudx + m[4] * s->dvdx, m[0] * s->dudy + m[1] * s->dvdy,
                       m[3] * s->dudy + m[4] * s->dvdy);
}

SEAMCL_INLINE uchar footprint_class(__constant FrameParams* frame, __global const TriangleSetup* t,
                                    __global const FaceGpu* faces, __global const FaceNeighbors* neighbors,
                                    __global const uint* level_offsets, TEXEL_BUFFER texels,
                                    __global const float* srgb_to_linear, float x, float y) {
  const SurfaceUv s = interpolate_uv(t, x, y);
  const FaceGpu face = faces[t->face];
  __global const FaceNeighbors* n = neighbors + t->face;
  const float tolerance = SEAMCL_SEAM_WEIGHT_TOLERANCE;
  int seam = 0, boundary = 0, any_edge = 0;
  /* Whether some edge's bound left the mirror to be evaluated: where none did, every tap lies
   * inside the face and the own weight below is whole. */
  int near_edge = 0;
  /* How far the point lies inside each edge (as traverse measures it): the distance its mirror
   * and its carried footprints lie outside the face they are evaluated on. */
  const float inside[4] = {s.v, 1.0f - s.u, 1.0f - s.v, s.u};
  for (int k = 0; k < 4; ++k) {
    /* Mirrored across edge k: v = 0, u = 1, v = 1, u = 0. */
    const int across_v = (k & 1) == 0;
    const float distance_u = across_v ? -1.0f : inside[k], distance_v = across_v ? inside[k] : -1.0f;
    const float offset = k == 1 || k == 2 ? 2.0f : 0.0f;
    const float mu = across_v ? s.u : offset - s.u, mv = across_v ? offset - s.v : s.v;
    const float mdudx = across_v ? s.dudx : -s.dudx, mdudy = across_v ? s.dudy : -s.dudy;
    const float mdvdx = across_v ? -s.dvdx : s.dvdx, mdvdy = across_v ? -s.dvdy : s.dvdy;
    const int may_cross = may_weigh_inside(frame, &face, 0, distance_u, distance_v, &s);
    near_edge |= may_cross;
    const float beyond = may_cross ? weight_inside(frame, &face, level_offsets, texels, srgb_to_linear, mu, mv, mdudx,
                                                   mdvdx, mdudy, mdvdy)
                                   : 0.0f;
    const int crosses = !(beyond <= tolerance);
    any_edge |= crosses;
    const int other = n->neighbor[k];
    if (other < 0) {
      boundary |= crosses;
      continue;
    }
    const float reach = weight_carried(frame, faces, other, n->edge_map[k], distance_u, distance_v, level_offsets,
                                       texels, srgb_to_linear, &s);
    seam |= crosses | !(reach <= tolerance);
  }
  /* The diagonal face past each valence-4 corner, as traverse reads it: a coarser one's taps can
   * reach back over the corner although no edge's footprint crosses. Corner k lies between edges
   * k - 1 and k. */
  for (int k = 0; k < 4; ++k) {
    const int other = n->corner[k];
    if (other < 0) continue;
    const float a = inside[(k + 3) & 3], b = inside[k];
    const int b_along_v = (k & 1) == 0;
    const float reach = weight_carried(frame, faces, other, n->corner_map[k], b_along_v ? a : b, b_along_v ? b : a,
                                       level_offsets, texels, srgb_to_linear, &s);
    seam |= !(reach <= tolerance);
  }
  /* Taps outside past a corner only (no edge's mirror saw them): a seam, to be safe. NaN weights (a
   * non-finite footprint, which no bound rules out) count as crossing: nothing shows they stay
   * inside. Evaluated last and only near an edge: most fragments lie too far inside their face
   * for any tap to leave it, and this was the one whole filter each of them paid. */
  if (!any_edge && near_edge) {
    const float own = weight_inside(frame, &face, level_offsets, texels, srgb_to_linear, s.u, s.v, s.dudx, s.dvdx,
                                    s.dudy, s.dvdy);
    seam |= !(own >= 1.0f - tolerance);
  }
  return seam ? (uchar)SEAMCL_MASK_SEAM : boundary ? (uchar)SEAMCL_MASK_BOUNDARY : (uchar)SEAMCL_MASK_NONE;
}
#endif

__kernel __attribute__((reqd_work_group_size(SEAMCL_TILE_SIZE, SEAMCL_TILE_SIZE, 1)))
void shade_resolve(__constant FrameParams* frame, __global const TriangleSetup* setups,
                   __global const FaceGpu* faces, __global const FaceNeighbors* neighbors,
                   __global const uint* level_offsets, TEXEL_BUFFER texels,
                   __global const float* srgb_to_linear, __global const uint* sample_triangle, __global float4* image,
                   __global FrameStats* stats, __global uchar* seam_mask,
                   __global const ReflectiveFace* reflective_faces, __global const float* cube_texels,
                   PtexShading ptex, __global const PtexFilterFace* ptex_faces, __global const uint* ptex_level_offsets,
                   __global const uchar* ptex_texels, DisplacedShading displaced,
                   __global const TessVertex* tess_vertices, __global const float4* tess_normals) {
  /* Fragments are summed per work-group without atomics: a locked add per pixel waits for the
   * pixel's image store to drain (docs/performance.md, "faces" rows). */
  __local uint group_fragments[SEAMCL_TILE_SIZE * SEAMCL_TILE_SIZE];
  const int x = (int)get_global_id(0);
  const int y = (int)get_global_id(1);
  uint fragments = 0;
#if SEAMCL_SHADE_PTEX
  PtexSource ptex_source;
  ptex_source.state.faces = ptex_faces;
  ptex_source.state.level_offsets = ptex_level_offsets;
  ptex_source.state.texels = ptex_texels;
  ptex_source.state.tex = ptex.texture;
  ptex_source.shading = ptex;
#else
  const PtexSource ptex_source = 0;
  (void)ptex;
  (void)ptex_faces;
  (void)ptex_level_offsets;
  (void)ptex_texels;
#endif
  DisplacedSource displaced_source;
  displaced_source.params = displaced;
  displaced_source.vertices = tess_vertices;
  displaced_source.normals = tess_normals;
  if (x < frame->width && y < frame->height) {
    const int samples = frame->sample_count;
    const int row = sample_pattern_row(samples);
    __global const uint* ids = sample_triangle + ((size_t)y * (size_t)frame->width + (size_t)x) * (size_t)samples;
    prefetch_ahead(frame, setups, faces, level_offsets, texels, ids, x);
    const float3 background = (float3)(frame->background[0], frame->background[1], frame->background[2]);
    float3 sum = (float3)(0.0f);
    int uncovered = 0;
    uchar crosses = SEAMCL_MASK_NONE;
    if (frame->shading_mode == SEAMCL_SHADE_SAMPLE) {
      for (int s = 0; s < samples; ++s) {
        const uint slot = ids[s];
        if (slot == SEAMCL_NO_TRIANGLE) {
          ++uncovered;
          continue;
        }
        const float sample_x = (float)sample_fixed_x(x, row, s) * (1.0f / SEAMCL_SUBPIXEL_ONE);
        const float sample_y = (float)sample_fixed_y(y, row, s) * (1.0f / SEAMCL_SUBPIXEL_ONE);
        if (!SEAMCL_SEAM_MASK || !frame->mask_only)
          sum += shade_fragment(frame, setups + slot, faces, neighbors, level_offsets, texels, srgb_to_linear, reflective_faces, cube_texels, &ptex_source,
                                &displaced_source, slot, sample_x, sample_y);
#if SEAMCL_SEAM_MASK
        crosses = merge_mask(crosses, footprint_class(frame, setups + slot, faces, neighbors, level_offsets, texels,
                                                      srgb_to_linear, sample_x, sample_y));
#endif
        ++fragments;
      }
    } else {
      /* Each distinct triangle once, in the order of its first sample (the lowest sample not yet
       * done), with the mask of the samples it holds: one vector compare of all of them. */
      const uint16 pixel_ids = pixel_sample_ids(ids, samples);
      uint remaining = (1u << samples) - 1u; /* samples <= SEAMCL_MAX_SAMPLES = 16 */
      while (remaining != 0) {
        const int s = lowest_bit(remaining);
        const uint slot = ids[s];
        const uint mask = (lanes_equal(pixel_ids, slot) | (1u << s)) & remaining;
        remaining &= ~mask;
        const int covered = (int)popcount(mask);
        if (slot == SEAMCL_NO_TRIANGLE) {
          uncovered = covered;
          continue;
        }
        float shade_x = (float)x + 0.5f;
        float shade_y = (float)y + 0.5f;
        /* Centroid shading keeps the centre when every sample is covered (as D3D and GL do): the
         * centroid of a full pattern is not the centre (16x: (-1/32, -1/32)). */
        const int partly_covered = covered < samples;
        if ((frame->shading_mode == SEAMCL_SHADE_CENTROID && partly_covered) ||
            !(plane_inv_w(setups + slot, shade_x, shade_y) > 0.0f)) {
          /* The mean of the covered samples' positions, summed in sample order. */
          float centroid_x = 0.0f, centroid_y = 0.0f;
          for (int r = s; r < samples; ++r) {
            if (((mask >> r) & 1u) == 0) continue;
            centroid_x += (float)sample_fixed_x(x, row, r) * (1.0f / SEAMCL_SUBPIXEL_ONE);
            centroid_y += (float)sample_fixed_y(y, row, r) * (1.0f / SEAMCL_SUBPIXEL_ONE);
          }
          shade_x = centroid_x / (float)covered;
          shade_y = centroid_y / (float)covered;
        }
        if (!SEAMCL_SEAM_MASK || !frame->mask_only)
          sum += shade_fragment(frame, setups + slot, faces, neighbors, level_offsets, texels, srgb_to_linear, reflective_faces, cube_texels, &ptex_source,
                                &displaced_source, slot, shade_x, shade_y) *
                 (float)covered;
#if SEAMCL_SEAM_MASK
        crosses = merge_mask(crosses, footprint_class(frame, setups + slot, faces, neighbors, level_offsets, texels,
                                                      srgb_to_linear, shade_x, shade_y));
#endif
        ++fragments;
      }
    }
    /* Added once, so that an empty pixel is exactly the background (n*b/n is exact for n a power
     * of two; b+b+b... rounds). */
#if SEAMCL_CUBE
    if (uncovered > 0 && frame->environment.skybox) {
      sum += shade_sky(frame, cube_texels, (float)x + 0.5f, (float)y + 0.5f) * (float)uncovered;
    } else {
      sum += background * (float)uncovered;
    }
#else
    sum += background * (float)uncovered;
#endif
    const float3 color = sum / (float)samples;
    image[(size_t)y * (size_t)frame->width + (size_t)x] = (float4)(color, 1.0f);
#if SEAMCL_SEAM_MASK
    seam_mask[(size_t)y * (size_t)frame->width + (size_t)x] = crosses;
#else
    (void)crosses;
#endif
  }
  group_fragments[get_local_id(1) * SEAMCL_TILE_SIZE + get_local_id(0)] = fragments;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0 && get_local_id(1) == 0) {
    uint sum = 0;
    for (int i = 0; i < SEAMCL_TILE_SIZE * SEAMCL_TILE_SIZE; ++i) sum += group_fragments[i];
    if (sum > 0) atomic_add(&stats->fragments, sum);
  }
}
