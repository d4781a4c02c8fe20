#include "ptexfilter/ptex_filter_texture.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

int element_bytes(PtexDataType t) {
  switch (t) {
    case PtexDataType::Uint8: return 1;
    case PtexDataType::Uint16:
    case PtexDataType::Float16: return 2;
    case PtexDataType::Float32: return 4;
  }
  return 1;
}

// Texels of every resolution 2^i x 2^j, i <= ulog2, j <= vlog2 (one texel for a constant face).
uint64_t face_texels(const PtexFaceInfo& info) {
  if (info.constant) return 1;
  return ((uint64_t(2) << info.ulog2) - 1) * ((uint64_t(2) << info.vlog2) - 1);
}

// Float to half as the Ptex library rounds it (PtexHalf::fromFloat): to nearest with ties away
// from zero, not IEEE ties to even. Halving two halves of one binade gives a tie half the time, so
// the rule shows in most texels of the resolutions made on demand.
uint16_t float_to_half(float f) {
  uint32_t x;
  std::memcpy(&x, &f, sizeof x);
  const uint32_t sign = (x >> 16) & 0x8000u;
  const uint32_t abs = x & 0x7fffffffu;
  if (abs == 0) return 0;
  if (abs >= 0x7f800000u) return static_cast<uint16_t>(sign | 0x7c00u | ((abs & 0x7fffffu) >> 13));
  const int exponent = static_cast<int>(abs >> 23) - 127 + 15;
  if (exponent <= 0) {  // a subnormal half (or zero): a multiple of 2^-24, ties away from zero
    float a;
    std::memcpy(&a, &abs, sizeof a);
    return static_cast<uint16_t>(sign | static_cast<uint32_t>(static_cast<double>(a) * 16777216.0 + 0.5));
  }
  if (exponent >= 31) return static_cast<uint16_t>(sign | 0x7c00u);
  // A carry out of the mantissa moves into the exponent (65520 and up become infinity).
  return static_cast<uint16_t>((sign | (static_cast<uint32_t>(exponent) << 10)) + (((abs & 0x7fffffu) + 0x1000u) >> 13));
}

float half_to_float(uint16_t h) {
  const int exponent = (h >> 10) & 0x1f;
  const uint32_t mantissa = h & 0x3ffu;
  float m;
  if (exponent == 0) {
    m = std::ldexp(static_cast<float>(mantissa), -24);
  } else {
    const uint32_t bits = exponent == 31 ? (0xffu << 23) | (mantissa << 13)
                                         : (uint32_t(exponent - 15 + 127) << 23) | (mantissa << 13);
    std::memcpy(&m, &bits, sizeof m);
  }
  return (h & 0x8000u) ? -m : m;
}

// The Ptex library's halving of two values of the file's type (PtexUtils' halve).
float halve(float a, float b, PtexDataType t) {
  switch (t) {
    case PtexDataType::Uint8:
    case PtexDataType::Uint16: return std::floor((a + b) * 0.5f);  // integers: exact in float, rounded down
    case PtexDataType::Float16: return half_to_float(float_to_half(0.5f * (a + b)));
    case PtexDataType::Float32: return 0.5f * (a + b);
  }
  return 0.5f * (a + b);
}

class FaceLevels {
 public:
  FaceLevels(const PtexFaceInfo& info, const PtexStoredFace& stored, int channels, PtexDataType type)
      : info_(info), stored_(stored), channels_(channels), type_(type) {}

