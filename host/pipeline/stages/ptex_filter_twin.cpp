#include "pipeline/stages/ptex_filter_twin.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

namespace seamcl {
namespace {

constexpr int kKmax = SEAMCL_PTEX_KMAX;
enum Edge { kBottom = 0, kRight = 1, kTop = 2, kLeft = 3 };
enum BorderMode { kClamp = 0, kBlack = 1, kPeriodic = 2 };

// A separable kernel at resolution 2^ulog2 x 2^vlog2: taps [u, u + uw) x [v, v + vw) with weights
// ku x kv, rot quarter turns from the face it was built on. Weights always start at index 0.
struct Kern {
  int ulog2 = 0, vlog2 = 0;
  int u = 0, v = 0, uw = 0, vw = 0;
  float ku[kKmax] = {};
  float kv[kKmax] = {};
  int rot = 0;
  int res_u() const { return 1 << ulog2; }
  int res_v() const { return 1 << vlog2; }
};

float accumulate(const float* p, int n) {
  float sum = 0.0f;
  for (int i = 0; i < n; ++i) sum += p[i];
  return sum;
}

float weight(const Kern& k) { return accumulate(k.ku, k.uw) * accumulate(k.kv, k.vw); }

// Drops the first `by` of n weights.
void drop_front(float* a, int n, int by) {
  for (int i = 0; i + by < n; ++i) a[i] = a[i + by];
}

void strip_zeros(Kern& k) {
  while (k.uw > 0 && k.ku[0] == 0.0f) { drop_front(k.ku, k.uw, 1); k.u++; k.uw--; }
  while (k.uw > 0 && k.ku[k.uw - 1] == 0.0f) k.uw--;
  while (k.vw > 0 && k.kv[0] == 0.0f) { drop_front(k.kv, k.vw, 1); k.v++; k.vw--; }
  while (k.vw > 0 && k.kv[k.vw - 1] == 0.0f) k.vw--;
}

// Taps past a boundary edge fold onto the edge texel (clamp, periodic) or are dropped (black,
// their weight still counted, so the edge darkens).
void merge_left(Kern& k, int mode) {
  const int w = -k.u;
  if (mode != kBlack) k.ku[w] += accumulate(k.ku, w);
  drop_front(k.ku, k.uw, w);
  k.uw -= w;
  k.u = 0;
}
void merge_right(Kern& k, int mode) {
  const int w = k.uw + k.u - k.res_u();
  const int first = k.uw - w;
  if (mode != kBlack) k.ku[first - 1] += accumulate(k.ku + first, w);
  k.uw -= w;
}
void merge_bottom(Kern& k, int mode) {
  const int w = -k.v;
  if (mode != kBlack) k.kv[w] += accumulate(k.kv, w);
  drop_front(k.kv, k.vw, w);
  k.vw -= w;
  k.v = 0;
}
void merge_top(Kern& k, int mode) {
  const int w = k.vw + k.v - k.res_v();
  const int first = k.vw - w;
  if (mode != kBlack) k.kv[first - 1] += accumulate(k.kv + first, w);
  k.vw -= w;
}

// A piece split off at an edge keeps the kernel's resolution and starts unrotated; when the whole
// kernel lies past the edge it moves over whole.
void split_left(Kern& k, Kern& piece) {
  const int w = -k.u;
  if (w < k.uw) {
    piece = k;
    piece.u = k.res_u() - w;
    piece.uw = w;
    piece.rot = 0;
    k.u = 0;
    drop_front(k.ku, k.uw, w);
    k.uw -= w;
  } else {
    piece = k;
    piece.u += k.res_u();
    k.u = 0;
    k.uw = 0;
  }
}
void split_right(Kern& k, Kern& piece) {
  const int w = k.u + k.uw - k.res_u();
  if (w < k.uw) {
    piece = k;
    piece.u = 0;
    piece.uw = w;
    piece.rot = 0;
    drop_front(piece.ku, k.uw, k.uw - w);
    k.uw -= w;
  } else {
    piece = k;
    piece.u -= k.res_u();
    k.u = 0;
    k.uw = 0;
  }
}
void split_bottom(Kern& k, Kern& piece) {
  const int w = -k.v;
  if (w < k.vw) {
    piece = k;
    piece.v = k.res_v() - w;
    piece.vw = w;
    piece.rot = 0;
    k.v = 0;
    drop_front(k.kv, k.vw, w);
    k.vw -= w;
  } else {
    piece = k;
    piece.v += k.res_v();
    k.v = 0;
    k.vw = 0;
  }
}
void split_top(Kern& k, Kern& piece) {
  const int w = k.v + k.vw - k.res_v();
  if (w < k.vw) {
    piece = k;
    piece.v = 0;
    piece.vw = w;
    piece.rot = 0;
    drop_front(piece.kv, k.vw, k.vw - w);
    k.vw -= w;
  } else {
    piece = k;
    piece.v -= k.res_v();
    k.v = 0;
    k.vw = 0;
  }
}

void flip_u(Kern& k) {
  k.u = k.res_u() - k.u - k.uw;
  std::reverse(k.ku, k.ku + k.uw);
}
void flip_v(Kern& k) {
  k.v = k.res_v() - k.v - k.vw;
  std::reverse(k.kv, k.kv + k.vw);
}
void swap_uv(Kern& k) {
  std::swap(k.ulog2, k.vlog2);
  std::swap(k.u, k.v);
  std::swap(k.uw, k.vw);
  for (int i = 0; i < kKmax; ++i) std::swap(k.ku[i], k.kv[i]);
}
// Turns the kernel `r` quarter turns counter-clockwise.
void rotate(Kern& k, int r) {
  switch (r & 3) {
    default: return;
    case 1: flip_u(k); swap_uv(k); break;
    case 2: flip_u(k); flip_v(k); break;
    case 3: flip_v(k); swap_uv(k); break;
  }
  k.rot = (k.rot + r) & 3;
}

// Halves the resolution: pairs of taps aligned to even texels sum.
void downres_u(Kern& k) {
  int src = 0, dst = 0, uw = k.uw;
  if (k.u & 1) { dst++; src++; uw--; }
  for (int i = uw / 2; i > 0; --i) { k.ku[dst++] = k.ku[src] + k.ku[src + 1]; src += 2; }
  if (uw & 1) k.ku[dst++] = k.ku[src++];
  k.u /= 2;
  k.uw = dst;
  k.ulog2--;
}
void downres_v(Kern& k) {
  int src = 0, dst = 0, vw = k.vw;
  if (k.v & 1) { dst++; src++; vw--; }
  for (int i = vw / 2; i > 0; --i) { k.kv[dst++] = k.kv[src] + k.kv[src + 1]; src += 2; }
  if (vw & 1) k.kv[dst++] = k.kv[src++];
  k.v /= 2;
  k.vw = dst;
  k.vlog2--;
}

// A corner kernel (at u = v = 0) made the same along both axes, so that it reads the same from
// every corner face whatever their orientation; its weight is scaled back towards the original's.
float make_symmetric(Kern& k, float initial_weight) {
  while (k.ulog2 > k.vlog2) downres_u(k);
  while (k.vlog2 > k.ulog2) downres_v(k);
  k.uw = k.vw = std::min(k.uw, k.vw);
  float new_weight = 0.0f;
  for (int i = 0; i < k.uw; ++i) {
    const float sum = k.ku[i] + k.kv[i];
    k.ku[i] = k.kv[i] = sum;
    new_weight += sum;
  }
  new_weight *= new_weight;
  const float scale = new_weight == 0.0f ? 1.0f : initial_weight / new_weight;
  if (scale < 1.0f) {
    if (scale < -1.0f) {
      for (int i = 0; i < k.uw; ++i) k.ku[i] *= -1.0f;
      new_weight = -new_weight;
    } else {
      for (int i = 0; i < k.uw; ++i) k.ku[i] *= scale;
      new_weight = initial_weight;
    }
  }
  return new_weight;
}

// Bits of a float: Ptex reads resolutions off the exponent.
int calc_res_from_width(float w) {
  uint32_t bits;
  std::memcpy(&bits, &w, sizeof bits);
  return 127 - static_cast<int>((bits >> 23) & 0xffu);
}
float reciprocal_pow2(int power) {
  const uint32_t bits = static_cast<uint32_t>(127 - power) << 23;
  float f;
  std::memcpy(&f, &bits, sizeof f);
  return f;
}

struct Width4 {
  int filter = SEAMCL_PTEX_GAUSSIAN;
  float c[7] = {};
  float eval(float x) const {
    if (filter == SEAMCL_PTEX_GAUSSIAN) return static_cast<float>(std::exp(static_cast<double>(-2.0f * x * x)));
    x = std::fabs(x);
    if (x < 1.0f) return (c[0] * x + c[1]) * x * x + c[2];
    if (x < 2.0f) return ((c[3] * x + c[4]) * x + c[5]) * x + c[6];
    return 0.0f;
  }
};

// A 2-unit cubic Hermite, which Ptex blends towards at widths of a quarter face and more.
float hermite_blur(float x) {
  x = std::fabs(x);
  return x < 1.0f ? (2.0f * x - 3.0f) * x * x + 1.0f : 0.0f;
}

// One axis of a width-4 kernel (gaussian, bicubic): 4 filter widths of taps at the resolution
// whose texel is at most the width, with Ptex's special cases for widths of a quarter face or more.
void width4_axis(const Width4& fn, int& res_log2, int& k_u, int& k_uw, float* ku, float u, float uw, int face_log2) {
  uw = std::max(uw, reciprocal_pow2(face_log2));
  res_log2 = calc_res_from_width(uw);
  const int resu = 1 << res_log2;
  const float lerp2 = 0.0f;  // Ptex's default: no blend towards the next resolution
  const float lerp1 = 1.0f - lerp2;
  if (uw >= 0.25f) {
    if (uw < 0.5f) {
      res_log2 = 2;
      const float upix = u * 4.0f - 0.5f;
      int u1 = static_cast<int>(std::ceil(upix - 2)), u2 = static_cast<int>(std::ceil(upix + 2));
      u1 = u1 & ~1;
      u2 = (u2 + 1) & ~1;
      k_u = u1;
      k_uw = u2 - u1;
      const float x1 = static_cast<float>(u1) - upix;
      for (int i = 0; i < k_uw; i += 2) {
        const float xa = x1 + static_cast<float>(i), xb = xa + 1.0f, xc = (xa + xb) * 0.25f;
        const float s = 1.0f / (uw + 0.75f);
        const float ka = fn.eval(xa), kb = fn.eval(xb), kc = hermite_blur(xc * s);
        ku[i] = ka * lerp1 + kc * lerp2;
        ku[i + 1] = kb * lerp1 + kc * lerp2;
      }
      return;
    }
    if (uw < 1.0f) {
      res_log2 = 1;
      const float upix = u * 2.0f - 0.5f;
      k_u = static_cast<int>(std::floor(u - 0.5f)) * 2;
      k_uw = 4;
      const float x1 = static_cast<float>(k_u) - upix;
      for (int i = 0; i < k_uw; i += 2) {
        const float xa = x1 + static_cast<float>(i), xb = xa + 1.0f, xc = (xa + xb) * 0.5f;
        const float s = 1.0f / (uw * 1.5f + 0.5f);
        const float ka = hermite_blur(xa * s), kb = hermite_blur(xb * s), kc = hermite_blur(xc * s);
        ku[i] = ka * lerp1 + kc * lerp2;
        ku[i + 1] = kb * lerp1 + kc * lerp2;
      }
      return;
    }
    res_log2 = 0;
    const float upix = u - 0.5f;
    k_uw = 2;
    const float ui = std::floor(upix);
    k_u = static_cast<int>(ui);
    ku[0] = hermite_blur(upix - ui);
    ku[1] = 1.0f - ku[0];
    return;
  }
  const float upix = u * static_cast<float>(resu) - 0.5f;
  const float uwpix = uw * static_cast<float>(resu);
  const float dupix = 2.0f * uwpix;
  const int u1 = static_cast<int>(std::ceil(upix - dupix)), u2 = static_cast<int>(std::ceil(upix + dupix));
  k_u = u1;
  k_uw = std::min(u2 - u1, kKmax);
  const float x1 = (static_cast<float>(u1) - upix) / uwpix, step = 1.0f / uwpix;
  for (int i = 0; i < k_uw; ++i) ku[i] = fn.eval(x1 + static_cast<float>(i) * step);
}

void box_weights(float* kernel, int size, float f1, float f2) {
  if (size == 1) {
    kernel[0] = f1 + f2 - 1.0f;
  } else {
    kernel[0] = f1;
    for (int i = 1; i < size - 1; ++i) kernel[i] = 1.0f;
    kernel[size - 1] = f2;
  }
}

void build_kernel(Kern& k, const PtexFilterQuery& q, float u, float v, float uw, float vw, const PtexFilterFace& f) {
  if (q.filter == SEAMCL_PTEX_BILINEAR || q.filter == SEAMCL_PTEX_BOX) {
    uw = std::min(uw, 1.0f);
    vw = std::min(vw, 1.0f);
    uw = std::max(uw, reciprocal_pow2(f.ulog2));
    vw = std::max(vw, reciprocal_pow2(f.vlog2));
    k.ulog2 = calc_res_from_width(uw);
    k.vlog2 = calc_res_from_width(vw);
    if (q.filter == SEAMCL_PTEX_BILINEAR) {
      const float upix = u * static_cast<float>(k.res_u()) - 0.5f;
      const float vpix = v * static_cast<float>(k.res_v()) - 0.5f;
      const float ufloor = std::floor(upix), vfloor = std::floor(vpix);
      k.u = static_cast<int>(ufloor);
      k.v = static_cast<int>(vfloor);
      k.uw = 2;
      k.vw = 2;
      const float ufrac = upix - ufloor, vfrac = vpix - vfloor;
      k.ku[0] = 1.0f - ufrac;
      k.ku[1] = ufrac;
      k.kv[0] = 1.0f - vfrac;
      k.kv[1] = vfrac;
      return;
    }
    u = u * static_cast<float>(k.res_u());
    v = v * static_cast<float>(k.res_v());
    uw *= static_cast<float>(k.res_u());
    vw *= static_cast<float>(k.res_v());
    const float u1 = u - 0.5f * uw, u2 = u + 0.5f * uw;
    const float v1 = v - 0.5f * vw, v2 = v + 0.5f * vw;
    const float u1floor = std::floor(u1), u2ceil = std::ceil(u2);
    const float v1floor = std::floor(v1), v2ceil = std::ceil(v2);
    k.u = static_cast<int>(u1floor);
    k.v = static_cast<int>(v1floor);
    k.uw = std::min(static_cast<int>(u2ceil) - k.u, 3);
    k.vw = std::min(static_cast<int>(v2ceil) - k.v, 3);
    box_weights(k.ku, k.uw, 1.0f - (u1 - u1floor), 1.0f - (u2ceil - u2));
    box_weights(k.kv, k.vw, 1.0f - (v1 - v1floor), 1.0f - (v2ceil - v2));
    return;
  }
  Width4 fn;
  fn.filter = q.filter;
  if (q.filter == SEAMCL_PTEX_BICUBIC) {
    const float B = 1.0f - q.sharpness;  // C = (1 - B) / 2
    fn.c[0] = 1.5f - B;
    fn.c[1] = 1.5f * B - 2.5f;
    fn.c[2] = 1.0f - static_cast<float>(1.0 / 3.0) * B;
    fn.c[3] = static_cast<float>(1.0 / 3.0) * B - 0.5f;
    fn.c[4] = 2.5f - 1.5f * B;
    fn.c[5] = 2.0f * B - 4.0f;
    fn.c[6] = 2.0f - static_cast<float>(2.0 / 3.0) * B;
  }
  width4_axis(fn, k.ulog2, k.u, k.uw, k.ku, u, uw, f.ulog2);
  width4_axis(fn, k.vlog2, k.v, k.vw, k.kv, v, vw, f.vlog2);
}

class Evaluator {
 public:
  Evaluator(const PtexFilterData& data, const PtexFilterTexture& texture)
      : d_(data), tex_(texture), nchan_(texture.channels) {}

