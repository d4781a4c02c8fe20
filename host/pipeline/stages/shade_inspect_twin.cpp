#include "pipeline/stages/shade_inspect_twin.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "pipeline/adjacency.h"
#include "pipeline/stages/raster_twin.h"
#include "pipeline/stages/sample_pattern.h"
#include "pipeline/stages/shade_resolve_twin.h"
#include "pipeline/stages/texture_sample_twin.h"

namespace seamcl {
namespace {

float lod_of(float len2) { return 0.5f * approx_log2(std::fmax(len2, 1e-30f)); }

// The levels, probe count and axes of a lookup on `face` (the kernel's inspect_levels; the
// footprint, trilinear, aniso and EWA levels as texture_sample.cl makes them).
void inspect_levels(InspectSample& r, const FaceGpu& face, const SamplerParams& s, float dudx, float dvdx, float dudy,
                    float dvdy) {
  const float w = static_cast<float>(face.width), h = static_cast<float>(face.height);
  const float len2_x = (dudx * w) * (dudx * w) + (dvdx * h) * (dvdx * h);
  const float len2_y = (dudy * w) * (dudy * w) + (dvdy * h) * (dvdy * h);
  const bool finite = len2_x < INFINITY && len2_y < INFINITY;
  r.axis_x = std::sqrt(len2_x);
  r.axis_y = std::sqrt(len2_y);
  r.probes = 1;
  const float top = static_cast<float>(face.level_count - 1);
  const float major2 = std::fmax(len2_x, len2_y);
  float minor2 = std::fmin(len2_x, len2_y);
  float lod = top;
  if (s.filter == SEAMCL_FILTER_BILINEAR) {
    lod = std::floor(std::fmin(std::fmax(s.lod_bias + 0.5f, 0.0f), top));
  } else if (s.filter == SEAMCL_FILTER_TRILINEAR) {
    if (finite) lod = lod_of(major2) + s.lod_bias;
  } else if (s.filter == SEAMCL_FILTER_ANISO) {
    // The kernel's major is len2_x on a tie, which fmax picks as well (equal values).
    const float ratio = minor2 > 0.0f ? std::sqrt(major2 / minor2) : major2 > 0.0f ? static_cast<float>(s.max_aniso) : 1.0f;
    r.probes = finite ? probe_count(ratio, s.max_aniso) : 1;
    if (finite) lod = lod_of(major2) - log2_probe_count(r.probes) + s.lod_bias;
  } else {
    const float limit = static_cast<float>(s.max_aniso * s.max_aniso);
    if (minor2 * limit < major2 && minor2 > 0.0f) minor2 = major2 / limit;
    lod = !finite ? top : !(minor2 > 0.0f) ? 0.0f : lod_of(minor2) + s.lod_bias;
  }
  r.lod = std::fmin(std::fmax(lod, 0.0f), top);
  r.level0 = static_cast<int>(r.lod);
  r.level1 = s.filter == SEAMCL_FILTER_BILINEAR ? r.level0 : std::min(r.level0 + 1, face.level_count - 1);
}

}  // namespace

std::vector<InspectSample> shade_inspect_reference(const PackedScene& scene, const FrameParams& f,
                                                   const std::vector<TriangleSetup>& setups,
                                                   const std::vector<uint32_t>& sample_triangle, int window_x,
                                                   int window_y, int window_width, int window_height,
                                                   const std::vector<float>* cube_texels,
                                                   const DisplacedShadingReference* displaced) {
  const int samples = f.sample_count;
  const std::vector<SampleOffset>& pattern = sample_pattern(samples);
  constexpr float to_pixels = 1.0f / SEAMCL_SUBPIXEL_ONE;
  const TextureView textures = scene.textures();
  const SamplerParams& sampler = f.sampler;
  std::vector<InspectSample> out;
  out.reserve(static_cast<size_t>(window_width) * window_height * samples);
  for (int wy = 0; wy < window_height; ++wy) {
    for (int wx = 0; wx < window_width; ++wx) {
      const int x = window_x + wx, y = window_y + wy;
      const uint32_t* ids = &sample_triangle.at((static_cast<size_t>(y) * f.width + x) * samples);
      for (int s = 0; s < samples; ++s) {
        InspectSample r{};
        const uint32_t slot = ids[s];
        for (int q = 0; q < samples; ++q)
          if (ids[q] == slot) r.coverage |= 1u << q;
        r.triangle = slot;
        r.face = -1;
        r.level0 = r.level1 = -1;
        for (int k = 0; k < 4; ++k) r.edge_face[k] = r.corner_face[k] = -1;
        r.color[0] = f.background[0];
        r.color[1] = f.background[1];
        r.color[2] = f.background[2];
        r.color[3] = 1.0f;
        if (slot == SEAMCL_NO_TRIANGLE) {
          out.push_back(r);
          continue;
        }
        const TriangleSetup& t = setups.at(slot);
        float px, py;
        if (f.shading_mode == SEAMCL_SHADE_SAMPLE) {
          px = static_cast<float>(sample_fixed_x(x, pattern[s])) * to_pixels;
          py = static_cast<float>(sample_fixed_y(y, pattern[s])) * to_pixels;
        } else {
          const PixelFragment fragment = pixel_fragment(f, t, ids, slot, x, y);
          px = fragment.x;
          py = fragment.y;
        }
        const SurfaceUv uv = interpolate_uv(t, px, py);
        const FaceGpu& face = scene.faces.at(t.face);
        r.face = static_cast<int>(t.face);
        r.x = px;
        r.y = py;
        r.u = uv.u;
        r.v = uv.v;
        r.dudx = uv.dudx;
        r.dvdx = uv.dvdx;
        r.dudy = uv.dudy;
        r.dvdy = uv.dvdy;
        const glm::vec3 c = shade_fragment_reference(scene, f, t, px, py, cube_texels, nullptr, displaced, slot);
        r.color[0] = c.x;
        r.color[1] = c.y;
        r.color[2] = c.z;
        if (face.reflective >= 0) {
          r.reflective = 1;
          out.push_back(r);
          continue;
        }
        inspect_levels(r, face, sampler, uv.dudx, uv.dvdx, uv.dudy, uv.dvdy);
        r.own_weight = filter_texture_reference(textures, t.face, sampler, sampler.address, uv.u, uv.v, uv.dudx, uv.dvdx,
                                                uv.dudy, uv.dvdy)
                           .weight;
        if (!scene.neighbors.empty()) {
          const FaceNeighbors& n = scene.neighbors.at(t.face);
          // The same filter, border-addressed, on the face at this point and footprint carried
          // into its uv (what traverse adds; its early-outs skip only lookups that weigh 0).
          auto across = [&](int32_t other, uint8_t code) {
            if (other < 0) return 0.0f;
            const std::array<float, 6> m = map_coefficients(code);
            return filter_texture_reference(textures, static_cast<uint32_t>(other), sampler, SEAMCL_ADDRESS_BORDER,
                                            m[0] * uv.u + m[1] * uv.v + m[2], m[3] * uv.u + m[4] * uv.v + m[5],
                                            m[0] * uv.dudx + m[1] * uv.dvdx, m[3] * uv.dudx + m[4] * uv.dvdx,
                                            m[0] * uv.dudy + m[1] * uv.dvdy, m[3] * uv.dudy + m[4] * uv.dvdy)
                .weight;
          };
          for (int k = 0; k < 4; ++k) {
            r.edge_face[k] = n.neighbor[k];
            r.corner_face[k] = n.corner[k];
            if (sampler.traverse == SEAMCL_TRAVERSE_NONE) continue;
            r.edge_weight[k] = across(n.neighbor[k], n.edge_map[k]);
            if (sampler.traverse == SEAMCL_TRAVERSE_CORNERS) r.corner_weight[k] = across(n.corner[k], n.corner_map[k]);
          }
        }
        out.push_back(r);
      }
    }
  }
  return out;
}

}  // namespace seamcl
