#include "pipeline/stages/texture_sample_twin.h"

#include "core/srgb.h"
#include "pipeline/adjacency.h"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

namespace seamcl {


namespace {

// How far past a face's edge (or its guard band's), in texels of the level read, a bilinear probe
// can still weigh a texel inside. A tap at texel i weighs something only while the point's texel
// coordinate x = u * width - 0.5 lies in (i - 1, i + 1): the point less than half a texel past
// the texel's edge. At exactly half a texel x = -1, fx = 0, and the weight derived as
// fy - ((1 - fx) - (1 - fx)(1 - fy)) can still round to a few ulps, so the bound is kept
// strict; the 1/16 texel more absorbs that, the rounding of u * width - 0.5 and, for the
// whole-line test, the probes' positions summed step by step. The kernel's TAP_REACH_TEXELS.
constexpr float kTapReachTexels = 0.5625f;

struct Level {
  uint32_t offset;    // first stored texel (the band's corner with a guard band)
  int width, height;  // the face's texels
  int pad;            // guard band texels on each side
  int stride;         // stored texels per row
};

Level face_level(const TextureView& tex, const FaceGpu& face, int level) {
  const int width = std::max(face.width >> level, 1);
  return {tex.level_offsets->at(face.level_table + static_cast<uint32_t>(level)), width,
          std::max(face.height >> level, 1), tex.guard_band, width + 2 * tex.guard_band};
}

void add_texel(FilterSum& sum, const TextureView& tex, uint32_t index, float weight) {
  glm::vec4 texel;
  if (tex.format == TexelFormat::Rgba32f) {
    const float* p = &tex.texels32->at(4 * static_cast<size_t>(index));
    texel = glm::vec4(p[0], p[1], p[2], p[3]);
  } else {
    texel = decode_srgb8(tex.texels8->at(index));
  }
  // One rounding per channel, as the kernel's fma (the library builds with contraction off).
  for (int c = 0; c < 4; ++c) sum.color[c] = std::fma(weight, texel[c], sum.color[c]);
  sum.weight += weight;
}

// Stored index on an axis of n texels with `pad` band texels each side; inside = 0 for a tap
// the border address mode discards. Clamp reaches into the band, to its outer edge.
int address_texel(int i, int n, int pad, int address, float& inside) {
  const int clamped = std::clamp(i, -pad, n - 1 + pad);
  inside = (address != SEAMCL_ADDRESS_BORDER || i == clamped) ? 1.0f : 0.0f;
  return address == SEAMCL_ADDRESS_WRAP ? (i & (n - 1)) : clamped + pad;
}

float texel_coordinate(float u, int n, int pad, int address) {
  if (address == SEAMCL_ADDRESS_WRAP) u = u - std::floor(u);
  return std::fmin(std::fmax(u * static_cast<float>(n) - 0.5f, -2.0f - static_cast<float>(pad)),
                   static_cast<float>(n + 1 + pad));
}

void accumulate_bilinear(FilterSum& sum, const TextureView& tex, Level level, float u, float v, float weight, int address) {
  const float x = texel_coordinate(u, level.width, level.pad, address);
  const float y = texel_coordinate(v, level.height, level.pad, address);
  const float x_floor = std::floor(x), y_floor = std::floor(y);
  const float fx = x - x_floor, fy = y - y_floor;
  float in_x0, in_x1, in_y0, in_y1;
  const int x0 = address_texel(static_cast<int>(x_floor), level.width, level.pad, address, in_x0);
  const int x1 = address_texel(static_cast<int>(x_floor) + 1, level.width, level.pad, address, in_x1);
  const int y0 = address_texel(static_cast<int>(y_floor), level.height, level.pad, address, in_y0);
  const int y1 = address_texel(static_cast<int>(y_floor) + 1, level.height, level.pad, address, in_y1);
  const uint32_t row0 = level.offset + static_cast<uint32_t>(y0 * level.stride);
  const uint32_t row1 = level.offset + static_cast<uint32_t>(y1 * level.stride);
  // The kernel derives each weight from the one before (to keep LLVM's SLP pass from pairing
  // them); the twin rounds the same way: w10 = (1-fy) - w00 rather than fx (1-fy).
  const float w00 = (1.0f - fx) * (1.0f - fy);
  const float w10 = (1.0f - fy) - w00;
  const float w01 = (1.0f - fx) - w00;
  const float w11 = fy - w01;
  add_texel(sum, tex, row0 + static_cast<uint32_t>(x0), weight * w00 * in_x0 * in_y0);
  add_texel(sum, tex, row0 + static_cast<uint32_t>(x1), weight * w10 * in_x1 * in_y0);
  add_texel(sum, tex, row1 + static_cast<uint32_t>(x0), weight * w01 * in_x0 * in_y1);
  add_texel(sum, tex, row1 + static_cast<uint32_t>(x1), weight * w11 * in_x1 * in_y1);
}

void accumulate_trilinear(FilterSum& sum, const TextureView& tex, const FaceGpu& face, float u, float v, float lod,
                          float weight, int address) {
  lod = std::fmin(std::fmax(lod, 0.0f), static_cast<float>(face.level_count - 1));
  const int level0 = static_cast<int>(lod);
  const int level1 = std::min(level0 + 1, face.level_count - 1);
  const float t = lod - static_cast<float>(level0);
  accumulate_bilinear(sum, tex, face_level(tex, face, level0), u, v, weight * (1.0f - t), address);
  accumulate_bilinear(sum, tex, face_level(tex, face, level1), u, v, weight * t, address);
}

// The footprint's screen axes: uv per pixel, and squared lengths in level-0 texels; the bias
// every filter adds to the level it makes of them.
struct Footprint {
  float ax_u, ax_v, ay_u, ay_v;
  float len2_x, len2_y;
  bool finite;
  float lod_bias;
};

Footprint footprint(const FaceGpu& face, float lod_bias, float dudx, float dvdx, float dudy, float dvdy) {
  const float w = static_cast<float>(face.width), h = static_cast<float>(face.height);
  Footprint f{dudx, dvdx, dudy, dvdy, 0, 0, false, lod_bias};
  f.len2_x = (dudx * w) * (dudx * w) + (dvdx * h) * (dvdx * h);
  f.len2_y = (dudy * w) * (dudy * w) + (dvdy * h) * (dvdy * h);
  f.finite = f.len2_x < INFINITY && f.len2_y < INFINITY;
  return f;
}

float lod_of(float len2) { return 0.5f * approx_log2(std::fmax(len2, 1e-30f)); }

// The line of trilinear probes of an aniso lookup (the kernel's AnisoProbes).
struct AnisoProbes {
  int probes;              // N
  float weight;            // 1 / N, each probe's
  float lod;               // each probe's, bias included, before the chain's clamp
  float step_u, step_v;    // from one probe to the next (uv)
  float first_u, first_v;  // probe 0
};

AnisoProbes aniso_probes(const FaceGpu& face, float u, float v, const Footprint& f, int max_aniso) {
  const bool x_major = f.len2_x >= f.len2_y;
  const float major2 = x_major ? f.len2_x : f.len2_y;
  const float minor2 = x_major ? f.len2_y : f.len2_x;
  // N = min(ceil(major / minor), max_aniso) trilinear probes at log2(major / N).
  // A line footprint takes the most probes; a point footprint one.
  const float ratio = minor2 > 0.0f ? std::sqrt(major2 / minor2) : major2 > 0.0f ? static_cast<float>(max_aniso) : 1.0f;
  AnisoProbes p{};
  p.probes = f.finite ? probe_count(ratio, max_aniso) : 1;
  p.weight = 1.0f / static_cast<float>(p.probes);
  p.lod = f.finite ? lod_of(major2) - log2_probe_count(p.probes) + f.lod_bias : static_cast<float>(face.level_count - 1);
  p.step_u = (x_major ? f.ax_u : f.ay_u) * p.weight;
  p.step_v = (x_major ? f.ax_v : f.ay_v) * p.weight;
  // Probe i at (i + 0.5) / N - 0.5 of the major axis from the centre.
  p.first_u = f.finite ? u + p.step_u * (0.5f - 0.5f * static_cast<float>(p.probes)) : u;
  p.first_v = f.finite ? v + p.step_v * (0.5f - 0.5f * static_cast<float>(p.probes)) : v;
  return p;
}

float trilinear_lod(const FaceGpu& face, const Footprint& f) {
  return f.finite ? lod_of(std::fmax(f.len2_x, f.len2_y)) + f.lod_bias : static_cast<float>(face.level_count - 1);
}

// Bilinear has no footprint level: it reads the level nearest the bias, within the chain (level 0
// for biases below 0.5; a NaN bias reads level 0).
int bilinear_level(const FaceGpu& face, float lod_bias) {
  return static_cast<int>(std::floor(std::fmin(std::fmax(lod_bias + 0.5f, 0.0f), static_cast<float>(face.level_count - 1))));
}

// How many times longer than at bias 0 the texels a lookup reads can be, for the early-outs'
// bounds: a positive bias b moves every level up by b, and the texels of level l + b are 2^b
// times those of l, so 2^ceil(b) bounds them (and bilinear's level floor(b + 0.5) <= ceil(b)); a
// negative bias reads finer texels, whose taps reach less far: 1. A power of two, so a bound
// multiplied by it rounds as before and keeps its order.
float bias_coarsening(float lod_bias) {
  const int steps = static_cast<int>(std::ceil(std::fmin(std::fmax(lod_bias, 0.0f), 64.0f)));
  return std::ldexp(1.0f, steps);
}

// The level whose texels are the coarsest a trilinear lookup at `lod` reads.
int coarser_level(const FaceGpu& face, float lod) {
  lod = std::fmin(std::fmax(lod, 0.0f), static_cast<float>(face.level_count - 1));
  return std::min(static_cast<int>(lod) + 1, face.level_count - 1);
}

// Whether a bilinear probe at (u, v) can weigh a texel inside the face (border address mode),
// `reach` being kTapReachTexels texels of the level it reads: a tap weighs something only while the point lies
// less than half a texel past the texel's edge; kTapReachTexels keeps a sixteenth more for rounding. NaN: may reach.
bool probe_reaches_face(float u, float v, float reach_u, float reach_v) {
  return !(u + reach_u <= 0.0f || u - reach_u >= 1.0f || v + reach_v <= 0.0f || v - reach_v >= 1.0f);
}

// The same for probes on `level` centred at (u, v) and spread no further than (half_u, half_v).
// The band's texels (`pad` each side) count as inside.
bool probes_reach_face(const FaceGpu& face, int pad, int level, float u, float v, float half_u, float half_v) {
  const float texels = kTapReachTexels + static_cast<float>(pad);
  return probe_reaches_face(u, v, half_u + texels / static_cast<float>(std::max(face.width >> level, 1)),
                            half_v + texels / static_cast<float>(std::max(face.height >> level, 1)));
}

// Border-addressed, probes whose taps all lie outside the face add exactly nothing: skipped, as
// the kernel skips them.
void accumulate_probes(FilterSum& sum, const TextureView& tex, const FaceGpu& face, const AnisoProbes& p, int address) {
  float pu = p.first_u, pv = p.first_v;
  const int level = coarser_level(face, p.lod);
  const float texels = kTapReachTexels + static_cast<float>(tex.guard_band);
  const float reach_u = texels / static_cast<float>(std::max(face.width >> level, 1));
  const float reach_v = texels / static_cast<float>(std::max(face.height >> level, 1));
  for (int i = 0; i < p.probes; ++i) {
    if (address != SEAMCL_ADDRESS_BORDER || probe_reaches_face(pu, pv, reach_u, reach_v)) {
      accumulate_trilinear(sum, tex, face, pu, pv, p.lod, p.weight, address);
    }
    pu += p.step_u;
    pv += p.step_v;
  }
}

void accumulate_aniso(FilterSum& sum, const TextureView& tex, const FaceGpu& face, float u, float v, const Footprint& f,
                      int max_aniso, int address) {
  accumulate_probes(sum, tex, face, aniso_probes(face, u, v, f, max_aniso), address);
}

// pbrt-v4's EWA on one level (Gaussian, alpha 2), weights divided by their total over the
// ellipse: sum.weight is then the fraction of the ellipse inside the face.
void accumulate_ewa_level(FilterSum& sum, const TextureView& tex, const FaceGpu& face, int level_index, float u, float v,
                          float a_u, float a_v, float b_u, float b_v, float weight, int address) {
  const Level level = face_level(tex, face, level_index);
  const float w = static_cast<float>(level.width), h = static_cast<float>(level.height);
  float s = u, t = v;
  if (address == SEAMCL_ADDRESS_WRAP) {
    s = s - std::floor(s);
    t = t - std::floor(t);
  }
  const float cs = std::fmin(std::fmax(s * w - 0.5f, -2.0f * w - 2.0f), 3.0f * w + 2.0f);
  const float ct = std::fmin(std::fmax(t * h - 0.5f, -2.0f * h - 2.0f), 3.0f * h + 2.0f);
  const float x0 = a_u * w, y0 = a_v * h, x1 = b_u * w, y1 = b_v * h;
  // Implicit ellipse A s^2 + B s t + C t^2 < 1, widened by a texel (the + 1) so it never misses all texels.
  float A = y0 * y0 + y1 * y1 + 1.0f;
  float B = -2.0f * (x0 * y0 + x1 * y1);
  float C = x0 * x0 + x1 * x1 + 1.0f;
  const float inv_f = 1.0f / (A * C - B * B * 0.25f);
  A *= inv_f;
  B *= inv_f;
  C *= inv_f;
  const float det = -B * B + 4.0f * A * C;
  const float inv_det = 1.0f / det;
  const float u_extent = 2.0f * inv_det * std::sqrt(det * C);
  const float v_extent = 2.0f * inv_det * std::sqrt(A * det);
  // At most two level widths around the level: a wider ellipse only repeats what it holds.
  const int s0 = static_cast<int>(std::fmax(std::ceil(cs - u_extent), -2.0f * w - 2.0f));
  const int s1 = static_cast<int>(std::fmin(std::floor(cs + u_extent), 3.0f * w + 2.0f));
  const int t0 = static_cast<int>(std::fmax(std::ceil(ct - v_extent), -2.0f * h - 2.0f));
  const int t1 = static_cast<int>(std::fmin(std::floor(ct + v_extent), 3.0f * h + 2.0f));
  FilterSum level_sum;
  float total = 0.0f;
  for (int it = t0; it <= t1; ++it) {
    const float tt = static_cast<float>(it) - ct;
    float in_y;
    const int iy = address_texel(it, level.height, level.pad, address, in_y);
    for (int is = s0; is <= s1; ++is) {
      const float ss = static_cast<float>(is) - cs;
      const float r2 = A * ss * ss + B * ss * tt + C * tt * tt;
      if (r2 >= 1.0f) continue;
      const float gauss = std::exp(-2.0f * r2) - std::exp(-2.0f);
      float in_x;
      const int ix = address_texel(is, level.width, level.pad, address, in_x);
      total += gauss;
      add_texel(level_sum, tex, level.offset + static_cast<uint32_t>(iy * level.stride + ix), gauss * in_x * in_y);
    }
  }
  const float scale = total > 0.0f ? weight / total : 0.0f;
  sum.color += level_sum.color * scale;
  sum.weight += level_sum.weight * scale;
}

void accumulate_ewa(FilterSum& sum, const TextureView& tex, const FaceGpu& face, float u, float v, const Footprint& f,
                    int max_aniso, int address) {
  if (!f.finite) {
    accumulate_trilinear(sum, tex, face, u, v, static_cast<float>(face.level_count - 1), 1.0f, address);
    return;
  }
  const bool x_major = f.len2_x >= f.len2_y;
  const float a_u = x_major ? f.ax_u : f.ay_u, a_v = x_major ? f.ax_v : f.ay_v;
  float b_u = x_major ? f.ay_u : f.ax_u, b_v = x_major ? f.ay_v : f.ax_v;
  const float major2 = x_major ? f.len2_x : f.len2_y;
  float minor2 = x_major ? f.len2_y : f.len2_x;
  // Clamp the eccentricity to max_aniso by growing the minor axis.
  const float limit = static_cast<float>(max_aniso * max_aniso);
  if (minor2 * limit < major2 && minor2 > 0.0f) {
    const float scale = std::sqrt(major2 / (minor2 * limit));
    b_u *= scale;
    b_v *= scale;
    minor2 = major2 / limit;
  }
  // A minor axis of length 0 (a point or a line) is a level of minus infinity: no finite bias
  // lifts it off level 0.
  if (!(minor2 > 0.0f)) {
    accumulate_bilinear(sum, tex, face_level(tex, face, 0), u, v, 1.0f, address);
    return;
  }
  // The level where the minor axis spans about one texel, plus the bias.
  const float lod = std::fmin(std::fmax(lod_of(minor2) + f.lod_bias, 0.0f), static_cast<float>(face.level_count - 1));
  const int level0 = static_cast<int>(lod);
  const int level1 = std::min(level0 + 1, face.level_count - 1);
  const float t = lod - static_cast<float>(level0);
  accumulate_ewa_level(sum, tex, face, level0, u, v, a_u, a_v, b_u, b_v, 1.0f - t, address);
  if (t > 0.0f) accumulate_ewa_level(sum, tex, face, level1, u, v, a_u, a_v, b_u, b_v, t, address);
}

}  // namespace

float approx_log2(float x) {
  const auto bits = std::bit_cast<int32_t>(x);
  const float exponent = static_cast<float>(((bits >> 23) & 255) - 127);
  const float m = std::bit_cast<float>((bits & 0x007fffff) | 0x3f800000) - 1.0f;
  const float p = m * (1.442517034f + m * (-0.7178983813f + m * (0.4568941740f + m * (-0.2773650501f +
                  m * (0.1219141394f + m * -0.02606630148f)))));
  return exponent + p;
}

float log2_probe_count(int probes) {
  static constexpr float kLog2ProbeCounts[SEAMCL_MAX_PROBES] = SEAMCL_LOG2_PROBE_COUNTS;
  assert(probes >= 1 && probes <= SEAMCL_MAX_PROBES);
  return kLog2ProbeCounts[probes - 1];
}

int probe_count(float ratio, int max_aniso) {
  const int ceiling = static_cast<int>(std::ceil(std::fmin(ratio, static_cast<float>(SEAMCL_MAX_PROBES))));
  return std::max(std::min(ceiling, max_aniso), 1);
}

FilterSum filter_texture_reference(const TextureView& tex, uint32_t face_index, const SamplerParams& sampler, int address,
                                   float u, float v, float dudx, float dvdx, float dudy, float dvdy) {
  const FaceGpu& face = tex.faces->at(face_index);
  FilterSum sum;
  const Footprint f = footprint(face, sampler.lod_bias, dudx, dvdx, dudy, dvdy);
  switch (sampler.filter) {
    case SEAMCL_FILTER_BILINEAR:
      accumulate_bilinear(sum, tex, face_level(tex, face, bilinear_level(face, sampler.lod_bias)), u, v, 1.0f, address);
      break;
    case SEAMCL_FILTER_TRILINEAR:
      accumulate_trilinear(sum, tex, face, u, v, trilinear_lod(face, f), 1.0f, address);
      break;
    case SEAMCL_FILTER_ANISO:
      accumulate_aniso(sum, tex, face, u, v, f, sampler.max_aniso, address);
      break;
    default:
      accumulate_ewa(sum, tex, face, u, v, f, sampler.max_aniso, address);
      break;
  }
  return sum;
}

bool ewa_sides_may_contribute(float min_side, float max_side, int guard_band, float lod_bias, float distance_u,
                              float distance_v, float dudx, float dvdx, float dudy, float dvdy) {
  // Footprint axes by their 1-norms in uv: no shorter than their lengths, and kept by the maps
  // between faces (which only permute and negate u and v).
  const float axis_x = std::fabs(dudx) + std::fabs(dvdx);
  const float axis_y = std::fabs(dudy) + std::fabs(dvdy);
  const float axes = axis_x + axis_y;
  // A non-finite footprint sends every filter to the coarsest level: it may reach anything.
  if (!(axes < INFINITY)) return true;
  // The coarsest texel EWA's trilinear pair of levels can weigh (uv): the level where the minor
  // axis (no longer than max side x the longer 1-norm, in level-0 texels) spans a texel, and the
  // next, whose texels are up to twice that (2.01: approx_log2's error); none longer than the
  // face. A positive bias makes them up to bias_coarsening times longer. Kept multiplied by
  // min_side (a power of two: exact), so that the kernel divides nothing.
  const float texel_sides = std::fmin(
      min_side, std::fmax(2.0f, 2.01f * max_side * std::fmax(axis_x, axis_y) * bias_coarsening(lod_bias)));
  // The ellipse spreads over both axes, its minor one grown up to max/min side times in uv by the
  // eccentricity clamp; it is widened by about a texel (the + 1 of accumulate_ewa_level): a whole one.
  const float spread = (1.0f + max_side / min_side) * axes;
  const float texel_reach = texel_sides * (1.0f + static_cast<float>(guard_band));  // band texels read as inside
  // EWA pulls a centre more than two face widths out back to two widths: count no distance
  // beyond 2. A NaN distance is never skipped.
  const float counted_u = distance_u > 2.0f ? 2.0f : distance_u;
  const float counted_v = distance_v > 2.0f ? 2.0f : distance_v;
  return !(min_side > 0.0f && (counted_u * min_side >= spread * min_side + texel_reach ||
                               counted_v * min_side >= spread * min_side + texel_reach));
}

bool axis_rules_out(float side, float cross_side, int filter, int max_aniso, float lod_bias, int guard_band,
                    float distance, float x_a, float x_b, float y_a, float y_b) {
  // The screen axes' lengths in the face's level-0 texels, bounded by their 1-norms weighted by
  // the sides: |a| side + |b| cross_side >= sqrt((a side)^2 + (b cross_side)^2).
  const float len_x = x_a * side + x_b * cross_side;
  const float len_y = y_a * side + y_b * cross_side;
  // The coarsest texel the face's filter can weigh, in level-0 texels: bilinear reads level 0;
  // the others a trilinear pair at lod (at least 0) and the next level, whose texels are up to
  // twice 2^lod (2.01: approx_log2's error); none longer than the side (a 1-texel level).
  // Trilinear's 2^lod is the longer axis; aniso's that divided by its N probes, N >= min(major /
  // minor, max_aniso), so at most the longer of the minor axis and major / max_aniso (whichever
  // of the two screen axes the face's texels make the minor one: the shorter bound serves). A
  // positive bias lengthens them up to bias_coarsening times (bilinear's level then being at most
  // ceil(bias), its texels at most that power of two long).
  const float probe_len = filter == SEAMCL_FILTER_ANISO
                              ? std::fmax(std::fmin(len_x, len_y), std::fmax(len_x, len_y) / static_cast<float>(max_aniso))
                              : std::fmax(len_x, len_y);
  const float coarsening = bias_coarsening(lod_bias);
  const float texel_sides = filter == SEAMCL_FILTER_BILINEAR
                                ? std::fmin(side, coarsening)
                                : std::fmin(side, std::fmax(2.0f, 2.01f * probe_len * coarsening));
  // Aniso's probes spread over half its major axis, one of the two screen axes.
  const float spread = filter == SEAMCL_FILTER_ANISO ? 0.5f * std::fmax(x_a, y_a) : 0.0f;
  // A tap weighs something only within half a texel of its probe (kTapReachTexels); band texels read as inside.
  const float texel_reach = texel_sides * (kTapReachTexels + static_cast<float>(guard_band));
  // No distance beyond 2 counts (as for EWA); a NaN or negative one never decides.
  const float counted = distance > 2.0f ? 2.0f : distance;
  // In units of 1 / side (exact: powers of two). Every term grows as side shrinks or cross_side /
  // side grows, and rounding keeps that order (each step is monotone and the scaling by side is
  // exact), so a side and ratio that bound several faces' bound each of them.
  return side > 0.0f && counted * side >= spread * side + texel_reach;
}

bool neighbor_may_contribute(const FaceGpu& other, bool swapped, int filter, int max_aniso, float lod_bias,
                             int guard_band, float distance_u, float distance_v, float dudx, float dvdx, float dudy,
                             float dvdy) {
  if (filter == SEAMCL_FILTER_EWA) {
    return ewa_sides_may_contribute(static_cast<float>(std::min(other.width, other.height)),
                                    static_cast<float>(std::max(other.width, other.height)), guard_band, lod_bias,
                                    distance_u, distance_v, dudx, dvdx, dudy, dvdy);
  }
  const float x_u = std::fabs(dudx), x_v = std::fabs(dvdx), y_u = std::fabs(dudy), y_v = std::fabs(dvdy);
  if (!(x_u + x_v + y_u + y_v < INFINITY)) return true;
  // The other face's sides along this face's u and v.
  const float side_u = static_cast<float>(swapped ? other.height : other.width);
  const float side_v = static_cast<float>(swapped ? other.width : other.height);
  return !(axis_rules_out(side_u, side_v, filter, max_aniso, lod_bias, guard_band, distance_u, x_u, x_v, y_u, y_v) ||
           axis_rules_out(side_v, side_u, filter, max_aniso, lod_bias, guard_band, distance_v, x_v, x_u, y_v, y_u));
}

bool map_swaps_axes(const float transform[6]) { return transform[0] == 0.0f; }

int edges_may_reach(const FaceNeighbors& n, int filter, int max_aniso, float lod_bias, int guard_band, float u, float v,
                    float dudx, float dvdx, float dudy, float dvdy) {
  const float x_u = std::fabs(dudx), x_v = std::fabs(dvdx), y_u = std::fabs(dudy), y_v = std::fabs(dvdy);
  if (filter == SEAMCL_FILTER_EWA || !(x_u + x_v + y_u + y_v < INFINITY)) return 15;
  const float inside[4] = {v, 1.0f - u, 1.0f - v, u};
  int mask = 0;
  for (int k = 0; k < 4; ++k) {
    // Edges 0 and 2 are crossed along v, 1 and 3 along u.
    const bool along_v = k % 2 == 0;
    const bool ruled_out = axis_rules_out(reach_side(n.reach_min_side[k]), reach_side(n.reach_max_side[k]), filter, max_aniso,
                                          lod_bias, guard_band,
                                          inside[k], along_v ? x_v : x_u, along_v ? x_u : x_v, along_v ? y_v : y_u,
                                          along_v ? y_u : y_v);
    mask |= (ruled_out ? 0 : 1) << k;
  }
  return mask;
}

bool lookup_may_reach_face(const FaceGpu& face, int guard_band, int filter, int max_aniso, float lod_bias, float u,
                           float v, float dudx, float dvdx, float dudy, float dvdy) {
  const Footprint f = footprint(face, lod_bias, dudx, dvdx, dudy, dvdy);
  switch (filter) {
    case SEAMCL_FILTER_BILINEAR:
      return probes_reach_face(face, guard_band, bilinear_level(face, lod_bias), u, v, 0.0f, 0.0f);
    case SEAMCL_FILTER_TRILINEAR:
      return probes_reach_face(face, guard_band, coarser_level(face, trilinear_lod(face, f)), u, v, 0.0f, 0.0f);
    case SEAMCL_FILTER_ANISO: {
      const AnisoProbes p = aniso_probes(face, u, v, f, max_aniso);
      // The probes lie within (N - 1) / 2 steps of the centre; N / 2 leaves half a step spare.
      const float spread = 0.5f * static_cast<float>(p.probes);
      return probes_reach_face(face, guard_band, coarser_level(face, p.lod), u, v, spread * std::fabs(p.step_u),
                               spread * std::fabs(p.step_v));
    }
    default:
      return true;  // EWA: neighbor_may_contribute only
  }
}

FilterSum method_sum_reference(const TextureView& tex, uint32_t face, const SamplerParams& sampler, float u, float v,
                               float dudx, float dvdx, float dudy, float dvdy, bool early_out) {
  FilterSum sum = filter_texture_reference(tex, face, sampler, sampler.address, u, v, dudx, dvdx, dudy, dvdy);
  if (sampler.traverse == SEAMCL_TRAVERSE_NONE) return sum;
  // Traverse: each neighbour at this point and footprint carried into its uv, border-addressed,
  // so it weighs only the taps that fall inside it. A neighbour whose taps cannot reach the
  // point is skipped: it would add nothing.
  auto add_across = [&](int other, const float* t, float distance_u, float distance_v) {
    if (other < 0) return;
    const FaceGpu& g = tex.faces->at(static_cast<size_t>(other));
    if (early_out && !neighbor_may_contribute(g, map_swaps_axes(t), sampler.filter, sampler.max_aniso, sampler.lod_bias,
                                              tex.guard_band, distance_u, distance_v, dudx, dvdx, dudy, dvdy)) {
      return;
    }
    const float gu = t[0] * u + t[1] * v + t[2], gv = t[3] * u + t[4] * v + t[5];
    const float gdudx = t[0] * dudx + t[1] * dvdx, gdvdx = t[3] * dudx + t[4] * dvdx;
    const float gdudy = t[0] * dudy + t[1] * dvdy, gdvdy = t[3] * dudy + t[4] * dvdy;
    // Then the probes the filter would take there, against the other face's square.
    if (early_out && !lookup_may_reach_face(g, tex.guard_band, sampler.filter, sampler.max_aniso, sampler.lod_bias, gu, gv,
                                            gdudx, gdvdx, gdudy, gdvdy)) {
      return;
    }
    const FilterSum s = filter_texture_reference(tex, static_cast<uint32_t>(other), sampler, SEAMCL_ADDRESS_BORDER, gu,
                                                 gv, gdudx, gdvdx, gdudy, gdvdy);
    sum.color += s.color;
    sum.weight += s.weight;
  };
  // How far the point lies inside each edge: the least distance to the face across it, along v
  // (edges 0 and 2) or u (1 and 3); the other axis never decides (-1).
  const float inside[4] = {v, 1.0f - u, 1.0f - v, u};
  const FaceNeighbors& n = tex.neighbors->at(face);
  // First, from this face's record alone, the edges whose faces (across and past the ends) the
  // lookup may reach: the others' three faces are not read at all.
  const int edge_may_reach =
      early_out ? edges_may_reach(n, sampler.filter, sampler.max_aniso, sampler.lod_bias, tex.guard_band, u, v, dudx, dvdx,
                                  dudy, dvdy)
                : 15;
  for (int k = 0; k < 4; ++k) {
    if (((edge_may_reach >> k) & 1) == 0) continue;
    const bool along_v = k % 2 == 0;
    add_across(n.neighbor[k], map_coefficients(n.edge_map[k]).data(), along_v ? -1.0f : inside[k], along_v ? inside[k] : -1.0f);
  }
  if (sampler.traverse != SEAMCL_TRAVERSE_CORNERS) return sum;
  // Past a valence-4 corner, the diagonal face (corner k lies between edges k-1 and k): past both.
  for (int k = 0; k < 4; ++k) {
    // Corner k lies at the ends of edges k - 1 and k: either edge's test rules it out.
    if (((edge_may_reach >> k) & (edge_may_reach >> ((k + 3) % 4)) & 1) == 0) continue;
    const float a = inside[(k + 3) % 4], b = inside[k];
    const bool b_along_v = k % 2 == 0;
    add_across(n.corner[k], map_coefficients(n.corner_map[k]).data(), b_along_v ? a : b, b_along_v ? b : a);
  }
  return sum;
}

glm::vec4 sample_texture_reference(const TextureView& tex, uint32_t face, const SamplerParams& sampler, float u, float v,
                                   float dudx, float dvdx, float dudy, float dvdy) {
  FilterSum sum = method_sum_reference(tex, face, sampler, u, v, dudx, dvdx, dudy, dvdy);
  if (!sampler.renormalize) return sum.color;
  if (sum.weight == 0.0f && sampler.zero_coverage == SEAMCL_ZERO_COVERAGE_CLAMP) {
    // Every tap fell outside: a clamped trilinear lookup at the centre clamped to the face (with
    // the sampler's bias, as every lookup).
    SamplerParams fallback = sampler;
    fallback.filter = SEAMCL_FILTER_TRILINEAR;
    sum = filter_texture_reference(tex, face, fallback, SEAMCL_ADDRESS_CLAMP, std::fmin(std::fmax(u, 0.0f), 1.0f),
                                   std::fmin(std::fmax(v, 0.0f), 1.0f), dudx, dvdx, dudy, dvdy);
  }
  const float inv_weight = 1.0f / sum.weight;
  return sum.color * inv_weight;
}

}  // namespace seamcl