  float weight_ = 0.0f;
  float applied_ = 0.0f;  // SEAMCL_PTEX_SEAMS_DISCARD: the weight of the taps read
  float result_[4] = {};

  int adj_face(const PtexFilterFace& f, int e) const { return f.adj_faces[e & 3]; }
  // Whether edge e leads to a neighbour the filter walks to (seam rules other than Ptex's walk none).
  bool walks(const PtexFilterFace& f, int e) const { return tex_.seams == SEAMCL_PTEX_SEAMS_PTEX && adj_face(f, e) >= 0; }
  int adj_edge(const PtexFilterFace& f, int e) const { return static_cast<int>((f.adj_edges >> (2 * (e & 3))) & 3u); }

  float texel(size_t index, int c) const {
    const size_t i = index * static_cast<size_t>(nchan_) + static_cast<size_t>(c);
    switch (tex_.data_type) {
      case 0: return static_cast<float>(d_.texels[i]);
      case 1: {
        uint16_t x;
        std::memcpy(&x, &d_.texels[2 * i], 2);
        return static_cast<float>(x);
      }
      case 2: {
        uint16_t h;
        std::memcpy(&h, &d_.texels[2 * i], 2);
        return half_to_float(h);
      }
      default: {
        float x;
        std::memcpy(&x, &d_.texels[4 * i], 4);
        return x;
      }
    }
  }

