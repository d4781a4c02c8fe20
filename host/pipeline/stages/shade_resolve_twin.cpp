#include "pipeline/stages/shade_resolve_twin.h"

#include <algorithm>
#include <cmath>

#include "pipeline/stages/ptex_filter_twin.h"
#include "pipeline/stages/raster_twin.h"
#include "pipeline/stages/sample_pattern.h"
#include "pipeline/stages/shade_resolve_reflection_twin.h"
#include "pipeline/stages/texture_sample_twin.h"

#include "pipeline/adjacency.h"

namespace seamcl {

SurfaceUv interpolate_uv(const TriangleSetup& t, float x, float y) {
  const float dx = x - t.ref_x;
  const float dy = y - t.ref_y;
  const float inv_w = t.inv_w[0] + t.inv_w[1] * dx + t.inv_w[2] * dy;
  const float u_w = t.u_over_w[0] + t.u_over_w[1] * dx + t.u_over_w[2] * dy;
  const float v_w = t.v_over_w[0] + t.v_over_w[1] * dx + t.v_over_w[2] * dy;
  const float w = 1.0f / inv_w;
  SurfaceUv r{};
  r.u = u_w * w;
  r.v = v_w * w;
  // u = (u/w) / (1/w): quotient rule for the derivatives.
  r.dudx = (t.u_over_w[1] - r.u * t.inv_w[1]) * w;
  r.dudy = (t.u_over_w[2] - r.u * t.inv_w[2]) * w;
  r.dvdx = (t.v_over_w[1] - r.v * t.inv_w[1]) * w;
  r.dvdy = (t.v_over_w[2] - r.v * t.inv_w[2]) * w;
  return r;
}

glm::vec3 displaced_shading_normal_reference(const DisplacedShadingReference& d, int tri, float u, float v) {
  // tessellated_setup's vertices of micro-triangle `tri` (kernels/tessellation_grid.h).
  const int t = d.params.tessellation;
  const int patch = tri / (2 * t * t), cell = (tri / 2) % (t * t), ci = cell % t, cj = cell / t;
  const bool flipped = d.params.adaptive && t >= 2 && ((ci == t - 1 && cj == 0) || (ci == 0 && cj == t - 1));
  static constexpr int kPlain[2][3][2] = {{{0, 0}, {1, 0}, {1, 1}}, {{0, 0}, {1, 1}, {0, 1}}};
  static constexpr int kFlipped[2][3][2] = {{{0, 0}, {1, 0}, {0, 1}}, {{1, 0}, {1, 1}, {0, 1}}};
  const auto& corners = (flipped ? kFlipped : kPlain)[tri & 1];
  size_t id[3];
  for (int k = 0; k < 3; ++k) {
    id[k] = (static_cast<size_t>(patch) * (t + 1) + static_cast<size_t>(cj + corners[k][1])) * (t + 1) +
            static_cast<size_t>(ci + corners[k][0]);
  }
  const TessVertex &a = d.vertices->at(id[0]), &b = d.vertices->at(id[1]), &c = d.vertices->at(id[2]);
  const float e1u = b.u - a.u, e1v = b.v - a.v, e2u = c.u - a.u, e2v = c.v - a.v;
  const float det = e1u * e2v - e2u * e1v;
  const float pu = u - a.u, pv = v - a.v;
  const float wb = (pu * e2v - e2u * pv) / det;
  const float wc = (e1u * pv - pu * e1v) / det;
  const float wa = 1.0f - wb - wc;
  const float ka = wa > 0.0f ? wa : 0.0f, kb = wb > 0.0f ? wb : 0.0f, kc = wc > 0.0f ? wc : 0.0f;
  const cl_float4 &na = d.normals->at(id[0]), &nb = d.normals->at(id[1]), &nc = d.normals->at(id[2]);
  const float nx = ka * na.s[0] + kb * nb.s[0] + kc * nc.s[0];
  const float ny = ka * na.s[1] + kb * nb.s[1] + kc * nc.s[1];
  const float nz = ka * na.s[2] + kb * nb.s[2] + kc * nc.s[2];
  const float length = std::sqrt(nx * nx + ny * ny + nz * nz);
  if (!(length > 0.0f) || !std::isfinite(length)) return glm::vec3(0.0f);
  return glm::vec3(nx / length, ny / length, nz / length);
}

glm::vec3 shade_fragment_reference(const PackedScene& scene, const FrameParams& f, const TriangleSetup& t, float x, float y,
                                   const std::vector<float>* cube_texels, const PtexRenderTexture* ptex,
                                   const DisplacedShadingReference* displaced, uint32_t slot) {
  const SurfaceUv s = interpolate_uv(t, x, y);
  const int reflective = scene.faces.at(t.face).reflective;
  if (reflective >= 0) return shade_reflection_reference(f, scene.reflective_faces.at(reflective), *cube_texels, s);
  const glm::vec4 albedo =
      ptex ? glm::vec4(ptex_albedo_twin(*ptex, static_cast<int>(t.face), s.u, s.v, s.dudx, s.dvdx, s.dudy, s.dvdy), 1.0f)
           : sample_texture_reference(scene.textures(), t.face, f.sampler, s.u, s.v, s.dudx, s.dvdx, s.dudy, s.dvdy);
  const FaceGpu& face = scene.faces.at(t.face);
  glm::vec3 n(face.normal[0], face.normal[1], face.normal[2]);
  if (displaced && displaced->params.tessellation > 0) {
    const glm::vec3 smooth =
        displaced_shading_normal_reference(*displaced, static_cast<int>(slot / SEAMCL_CLIP_SLOTS), s.u, s.v);
    if (smooth.x != 0.0f || smooth.y != 0.0f || smooth.z != 0.0f) n = smooth;
  }
  const float n_dot_l = n.x * f.light_dir[0] + n.y * f.light_dir[1] + n.z * f.light_dir[2];
  const float lighting = f.ambient + (1.0f - f.ambient) * std::fmax(n_dot_l, 0.0f);
  return glm::vec3(albedo.x * f.light_color[0], albedo.y * f.light_color[1], albedo.z * f.light_color[2]) * lighting;
}

uint8_t footprint_class(const PackedScene& scene, const FrameParams& f, const TriangleSetup& t, float x, float y) {
  const SurfaceUv s = interpolate_uv(t, x, y);
  const TextureView textures = scene.textures();
  auto weight_inside = [&](uint32_t face, float u, float v, float dudx, float dvdx, float dudy, float dvdy) {
    return filter_texture_reference(textures, face, f.sampler, SEAMCL_ADDRESS_BORDER, u, v, dudx, dvdx, dudy, dvdy).weight;
  };
  // Traverse's bound: false when no tap at a point distance_u / distance_v outside `face` (-1: the
  // axis that never decides) can fall inside it, so the weight there is exactly 0, unevaluated.
  auto may_weigh_inside = [&](const FaceGpu& face, bool swapped, float distance_u, float distance_v) {
    return neighbor_may_contribute(face, swapped, f.sampler.filter, f.sampler.max_aniso, f.sampler.lod_bias, 0,
                                   distance_u, distance_v, s.dudx, s.dvdx, s.dudy, s.dvdy);
  };
  // The same filter on face `other` at this point and footprint carried into its uv by map m.
  auto weight_carried = [&](int32_t other, uint8_t map, float distance_u, float distance_v) {
    const auto m = map_coefficients(map);
    if (!may_weigh_inside(scene.faces.at(static_cast<size_t>(other)), map_swaps_axes(m.data()), distance_u, distance_v))
      return 0.0f;
    return weight_inside(static_cast<uint32_t>(other), m[0] * s.u + m[1] * s.v + m[2], m[3] * s.u + m[4] * s.v + m[5],
                         m[0] * s.dudx + m[1] * s.dvdx, m[3] * s.dudx + m[4] * s.dvdx, m[0] * s.dudy + m[1] * s.dvdy,
                         m[3] * s.dudy + m[4] * s.dvdy);
  };
  constexpr float tolerance = SEAMCL_SEAM_WEIGHT_TOLERANCE;
  const FaceNeighbors& n = scene.neighbors.at(t.face);
  bool seam = false, boundary = false, any_edge = false;
  bool near_edge = false;  // some edge's bound left its mirror to evaluate: else every tap is inside
  // How far the point lies inside each edge: how far its mirror and carried footprints lie
  // outside the face they are evaluated on.
  const float inside[4] = {s.v, 1.0f - s.u, 1.0f - s.v, s.u};
  for (int k = 0; k < 4; ++k) {
    // The point and footprint mirrored across edge k (v = 0, u = 1, v = 1, u = 0): the weight
    // there is what the (symmetric) filter puts beyond edge k.
    const bool across_v = (k & 1) == 0;
    const float distance_u = across_v ? -1.0f : inside[k], distance_v = across_v ? inside[k] : -1.0f;
    const float offset = k == 1 || k == 2 ? 2.0f : 0.0f;
    float beyond = 0.0f;
    if (may_weigh_inside(scene.faces.at(t.face), false, distance_u, distance_v)) {
      near_edge = true;
      beyond = across_v ? weight_inside(t.face, s.u, offset - s.v, s.dudx, -s.dvdx, s.dudy, -s.dvdy)
                        : weight_inside(t.face, offset - s.u, s.v, -s.dudx, s.dvdx, -s.dudy, s.dvdy);
    }
    const bool crosses = !(beyond <= tolerance);
    any_edge = any_edge || crosses;
    if (n.neighbor[k] < 0) {
      boundary = boundary || crosses;
      continue;
    }
    // The same filter on the neighbour, as traverse carries it there.
    const float reach = weight_carried(n.neighbor[k], n.edge_map[k], distance_u, distance_v);
    seam = seam || crosses || !(reach <= tolerance);
  }
  // The diagonal face past each valence-4 corner, as traverse reads it: a coarser one's taps can
  // reach back over the corner although no edge's footprint crosses. Corner k lies between edges
  // k - 1 and k.
  for (int k = 0; k < 4; ++k) {
    if (n.corner[k] < 0) continue;
    const float a = inside[(k + 3) & 3], b = inside[k];
    const bool b_along_v = (k & 1) == 0;
    const float reach = weight_carried(n.corner[k], n.corner_map[k], b_along_v ? a : b, b_along_v ? b : a);
    seam = seam || !(reach <= tolerance);
  }
  // Past a corner only; the own filter only near an edge, as the kernel. NaN weights count as
  // crossing: nothing shows the footprint stays inside.
  if (!any_edge && near_edge) {
    const float own = weight_inside(t.face, s.u, s.v, s.dudx, s.dvdx, s.dudy, s.dvdy);
    seam = seam || !(own >= 1.0f - tolerance);
  }
  return seam ? SEAMCL_MASK_SEAM : boundary ? SEAMCL_MASK_BOUNDARY : SEAMCL_MASK_NONE;
}

uint8_t merge_mask(uint8_t a, uint8_t b) {
  if (a == SEAMCL_MASK_SEAM || b == SEAMCL_MASK_SEAM) return SEAMCL_MASK_SEAM;
  if (a == SEAMCL_MASK_BOUNDARY || b == SEAMCL_MASK_BOUNDARY) return SEAMCL_MASK_BOUNDARY;
  return SEAMCL_MASK_NONE;
}

PixelFragment pixel_fragment(const FrameParams& f, const TriangleSetup& t, const uint32_t* ids, uint32_t slot, int x,
                             int y) {
  const std::vector<SampleOffset>& pattern = sample_pattern(f.sample_count);
  constexpr float to_pixels = 1.0f / SEAMCL_SUBPIXEL_ONE;
  PixelFragment out;
  float centroid_x = 0.0f, centroid_y = 0.0f;
  const int first = static_cast<int>(std::find(ids, ids + f.sample_count, slot) - ids);
  for (int r = first; r < f.sample_count; ++r) {
    if (ids[r] != slot) continue;
    ++out.covered;
    centroid_x += static_cast<float>(sample_fixed_x(x, pattern[r])) * to_pixels;
    centroid_y += static_cast<float>(sample_fixed_y(y, pattern[r])) * to_pixels;
  }
  centroid_x /= static_cast<float>(out.covered);
  centroid_y /= static_cast<float>(out.covered);
  out.x = static_cast<float>(x) + 0.5f;
  out.y = static_cast<float>(y) + 0.5f;
  // Centroid shading keeps the centre of a fully covered pixel (as D3D and GL do: a full
  // pattern's centroid is off centre, at 16x by (-1/32, -1/32)). The centroid also stands in for
  // a centre beyond the plane's horizon (1/w <= 0).
  const bool partly_covered = out.covered < f.sample_count;
  if ((f.shading_mode == SEAMCL_SHADE_CENTROID && partly_covered) || !(plane_inv_w(t, out.x, out.y) > 0.0f)) {
    out.x = centroid_x;
    out.y = centroid_y;
  }
  return out;
}

bool pixel_has_uncovered_fragment(const PackedScene& scene, const FrameParams& f,
                                  const std::vector<TriangleSetup>& setups, const uint32_t* ids, int x, int y) {
  for (int s = 0; s < f.sample_count; ++s) {
    if (ids[s] == SEAMCL_NO_TRIANGLE || std::find(ids, ids + s, ids[s]) != ids + s) continue;
    const TriangleSetup& t = setups.at(ids[s]);
    if (scene.faces.at(t.face).reflective >= 0) continue;  // a cube-map lookup: no patch taps
    const PixelFragment fragment = pixel_fragment(f, t, ids, ids[s], x, y);
    const SurfaceUv uv = interpolate_uv(t, fragment.x, fragment.y);
    const FilterSum sum =
        method_sum_reference(scene.textures(), t.face, f.sampler, uv.u, uv.v, uv.dudx, uv.dvdx, uv.dudy, uv.dvdy);
    if (sum.weight == 0.0f) return true;
  }
  return false;
}

ResolveReference shade_resolve_reference(const PackedScene& scene, const FrameParams& f,
                                         const std::vector<TriangleSetup>& setups,
                                         const std::vector<uint32_t>& sample_triangle,
                                         const std::vector<float>* cube_texels, const PtexRenderTexture* ptex,
                                         const DisplacedShadingReference* displaced) {
  const int samples = f.sample_count;
  const std::vector<SampleOffset>& pattern = sample_pattern(samples);
  constexpr float to_pixels = 1.0f / SEAMCL_SUBPIXEL_ONE;
  ResolveReference out;
  out.pixels.resize(static_cast<size_t>(f.width) * f.height);
  const bool with_mask = !scene.neighbors.empty() && ptex == nullptr;
  if (with_mask) out.seam_mask.assign(out.pixels.size(), 0);
  const glm::vec3 background(f.background[0], f.background[1], f.background[2]);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const uint32_t* ids = &sample_triangle[(static_cast<size_t>(y) * f.width + x) * samples];
      auto sample_x = [&](int s) { return static_cast<float>(sample_fixed_x(x, pattern[s])) * to_pixels; };
      auto sample_y = [&](int s) { return static_cast<float>(sample_fixed_y(y, pattern[s])) * to_pixels; };
      glm::vec3 sum(0.0f);
      int uncovered = 0;
      uint8_t crosses = SEAMCL_MASK_NONE;
      for (int s = 0; s < samples; ++s) {
        const uint32_t slot = ids[s];
        if (slot == SEAMCL_NO_TRIANGLE) {
          ++uncovered;
          continue;
        }
        const TriangleSetup& t = setups.at(slot);
        if (f.shading_mode == SEAMCL_SHADE_SAMPLE) {
          if (!(with_mask && f.mask_only))
            sum += shade_fragment_reference(scene, f, t, sample_x(s), sample_y(s), cube_texels, ptex, displaced, slot);
          if (with_mask) crosses = merge_mask(crosses, footprint_class(scene, f, t, sample_x(s), sample_y(s)));
          ++out.fragments;
          continue;
        }
        if (std::find(ids, ids + s, slot) != ids + s) continue;  // shaded at its first sample
        const PixelFragment fragment = pixel_fragment(f, t, ids, slot, x, y);
        if (!(with_mask && f.mask_only))
          sum += shade_fragment_reference(scene, f, t, fragment.x, fragment.y, cube_texels, ptex, displaced, slot) *
                 static_cast<float>(fragment.covered);
        if (with_mask) crosses = merge_mask(crosses, footprint_class(scene, f, t, fragment.x, fragment.y));
        ++out.fragments;
      }
      if (uncovered > 0 && f.environment.skybox) {
        sum += shade_sky_reference(f, *cube_texels, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f) *
               static_cast<float>(uncovered);
      } else {
        sum += background * static_cast<float>(uncovered);  // once: an empty pixel is exactly the background
      }
      out.pixels[static_cast<size_t>(y) * f.width + x] = glm::vec4(sum / static_cast<float>(samples), 1.0f);
      if (with_mask) out.seam_mask[static_cast<size_t>(y) * f.width + x] = crosses;
    }
  }
  return out;
}

}  // namespace seamcl
