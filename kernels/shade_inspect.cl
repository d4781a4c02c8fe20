/* The pixel inspector (debug stage, compiled only into shading programs built with
 * -DSEAMCL_INSPECT=1; empty otherwise, so that renders pay nothing). One work-item per pixel of a
 * window of the last frame; it writes one InspectSample per sample (seamcl_types.h): the sample's
 * winning slot and face, the samples that share it, and the fragment that colours it, shaded as
 * shade_resolve shades it (the pixel centre, the centroid of the covered samples, or the sample
 * itself; the same functions: interpolate_uv, shade_fragment) with its lookup taken apart: the
 * footprint's axes in level-0 texels, the levels and probe count the frame's filter reads, the
 * tap weight inside the own face (the method's address mode) and, where traverse reads them, the
 * weight of each edge neighbour's and diagonal face's taps (accumulate_across, as traverse sums
 * them). Reflective faces (cube-map lookups) report their colour only. A displaced render's
 * fragments are lit as shade_resolve lights them: with the displaced surface's normals where
 * displaced.tessellation > 0, else with the face normal.
 * Host guarantees: the frame's setups, winners and scene buffers as shade_resolve read them (with
 * displaced.tessellation > 0, the frame's tess_vertices and tess_normals);
 * window inside the image; records holds window_width * window_height * sample_count records,
 * pixel-major, row-major within the window; the global size at least the window's (the items past
 * it return at once).
 * Twin: host/pipeline/stages/shade_inspect_twin.cpp. */

#ifndef SEAMCL_INSPECT
#define SEAMCL_INSPECT 0
#endif

#if SEAMCL_INSPECT
#if SEAMCL_SHADE_PTEX
/* The inspector renders with the seam mask, which a Ptex filter's render refuses. */
#error "the pixel inspector has no Ptex variant"
#endif
/* The levels, probe count and axes of a lookup on `face` with the frame's filter. */
SEAMCL_INLINE void inspect_levels(InspectSample* r, const FaceGpu* face, SamplerParams sampler, float dudx,
                                  float dvdx, float dudy, float dvdy) {
  const Footprint f = footprint(face, sampler.lod_bias, dudx, dvdx, dudy, dvdy);
  r->axis_x = sqrt(f.len2_x);
  r->axis_y = sqrt(f.len2_y);
  r->probes = 1;
  const float top = (float)(face->level_count - 1);
  const int filter = SAMPLER_FILTER(sampler);
  float lod;
  if (filter == SEAMCL_FILTER_BILINEAR) {
    lod = (float)bilinear_level(face, sampler.lod_bias);
  } else if (filter == SEAMCL_FILTER_TRILINEAR) {
    lod = trilinear_lod(face, f);
  } else if (filter == SEAMCL_FILTER_ANISO) {
    const AnisoProbes p = aniso_probes(face, 0.0f, 0.0f, f, sampler.max_aniso);
    r->probes = p.probes;
    lod = p.lod;
  } else {
    /* EWA: the minor axis, grown to major / max_aniso, picks the level (accumulate_ewa). */
    const float major2 = fmax(f.len2_x, f.len2_y);
    float minor2 = fmin(f.len2_x, f.len2_y);
    const float limit = (float)(sampler.max_aniso * sampler.max_aniso);
    if (minor2 * limit < major2 && minor2 > 0.0f) minor2 = major2 / limit;
    lod = !f.finite ? top : !(minor2 > 0.0f) ? 0.0f : lod_of(minor2) + f.lod_bias;
  }
  r->lod = fmin(fmax(lod, 0.0f), top);
  r->level0 = (int)r->lod;
  r->level1 = filter == SEAMCL_FILTER_BILINEAR ? r->level0 : min(r->level0 + 1, face->level_count - 1);
}

/* The weight of the own face's taps in the lookup, with the method's address mode. A call, as
 * inspect_across is: the inspector reads one window, and each inlined copy is a whole filter. */
SEAMCL_CALLED float inspect_own_weight(const FaceGpu* face, __global const uint* level_offsets, TEXEL_BUFFER texels,
                                       __global const float* srgb_to_linear, SamplerParams sampler, SurfaceUv s) {
  return filter_texture(face, level_offsets, texels, srgb_to_linear, SAMPLER_FILTER(sampler), SAMPLER_ADDRESS(sampler),
                        sampler.max_aniso, sampler.lod_bias, s.u, s.v, s.dudx, s.dvdx, s.dudy, s.dvdy)
      .weight;
}

/* The weight of face `other`'s taps in the lookup at (u, v) carried there by `map`, as traverse
 * sums it (0 for no face). A call: the kernel asks it at eight places. */
SEAMCL_CALLED float inspect_across(__global const FaceGpu* faces, int other, uint map, float distance_u,
                                   float distance_v, __global const uint* level_offsets, TEXEL_BUFFER texels,
                                   __global const float* srgb_to_linear, SamplerParams sampler, SurfaceUv s) {
  FilterSum sum = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
  accumulate_across(&sum, faces, other, map, distance_u, distance_v, level_offsets, texels, srgb_to_linear,
                    SAMPLER_FILTER(sampler), sampler.max_aniso, sampler.lod_bias, s.u, s.v, s.dudx, s.dvdx, s.dudy,
                    s.dvdy);
  return sum.weight;
}