  static float half_to_float(uint16_t h) {
    const uint32_t sign = uint32_t(h & 0x8000u) << 16;
    const int exponent = (h >> 10) & 0x1f;
    const uint32_t mantissa = h & 0x3ffu;
    float magnitude;
    if (exponent == 0) {
      magnitude = std::ldexp(static_cast<float>(mantissa), -24);
    } else {
      const uint32_t bits = exponent == 31 ? (0xffu << 23) | (mantissa << 13)
                                           : (uint32_t(exponent - 15 + 127) << 23) | (mantissa << 13);
      std::memcpy(&magnitude, &bits, sizeof magnitude);
    }
    return sign ? -magnitude : magnitude;
  }

  size_t level_offset(const PtexFilterFace& f, int ulog2, int vlog2) const {
    return d_.level_offsets[f.level_base + static_cast<size_t>(ulog2) * (f.vlog2 + 1) + vlog2];
  }

  void apply(Kern& k, int face) {
    const PtexFilterFace& f = d_.faces[face];
    // Taps past the face's far side (a kernel wider than the neighbour) are out of Ptex's contract;
    // they are dropped rather than read from outside the face.
    if (k.u < 0) { const int w = std::min(-k.u, k.uw); drop_front(k.ku, k.uw, w); k.uw -= w; k.u = 0; }
    if (k.v < 0) { const int w = std::min(-k.v, k.vw); drop_front(k.kv, k.vw, w); k.vw -= w; k.v = 0; }
    if (k.u + k.uw > k.res_u()) k.uw = std::max(0, k.res_u() - k.u);
    if (k.v + k.vw > k.res_v()) k.vw = std::max(0, k.res_v() - k.v);
    if (k.uw <= 0 || k.vw <= 0) return;
    if (tex_.seams == SEAMCL_PTEX_SEAMS_DISCARD) applied_ += weight(k);
    while (k.ulog2 > f.ulog2) downres_u(k);
    while (k.vlog2 > f.vlog2) downres_v(k);
    float acc[4] = {};
    const bool constant = (f.flags & SEAMCL_PTEX_FLAG_CONSTANT) != 0 || (k.ulog2 == 0 && k.vlog2 == 0);
    if (constant) {
      const float w = weight(k);
      const size_t base = level_offset(f, 0, 0);
      for (int c = 0; c < nchan_; ++c) acc[c] = texel(base, c) * w;
    } else {
      // Columns first (down the rows with kv, then across with ku), as the kernel sums them.
      const size_t base = level_offset(f, k.ulog2, k.vlog2);
      const size_t rowlen = static_cast<size_t>(k.res_u());
      std::array<float, 4 * SEAMCL_PTEX_KMAX> columns{};
      for (int j = 0; j < k.vw; ++j) {
        const size_t first = base + static_cast<size_t>(k.v + j) * rowlen + static_cast<size_t>(k.u);
        for (int i = 0; i < k.uw; ++i)
          for (int c = 0; c < nchan_; ++c)
            columns[i * nchan_ + c] += texel(first + i, c) * k.kv[j];
      }
      for (int i = 0; i < k.uw; ++i)
        for (int c = 0; c < nchan_; ++c) acc[c] += columns[i * nchan_ + c] * k.ku[i];
    }
    // Tangent-space vectors (edge filter mode tanvec) turn with the neighbour.
    if (tex_.edge_filter_mode == 1 && nchan_ >= 2 && k.rot > 0) {
      switch (k.rot) {
        case 1: result_[0] -= acc[1]; result_[1] += acc[0]; break;
        case 2: result_[0] -= acc[0]; result_[1] -= acc[1]; break;
        default: result_[0] += acc[1]; result_[1] -= acc[0]; break;
      }
      for (int c = 2; c < nchan_; ++c) result_[c] += acc[c];
    } else {
      for (int c = 0; c < nchan_; ++c) result_[c] += acc[c];
    }
  }

