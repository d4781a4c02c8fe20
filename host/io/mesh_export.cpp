#include "io/mesh_export.h"

#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

size_t patch_count(const std::vector<TessVertex>& vertices, int tessellation) {
  if (tessellation < 1) throw std::invalid_argument("encode_patch_mesh: tessellation must be at least 1");
  const size_t side = static_cast<size_t>(tessellation) + 1;
  if (vertices.size() % (side * side) != 0)
    throw std::invalid_argument("encode_patch_mesh: " + std::to_string(vertices.size()) + " vertices are not whole (T+1)^2 grids");
  return vertices.size() / (side * side);
}

// The four grid vertices of cell (i, j) of `patch`, 0-based, in the patch's corner order.
void cell_quad(size_t patch, int i, int j, int tessellation, uint32_t out[4]) {
  const size_t side = static_cast<size_t>(tessellation) + 1;
  const size_t base = patch * side * side;
  auto at = [&](int x, int y) { return static_cast<uint32_t>(base + static_cast<size_t>(y) * side + static_cast<size_t>(x)); };
  out[0] = at(i, j);
  out[1] = at(i + 1, j);
  out[2] = at(i + 1, j + 1);
  out[3] = at(i, j + 1);
}

// Little-endian whatever the host's order, as the PLY header promises.
void append_u32(std::string& out, uint32_t value) {
  for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((value >> (8 * b)) & 0xffu));
}
void append_f32(std::string& out, float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  append_u32(out, bits);
}

// 9 significant digits: every float reads back to the same bits (FLT_DECIMAL_DIG). to_chars
// rather than printf, so the C locale's decimal point cannot change the file.
void append_obj_float(std::string& out, float value) {
  char text[32];
  const auto [end, error] = std::to_chars(text, text + sizeof text, value, std::chars_format::general, 9);
  if (error != std::errc()) throw std::runtime_error("encode_patch_mesh: a coordinate does not format");
  out.append(text, end);
}

std::string encode_ply(const std::vector<TessVertex>& vertices, int tessellation, size_t patches) {
  const size_t faces = patches * static_cast<size_t>(tessellation) * static_cast<size_t>(tessellation);
  std::string out = "ply\nformat binary_little_endian 1.0\n";
  out += "comment seamcl displaced patches: " + std::to_string(patches) + " patches, tessellation " +
         std::to_string(tessellation) + ", each patch's (T+1)^2 vertices its own (not merged)\n";
  out += "element vertex " + std::to_string(vertices.size()) + "\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  out += "element face " + std::to_string(faces) + "\n";
  out += "property list uchar uint vertex_indices\nend_header\n";
  out.reserve(out.size() + vertices.size() * 12 + faces * 17);
  for (const TessVertex& v : vertices)
    for (int c = 0; c < 3; ++c) append_f32(out, v.position[c]);
  uint32_t quad[4];
  for (size_t p = 0; p < patches; ++p) {
    for (int j = 0; j < tessellation; ++j) {
      for (int i = 0; i < tessellation; ++i) {
        cell_quad(p, i, j, tessellation, quad);
        out.push_back(static_cast<char>(4));
        for (uint32_t index : quad) append_u32(out, index);
      }
    }
  }
  return out;
}

std::string encode_obj(const std::vector<TessVertex>& vertices, int tessellation, size_t patches) {
  std::string out = "# seamcl displaced patches: " + std::to_string(patches) + " patches, tessellation " +
                    std::to_string(tessellation) + "\n# each patch's (T+1)^2 vertices are its own (not merged)\n";
  for (const TessVertex& v : vertices) {
    out += "v";
    for (int c = 0; c < 3; ++c) {
      out += ' ';
      append_obj_float(out, v.position[c]);
    }
    out += '\n';
  }
  uint32_t quad[4];
  for (size_t p = 0; p < patches; ++p) {
    for (int j = 0; j < tessellation; ++j) {
      for (int i = 0; i < tessellation; ++i) {
        cell_quad(p, i, j, tessellation, quad);
        out += "f";
        for (uint32_t index : quad) out += ' ' + std::to_string(index + 1);  // OBJ counts from 1
        out += '\n';
      }
    }
  }
  return out;
}

}  // namespace

MeshFormat mesh_format_for_path(const std::string& path, const std::string& field) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension == ".obj") return MeshFormat::Obj;
  if (extension == ".ply") return MeshFormat::Ply;
  throw InputError(field, "must end in .obj or .ply, got '" + path + "'");
}

void check_mesh_path(const std::string& path, const std::string& field) {
  if (path.empty()) throw InputError(field, "must not be empty");
  mesh_format_for_path(path, field);
  const std::filesystem::path file(path);
  std::error_code error;
  const std::filesystem::path parent = file.parent_path();
  if (!parent.empty() && !std::filesystem::is_directory(parent, error))
    throw InputError(field, "the directory '" + parent.string() + "' of '" + path + "' does not exist");
  if (std::filesystem::is_directory(file, error)) throw InputError(field, "'" + path + "' is a directory");
}

std::string encode_patch_mesh(MeshFormat format, const std::vector<TessVertex>& vertices, int tessellation) {
  const size_t patches = patch_count(vertices, tessellation);
  return format == MeshFormat::Ply ? encode_ply(vertices, tessellation, patches) : encode_obj(vertices, tessellation, patches);
}

void write_patch_mesh(const std::string& path, const std::vector<TessVertex>& vertices, int tessellation,
                      const std::string& field) {
  check_mesh_path(path, field);
  // Encoded whole first: a count that is not whole grids throws before any file exists.
  const std::string bytes = encode_patch_mesh(mesh_format_for_path(path, field), vertices, tessellation);
  const std::string temporary = path + ".partial";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (out) out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (out) out.flush();
    if (!out) {
      out.close();
      std::remove(temporary.c_str());
      throw InputError(field, "cannot write '" + path + "'");
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::remove(temporary.c_str());
    throw InputError(field, "cannot write '" + path + "': " + error.message());
  }
}

}  // namespace seamcl