  // Resolution (i, j) as Ptex's reader returns it from getData(face, Res(i, j)).
  const std::vector<float>& get(int i, int j) {
    const auto key = std::make_pair(i, j);
    if (auto it = made_.find(key); it != made_.end()) return it->second;
    std::vector<float> out;
    const int redu = info_.ulog2 - i, redv = info_.vlog2 - j;
    if (i == 0 && j == 0) {
      out = stored_.constant;
    } else if (redu == redv && static_cast<size_t>(redu) < stored_.levels.size()) {
      out = stored_.levels[redu];
    } else {
      const bool blend_u = redu == redv ? (i & 1) != 0 : redu > redv;
      const int width = 1 << i, height = 1 << j;
      out.resize(size_t(width) * height * channels_);
      if (blend_u) {
        const std::vector<float>& src = get(i + 1, j);
        const size_t src_width = size_t(width) * 2;
        for (int y = 0; y < height; ++y)
          for (int x = 0; x < width; ++x)
            for (int c = 0; c < channels_; ++c)
              out[(size_t(y) * width + x) * channels_ + c] =
                  halve(src[(y * src_width + 2 * x) * channels_ + c], src[(y * src_width + 2 * x + 1) * channels_ + c], type_);
      } else {
        const std::vector<float>& src = get(i, j + 1);
        for (int y = 0; y < height; ++y)
          for (int x = 0; x < width; ++x)
            for (int c = 0; c < channels_; ++c)
              out[(size_t(y) * width + x) * channels_ + c] =
                  halve(src[(size_t(2 * y) * width + x) * channels_ + c], src[(size_t(2 * y + 1) * width + x) * channels_ + c], type_);
      }
    }
    return made_.emplace(key, std::move(out)).first->second;
  }

 private:
  const PtexFaceInfo& info_;
  const PtexStoredFace& stored_;
  int channels_;
  PtexDataType type_;
  std::map<std::pair<int, int>, std::vector<float>> made_;
};

void put(std::vector<uint8_t>& texels, size_t index, float value, PtexDataType t) {
  switch (t) {
    case PtexDataType::Uint8: texels[index] = static_cast<uint8_t>(value); break;
    case PtexDataType::Uint16: {
      const uint16_t x = static_cast<uint16_t>(value);
      std::memcpy(&texels[2 * index], &x, 2);
      break;
    }
    case PtexDataType::Float16: {
      const uint16_t h = float_to_half(value);
      std::memcpy(&texels[2 * index], &h, 2);
      break;
    }
    case PtexDataType::Float32: std::memcpy(&texels[4 * index], &value, 4); break;
  }
}

}  // namespace

uint64_t ptex_filter_data_bytes(const PtexStored& stored) {
  uint64_t texels = 0, entries = 0;
  for (const PtexFaceInfo& info : stored.file.faces) {
    texels += face_texels(info);
    entries += uint64_t(info.ulog2 + 1) * (info.vlog2 + 1);
  }
  return texels * stored.file.channels * element_bytes(stored.file.data_type) + SEAMCL_PTEX_TEXEL_TAIL +
         entries * sizeof(cl_uint) + stored.file.faces.size() * sizeof(PtexFilterFace);
}