  void apply_across_edge(Kern& k, const PtexFilterFace& f, int eid) {
    const int afid = adj_face(f, eid), aeid = adj_edge(f, eid);
    rotate(k, eid - aeid + 2);
    apply(k, afid);
  }

  void apply_to_corner_face(Kern& k, int eid, int cfid, int ceid) {
    rotate(k, eid - ceid + 2);
    apply(k, cfid);
  }

  void apply_to_corner(Kern& k, int faceid, const PtexFilterFace& f, int eid) {
    int afid = faceid, aeid = eid;
    const PtexFilterFace* af = &f;
    int cface[SEAMCL_PTEX_MAX_VALENCE];
    int cedge[SEAMCL_PTEX_MAX_VALENCE];
    int corners = 0;
    // Clockwise around the corner's vertex, to a boundary or back to this face.
    for (int i = 0; i < SEAMCL_PTEX_MAX_VALENCE; ++i) {
      const int next = adj_face(*af, aeid);
      aeid = (adj_edge(*af, aeid) + 1) % 4;
      afid = next;
      if (afid < 0 || (afid == faceid && aeid == eid)) {
        corners = i - 2;
        break;
      }
      af = &d_.faces[afid];
      cface[i] = afid;
      cedge[i] = aeid;
    }
    if (corners == 1) {
      apply_to_corner_face(k, eid, cface[1], cedge[1]);
    } else if (corners > 1) {
      rotate(k, eid + 2);
      const float initial_weight = weight(k);
      const float new_weight = make_symmetric(k, initial_weight);
      for (int i = 1; i <= corners; ++i) {
        Kern kc = k;
        apply_to_corner_face(kc, 2, cface[i], cedge[i]);
      }
      weight_ += new_weight * static_cast<float>(corners) - initial_weight;
    } else {
      weight_ -= weight(k);
    }
  }