__kernel void shade_inspect(__constant FrameParams* frame, __global const TriangleSetup* setups,
                            __global const FaceGpu* faces, __global const FaceNeighbors* neighbors,
                            __global const uint* level_offsets, TEXEL_BUFFER texels,
                            __global const float* srgb_to_linear, __global const uint* sample_triangle,
                            __global const ReflectiveFace* reflective_faces, __global const float* cube_texels,
                            DisplacedShading displaced, __global const TessVertex* tess_vertices,
                            __global const float4* tess_normals, int adjacency, int window_x, int window_y,
                            int window_width, int window_height, __global InspectSample* records) {
  const int wx = (int)get_global_id(0);
  const int wy = (int)get_global_id(1);
  if (wx >= window_width || wy >= window_height) return;
  const int x = window_x + wx;
  const int y = window_y + wy;
  const int samples = frame->sample_count;
  const int row = sample_pattern_row(samples);
  __global const uint* ids = sample_triangle + ((size_t)y * (size_t)frame->width + (size_t)x) * (size_t)samples;
  __global InspectSample* out = records + ((size_t)wy * (size_t)window_width + (size_t)wx) * (size_t)samples;
  const SamplerParams sampler = frame->sampler;
  DisplacedSource displaced_source;
  displaced_source.params = displaced;
  displaced_source.vertices = tess_vertices;
  displaced_source.normals = tess_normals;
  for (int s = 0; s < samples; ++s) {
    InspectSample r;
    const uint slot = ids[s];
    uint mask = 0;
    int first = -1;
    for (int q = 0; q < samples; ++q) {
      if (ids[q] != slot) continue;
      mask |= 1u << q;
      if (first < 0) first = q;
    }
    r.triangle = slot;
    r.coverage = mask;
    r.face = -1;
    r.probes = 0;
    r.x = r.y = r.u = r.v = r.dudx = r.dvdx = r.dudy = r.dvdy = r.axis_x = r.axis_y = r.lod = 0.0f;
    r.level0 = r.level1 = -1;
    r.reflective = 0;
    r.own_weight = 0.0f;
    for (int k = 0; k < 4; ++k) {
      r.edge_face[k] = r.corner_face[k] = -1;
      r.edge_weight[k] = r.corner_weight[k] = 0.0f;
    }
    r.color[0] = frame->background[0];
    r.color[1] = frame->background[1];
    r.color[2] = frame->background[2];
    r.color[3] = 1.0f;
    if (slot != SEAMCL_NO_TRIANGLE) {
      __global const TriangleSetup* t = setups + slot;
      const int covered = (int)popcount(mask);
      float px, py;
      if (frame->shading_mode == SEAMCL_SHADE_SAMPLE) {
        px = (float)sample_fixed_x(x, row, s) * (1.0f / SEAMCL_SUBPIXEL_ONE);
        py = (float)sample_fixed_y(y, row, s) * (1.0f / SEAMCL_SUBPIXEL_ONE);
      } else {
        px = (float)x + 0.5f;
        py = (float)y + 0.5f;
        if ((frame->shading_mode == SEAMCL_SHADE_CENTROID && covered < samples) || !(plane_inv_w(t, px, py) > 0.0f)) {
          float cx = 0.0f, cy = 0.0f;
          for (int q = first; q < samples; ++q) {
            if (((mask >> q) & 1u) == 0) continue;
            cx += (float)sample_fixed_x(x, row, q) * (1.0f / SEAMCL_SUBPIXEL_ONE);
            cy += (float)sample_fixed_y(y, row, q) * (1.0f / SEAMCL_SUBPIXEL_ONE);
          }
          px = cx / (float)covered;
          py = cy / (float)covered;
        }
      }
      const SurfaceUv uv = interpolate_uv(t, px, py);
      const FaceGpu face = faces[t->face];
      r.face = (int)t->face;
      r.x = px;
      r.y = py;
      r.u = uv.u;
      r.v = uv.v;
      r.dudx = uv.dudx;
      r.dvdx = uv.dvdx;
      r.dudy = uv.dudy;
      r.dvdy = uv.dvdy;
      const PtexSource no_ptex = 0;
      const float3 c = shade_fragment(frame, t, faces, neighbors, level_offsets, texels, srgb_to_linear,
                                      reflective_faces, cube_texels, &no_ptex, &displaced_source, slot, px, py);
      r.color[0] = c.x;
      r.color[1] = c.y;
      r.color[2] = c.z;
      if (face.reflective >= 0) {
        r.reflective = 1;
      } else {
        inspect_levels(&r, &face, sampler, uv.dudx, uv.dvdx, uv.dudy, uv.dvdy);
        r.own_weight = inspect_own_weight(&face, level_offsets, texels, srgb_to_linear, sampler, uv);
        const int traverse = SAMPLER_TRAVERSE(sampler);
        /* Without adjacency (packed only for the methods and masks that read it) the buffer is a
         * one-element stand-in: the faces around stay -1. */
        if (adjacency) {
          __global const FaceNeighbors* n = neighbors + t->face;
          const float inside[4] = {uv.v, 1.0f - uv.u, 1.0f - uv.v, uv.u};
          for (int k = 0; k < 4; ++k) {
            const int along_v = (k & 1) == 0;
            r.edge_face[k] = n->neighbor[k];
            r.corner_face[k] = n->corner[k];
            if (traverse == SEAMCL_TRAVERSE_NONE) continue;
            r.edge_weight[k] = inspect_across(faces, n->neighbor[k], n->edge_map[k], along_v ? -1.0f : inside[k],
                                              along_v ? inside[k] : -1.0f, level_offsets, texels, srgb_to_linear,
                                              sampler, uv);
            if (traverse != SEAMCL_TRAVERSE_CORNERS) continue;
            /* Corner k lies between edges k - 1 and k. */
            const float a = inside[(k + 3) & 3], b = inside[k];
            r.corner_weight[k] = inspect_across(faces, n->corner[k], n->corner_map[k], along_v ? a : b,
                                                along_v ? b : a, level_offsets, texels, srgb_to_linear, sampler, uv);
          }
        }
      }
    }
    out[s] = r;
  }
}
#endif