PtexFilterData build_ptex_filter_data(const PtexStored& stored, const PtexFilterLimits& limits) {
  const PtexFile& file = stored.file;
  for (size_t f = 0; f < stored.faces.size(); ++f)
    if (stored.faces[f].flags & SEAMCL_PTEX_FLAG_SUBFACE)
      throw InputError("texture", "face " + std::to_string(f) +
                                      " is a subface (a quad of a split non-quad face); the Ptex filters take "
                                      "textures of quad meshes without subfaces");
  for (const auto& [name, mode] : {std::pair<const char*, int>{"u", stored.u_border_mode}, {"v", stored.v_border_mode}})
    if (mode < 0 || mode > 2)
      throw InputError("texture", std::string("the ") + name + " border mode " + std::to_string(mode) +
                                      " is none of 0 (clamp), 1 (black), 2 (periodic)");
  if (stored.edge_filter_mode < 0 || stored.edge_filter_mode > 1)
    throw InputError("texture", "the edge filter mode " + std::to_string(stored.edge_filter_mode) +
                                    " is neither 0 (none) nor 1 (tanvec)");
  const uint64_t bytes = ptex_filter_data_bytes(stored);
  if (bytes > limits.max_bytes)
    throw InputError("texture", "the Ptex filters' resolutions of every face would take " + std::to_string(bytes) +
                                    " bytes, more than the limit of " + std::to_string(limits.max_bytes));
  uint64_t total_texels = 0;
  for (const PtexFaceInfo& info : file.faces) total_texels += face_texels(info);
  // The kernel addresses texel values with 32-bit indices.
  if (total_texels * uint64_t(file.channels) > std::numeric_limits<cl_uint>::max())
    throw InputError("texture", "the Ptex filters' resolutions hold " + std::to_string(total_texels * file.channels) +
                                    " values, more than 2^32");

  PtexFilterData out;
  out.texture.data_type = static_cast<cl_int>(file.data_type);
  out.texture.channels = file.channels;
  out.texture.u_border_mode = stored.u_border_mode;
  out.texture.v_border_mode = stored.v_border_mode;
  out.texture.edge_filter_mode = stored.edge_filter_mode;
  out.texture.face_count = static_cast<cl_int>(file.faces.size());
  out.alpha_channel = file.alpha_channel;
  out.texture.one_value = file.data_type == PtexDataType::Uint8    ? 255.0f
                          : file.data_type == PtexDataType::Uint16 ? 65535.0f
                                                                   : 1.0f;
  const int channels = file.channels;
  out.texels.resize(static_cast<size_t>(total_texels) * channels * element_bytes(file.data_type) + SEAMCL_PTEX_TEXEL_TAIL);
  out.faces.resize(file.faces.size());
  size_t next_texel = 0;
  for (size_t f = 0; f < file.faces.size(); ++f) {
    const PtexFaceInfo& info = file.faces[f];
    PtexFilterFace& face = out.faces[f];
    for (int e = 0; e < 4; ++e) face.adj_faces[e] = info.adjacent_faces[e];
    face.ulog2 = info.ulog2;
    face.vlog2 = info.vlog2;
    face.adj_edges = 0;
    for (int e = 0; e < 4; ++e) face.adj_edges |= cl_uint(info.adjacent_edges[e] & 3u) << (2 * e);
    face.flags = stored.faces[f].flags;
    face.level_base = static_cast<cl_uint>(out.level_offsets.size());
    if (info.constant) {
      out.level_offsets.insert(out.level_offsets.end(), size_t(info.ulog2 + 1) * (info.vlog2 + 1),
                               static_cast<cl_uint>(next_texel));
      for (int c = 0; c < channels; ++c)
        put(out.texels, next_texel * channels + c, stored.faces[f].constant[c], file.data_type);
      next_texel += 1;
      continue;
    }
    FaceLevels levels(info, stored.faces[f], channels, file.data_type);
    for (int i = 0; i <= info.ulog2; ++i)
      for (int j = 0; j <= info.vlog2; ++j) {
        const std::vector<float>& values = levels.get(i, j);
        out.level_offsets.push_back(static_cast<cl_uint>(next_texel));
        for (size_t k = 0; k < values.size(); ++k) put(out.texels, next_texel * channels + k, values[k], file.data_type);
        next_texel += values.size() / channels;
      }
  }
  return out;
}

}  // namespace seamcl

namespace seamcl {

std::vector<float> ptex_face_resolution(const PtexStored& stored, size_t face, int ulog2, int vlog2) {
  const PtexFaceInfo& info = stored.file.faces.at(face);
  if (info.constant) {
    std::vector<float> out;
    for (int t = 0; t < (1 << ulog2) * (1 << vlog2); ++t)
      out.insert(out.end(), stored.faces[face].constant.begin(), stored.faces[face].constant.end());
    return out;
  }
  FaceLevels levels(info, stored.faces[face], stored.file.channels, stored.file.data_type);
  return levels.get(ulog2, vlog2);
}

}  // namespace seamcl