  void split_and_apply(Kern& k, int faceid) {
    const PtexFilterFace& f = d_.faces[faceid];
    const bool split_r = k.u + k.uw > k.res_u(), split_l = k.u < 0;
    const bool split_t = k.v + k.vw > k.res_v(), split_b = k.v < 0;
    // A seam method that reads no neighbour makes every edge a boundary of its own rule.
    const int seams = tex_.seams;
    const int rule = seams == SEAMCL_PTEX_SEAMS_CLAMP ? kClamp : kBlack;
    const int umode = seams == SEAMCL_PTEX_SEAMS_PTEX ? tex_.u_border_mode : rule;
    const int vmode = seams == SEAMCL_PTEX_SEAMS_PTEX ? tex_.v_border_mode : rule;
    Kern ka, kc;
    if (split_r) {
      if (walks(f, kRight)) {
        split_right(k, ka);
        if (split_t) {
          if (walks(f, kTop)) { split_top(ka, kc); apply_to_corner(kc, faceid, f, kTop); }
          else merge_top(ka, vmode);
        }
        if (split_b) {
          if (walks(f, kBottom)) { split_bottom(ka, kc); apply_to_corner(kc, faceid, f, kRight); }
          else merge_bottom(ka, vmode);
        }
        apply_across_edge(ka, f, kRight);
      } else {
        merge_right(k, umode);
      }
    }
    if (split_l) {
      if (walks(f, kLeft)) {
        split_left(k, ka);
        if (split_t) {
          if (walks(f, kTop)) { split_top(ka, kc); apply_to_corner(kc, faceid, f, kLeft); }
          else merge_top(ka, vmode);
        }
        if (split_b) {
          if (walks(f, kBottom)) { split_bottom(ka, kc); apply_to_corner(kc, faceid, f, kBottom); }
          else merge_bottom(ka, vmode);
        }
        apply_across_edge(ka, f, kLeft);
      } else {
        merge_left(k, umode);
      }
    }
    if (split_t) {
      if (walks(f, kTop)) { split_top(k, ka); apply_across_edge(ka, f, kTop); }
      else merge_top(k, vmode);
    }
    if (split_b) {
      if (walks(f, kBottom)) { split_bottom(k, ka); apply_across_edge(ka, f, kBottom); }
      else merge_bottom(k, vmode);
    }
    apply(k, faceid);
  }

