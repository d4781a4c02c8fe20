#include <seamcl/ptexfilter/ptex_inspect.h>

#include <algorithm>

#include <seamcl/core/input_error.h>

#include "ptexfilter/ptex_filter_texture.h"

namespace seamcl {
namespace {

using nlohmann::json;

const char* data_type_name(PtexDataType t) {
  switch (t) {
    case PtexDataType::Uint8: return "uint8";
    case PtexDataType::Uint16: return "uint16";
    case PtexDataType::Float16: return "float16";
    case PtexDataType::Float32: return "float32";
  }
  return "?";
}

const char* border_mode_name(int mode) {
  switch (mode) {
    case 0: return "clamp";
    case 1: return "black";
    case 2: return "periodic";
  }
  return "unknown";
}

// A value in the file's units as Ptex's getPixel returns it: integers divided by their maximum.
float as_float(float stored, PtexDataType t) {
  switch (t) {
    case PtexDataType::Uint8: return stored * (1.0f / 255.0f);
    case PtexDataType::Uint16: return stored * (1.0f / 65535.0f);
    default: return stored;
  }
}

json pixel(const float* p, int channels, PtexDataType t) {
  json out = json::array();
  for (int c = 0; c < channels; ++c) out.push_back(as_float(p[c], t));
  return out;
}

}  // namespace

json ptex_info_json(const PtexStored& stored) {
  const PtexFile& file = stored.file;
  json header = {
      {"version", stored.version},
      {"minor_version", stored.minor_version},
      {"mesh_type", stored.mesh_type},
      {"mesh_type_name", stored.mesh_type == 1 ? "quad" : "triangle"},
      {"data_type", static_cast<int>(file.data_type)},
      {"data_type_name", data_type_name(file.data_type)},
      {"channels", file.channels},
      {"alpha_channel", file.alpha_channel},
      {"faces", file.faces.size()},
      {"levels", stored.levels},
      {"u_border_mode", border_mode_name(stored.u_border_mode)},
      {"v_border_mode", border_mode_name(stored.v_border_mode)},
      {"edge_filter_mode", stored.edge_filter_mode == 1 ? "tanvec" : "none"},
      {"metadata_bytes", stored.metadata_bytes},
  };
  json metadata = json::object();
  for (const auto& [key, value] : file.metadata) metadata[key] = value;
  json faces = json::array();
  json averages = json::array();
  for (size_t f = 0; f < file.faces.size(); ++f) {
    const PtexFaceInfo& info = file.faces[f];
    const PtexStoredFace& face = stored.faces[f];
    faces.push_back({{"face", f},
                     {"ulog2", info.ulog2},
                     {"vlog2", info.vlog2},
                     {"width", 1 << info.ulog2},
                     {"height", 1 << info.vlog2},
                     {"constant", info.constant},
                     {"neighborhood_constant", (face.flags & 4) != 0},
                     {"subface", info.subface},
                     {"stored_levels", face.levels.size()},
                     {"adjfaces", info.adjacent_faces},
                     {"adjedges", info.adjacent_edges}});
    averages.push_back(pixel(face.constant.data(), file.channels, file.data_type));
  }
  header["has_mipmaps"] = stored.levels > 1;  // Ptex's hasMipMaps: the file holds reduction levels
  json out = {{"header", header}, {"metadata", metadata}, {"face_info", faces}, {"face_average", averages}};
  if (file.mesh) out["mesh"] = {{"vertices", file.mesh->positions.size()}, {"faces", file.mesh->faces.size()}};
  return out;
}

json ptex_dump_json(const PtexStored& stored, int face, std::optional<int> level) {
  const PtexFile& file = stored.file;
  const int faces = static_cast<int>(file.faces.size());
  if (face < 0 || face >= faces)
    throw InputError("face", "face " + std::to_string(face) + " is out of range: the file has " + std::to_string(faces) +
                                 " faces (0 to " + std::to_string(faces - 1) + ")");
  const PtexFaceInfo& info = file.faces[face];
  const int k = level.value_or(0);
  const int most = std::min(info.ulog2, info.vlog2);
  if (k < 0 || k > most)
    throw InputError("level", "level " + std::to_string(k) + " is out of range: face " + std::to_string(face) + " of 2^" +
                                  std::to_string(info.ulog2) + " x 2^" + std::to_string(info.vlog2) +
                                  " texels has levels 0 to " + std::to_string(most));
  const int ulog2 = info.ulog2 - k, vlog2 = info.vlog2 - k;
  // A JSON number per channel costs tens of bytes in memory: a 4096 x 4096 level would take
  // gigabytes, so larger levels are refused and a coarser one is asked for.
  constexpr int kMaxDumpTexelsLog2 = 20;
  if (ulog2 + vlog2 > kMaxDumpTexelsLog2)
    throw InputError("level", "level " + std::to_string(k) + " of face " + std::to_string(face) + " has 2^" +
                                  std::to_string(ulog2 + vlog2) + " texels, more than the 2^" +
                                  std::to_string(kMaxDumpTexelsLog2) + " a dump shows; give --level " +
                                  std::to_string((ulog2 + vlog2 - kMaxDumpTexelsLog2 + 1) / 2 + k) + " or more");
  const std::vector<float> values = ptex_face_resolution(stored, static_cast<size_t>(face), ulog2, vlog2);
  const int width = 1 << ulog2, height = 1 << vlog2;
  json rows = json::array();
  for (int j = 0; j < height; ++j) {
    json row = json::array();
    for (int i = 0; i < width; ++i)
      row.push_back(pixel(values.data() + (size_t(j) * width + i) * file.channels, file.channels, file.data_type));
    rows.push_back(std::move(row));
  }
  const bool stored_level = info.constant ? false : static_cast<size_t>(k) < stored.faces[face].levels.size();
  return {{"face", face},
          {"level", k},
          {"ulog2", ulog2},
          {"vlog2", vlog2},
          {"width", width},
          {"height", height},
          {"stored", stored_level},
          {"constant", info.constant},
          {"average", pixel(stored.faces[face].constant.data(), file.channels, file.data_type)},
          {"texels", std::move(rows)}};
}


const OptionTable& ptex_dump_option_table() {
  static const OptionTable table = [] {
    OptionSpec face = make_option("face", OptionType::Integer, "The face to dump, 0 to the file's faces - 1");
    face.minimum = 0;
    face.maximum = (1 << 20) - 1;
    face.absent = "required";
    OptionSpec level = make_option("level", OptionType::Integer, "The level: each side halved this many times");
    level.minimum = 0;
    level.maximum = 12;
    level.default_value = 0;
    return OptionTable{face, level};
  }();
  return table;
}

json ptex_dump_json(const PtexStored& stored, const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  if (!request.contains("face")) throw InputError("face", "required: the face to dump");
  const json face = checked_option(*find_option(ptex_dump_option_table(), "face"), request.at("face"));
  std::optional<int> level;
  if (request.contains("level"))
    level = checked_option(*find_option(ptex_dump_option_table(), "level"), request.at("level")).get<int>();
  return ptex_dump_json(stored, face.get<int>(), level);
}

}  // namespace seamcl