 private:
  const PtexFilterData& d_;
  const PtexFilterTexture& tex_;  // data's, or a render's with its seam rule
  int nchan_;
};

}  // namespace

std::array<float, 4> ptex_filter_twin(const PtexFilterData& data, const PtexFilterQuery& q) {
  return ptex_filter_twin(data, data.texture, q);
}

std::array<float, 4> ptex_filter_twin(const PtexFilterData& data, const PtexFilterTexture& tex, const PtexFilterQuery& q) {
  std::array<float, 4> out{};
  if (q.face < 0 || q.face >= static_cast<int>(data.faces.size())) return out;
  const PtexFilterFace& f = data.faces[q.face];
  Evaluator e(data, tex);
  const int nchan = tex.channels;
  const float one = tex.one_value;
  float u = q.u, v = q.v;
  if (q.filter == SEAMCL_PTEX_POINT || (f.flags & SEAMCL_PTEX_FLAG_NEIGHBORHOOD_CONSTANT) != 0) {
    // The texel under (u, v) at the face's own resolution; a constant face holds one texel, the
    // same at every resolution's offset, which every filter of a neighbourhood-constant face gives.
    const bool flat = (f.flags & (SEAMCL_PTEX_FLAG_CONSTANT | SEAMCL_PTEX_FLAG_NEIGHBORHOOD_CONSTANT)) != 0;
    const int ulog2 = flat ? 0 : f.ulog2, vlog2 = flat ? 0 : f.vlog2;
    const int resu = 1 << ulog2, resv = 1 << vlog2;
    const int ui = std::clamp(static_cast<int>(u * static_cast<float>(resu)), 0, resu - 1);
    const int vi = std::clamp(static_cast<int>(v * static_cast<float>(resv)), 0, resv - 1);
    const size_t base = e.level_offset(f, ulog2, vlog2) + static_cast<size_t>(vi) * resu + ui;
    for (int c = 0; c < nchan; ++c) out[c] = e.texel(base, c) / one;
    return out;
  }
  const float uw = std::fabs(q.uw), vw = std::fabs(q.vw);
  // A point outside the face is clamped into it under a seam method that reads no neighbour.
  const bool own = tex.seams == SEAMCL_PTEX_SEAMS_PTEX;
  bool black = false;
  switch (own ? tex.u_border_mode : kClamp) {
    case kClamp: u = std::clamp(u, 0.0f, 1.0f); break;
    case kPeriodic: u = u - std::floor(u); break;
    default: black = u <= -1.0f || u >= 2.0f; break;
  }
  switch (own ? tex.v_border_mode : kClamp) {
    case kClamp: v = std::clamp(v, 0.0f, 1.0f); break;
    case kPeriodic: v = v - std::floor(v); break;
    default: black = black || v <= -1.0f || v >= 2.0f; break;
  }
  if (black) return out;
  Kern k;
  build_kernel(k, q, u, v, uw, vw, f);
  strip_zeros(k);
  if (k.uw <= 0 || k.vw <= 0) return out;
  e.weight_ = weight(k);
  e.split_and_apply(k, q.face);
  const float w = (tex.seams == SEAMCL_PTEX_SEAMS_DISCARD ? e.applied_ : e.weight_) * one;
  if (!(w != 0.0f) || !std::isfinite(w)) return out;
  const float scale = 1.0f / w;
  for (int c = 0; c < nchan; ++c) out[c] = e.result_[c] * scale;
  return out;
}

std::array<cl_int, 3> ptex_rgb_source(int channels, int alpha_channel) {
  std::vector<int> colour;
  for (int c = 0; c < channels; ++c)
    if (c != alpha_channel) colour.push_back(c);
  std::array<cl_int, 3> out{-1, -1, -1};
  for (size_t o = 0; o < 3; ++o) {
    if (colour.size() == 1) out[o] = colour[0];
    else if (o < colour.size()) out[o] = colour[o];
  }
  return out;
}

PtexFilterQuery ptex_fragment_query(const PtexShading& p, int face, float u, float v, float dudx, float dvdx, float dudy,
                                    float dvdy) {
  PtexFilterQuery q{};
  q.face = std::isfinite(u) && std::isfinite(v) ? face : -1;
  q.filter = p.filter;
  q.u = u;
  q.v = v;
  const float uw = (std::fabs(dudx) + std::fabs(dudy)) * p.width_scale;
  const float vw = (std::fabs(dvdx) + std::fabs(dvdy)) * p.width_scale;
  q.uw = std::isfinite(uw) ? uw : 1.0f;
  q.vw = std::isfinite(vw) ? vw : 1.0f;
  q.sharpness = p.sharpness;
  return q;
}

glm::vec3 ptex_albedo_twin(const PtexRenderTexture& ptex, int face, float u, float v, float dudx, float dvdx, float dudy,
                           float dvdy) {
  const std::array<float, 4> value = ptex_filter_twin(*ptex.data, ptex.shading.texture,
                                                     ptex_fragment_query(ptex.shading, face, u, v, dudx, dvdx, dudy, dvdy));
  glm::vec3 rgb(0.0f);
  for (int o = 0; o < 3; ++o) {
    const int c = ptex.shading.rgb_source[o];
    rgb[o] = c >= 0 ? value[c] : 0.0f;
  }
  return rgb;
}

}  // namespace seamcl
