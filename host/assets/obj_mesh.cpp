#include <seamcl/assets/obj_mesh.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include <tiny_obj_loader.h>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

std::string_view first_word(std::string_view line) {
  const size_t begin = line.find_first_not_of(" \t");
  if (begin == std::string_view::npos) return {};
  const size_t end = line.find_first_of(" \t\r", begin);
  return line.substr(begin, end == std::string_view::npos ? std::string_view::npos : end - begin);
}

size_t word_count(std::string_view line) {
  size_t count = 0;
  bool in_word = false;
  for (char c : line) {
    const bool space = c == ' ' || c == '\t' || c == '\r';
    if (!space && !in_word) ++count;
    in_word = !space;
  }
  return count;
}

std::string face_name(size_t face, size_t line) {
  return "face " + std::to_string(face) + " (0-based; line " + std::to_string(line) + ")";
}

// What the reader learns from the text itself before tinyobjloader sees it: the line of every
// face (tinyobjloader keeps none), each face's vertex count, and the text without the lines that
// are not OBJ.
struct Prescan {
  std::string text;
  std::vector<size_t> face_lines;  // 1-based
};

Prescan prescan(const std::string& text, const std::string& source, const std::string& field) {
  Prescan out;
  out.text.reserve(text.size());
  size_t line_number = 0;
  std::string_view rest(text);
  while (!rest.empty()) {
    const size_t end = rest.find('\n');
    const std::string_view line = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view{} : rest.substr(end + 1);
    ++line_number;
    const std::string_view word = first_word(line);
    // Written by the tools that made the Ptex samples; blanked so line numbers stay true.
    if (word == "version" || word == "surface") {
      out.text += '\n';
      continue;
    }
    if (word == "f") {
      const size_t corners = word_count(line) - 1;
      if (corners != 4)
        throw InputError(field, "'" + source + "': " + face_name(out.face_lines.size(), line_number) + " has " +
                                    std::to_string(corners) + " vertices; only quads are supported");
      out.face_lines.push_back(line_number);
    }
    out.text.append(line);
    out.text += '\n';
  }
  return out;
}

}  // namespace

ObjMesh parse_obj(const std::string& text, const std::string& source, const std::string& field) {
  const Prescan scanned = prescan(text, source, field);
  tinyobj::ObjReaderConfig config;
  config.triangulate = false;  // faces are patches: their vertex order is their uv frame
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(scanned.text, "", config))
    throw InputError(field, "'" + source + "' is not a readable OBJ file: " + reader.Error());

  ObjMesh mesh;
  const std::vector<tinyobj::real_t>& coordinates = reader.GetAttrib().vertices;
  mesh.positions.reserve(coordinates.size() / 3);
  for (size_t v = 0; v + 2 < coordinates.size(); v += 3) {
    const glm::vec3 p(coordinates[v], coordinates[v + 1], coordinates[v + 2]);
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(field, "'" + source + "': vertex " + std::to_string(v / 3) + " (0-based) is not finite");
    mesh.positions.push_back(p);
  }
  mesh.faces.reserve(scanned.face_lines.size());
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    size_t next_index = 0;
    for (const unsigned char corners : shape.mesh.num_face_vertices) {
      const size_t face = mesh.faces.size();
      const size_t line = face < scanned.face_lines.size() ? scanned.face_lines[face] : 0;
      if (corners != 4)
        throw InputError(field, "'" + source + "': " + face_name(face, line) + " has " + std::to_string(corners) +
                                    " vertices; only quads are supported");
      std::array<uint32_t, 4> vertices{};
      for (int k = 0; k < 4; ++k) {
        const int index = shape.mesh.indices[next_index + static_cast<size_t>(k)].vertex_index;
        if (index < 0 || static_cast<size_t>(index) >= mesh.positions.size())
          throw InputError(field, "'" + source + "': " + face_name(face, line) + " names a vertex that does not exist (" +
                                      std::to_string(mesh.positions.size()) + " vertices)");
        vertices[static_cast<size_t>(k)] = static_cast<uint32_t>(index);
      }
      next_index += corners;
      mesh.faces.push_back(vertices);
    }
  }
  // tinyobjloader drops some malformed faces silently; face ids must not shift.
  if (mesh.faces.size() != scanned.face_lines.size())
    throw InputError(field, "'" + source + "': " + std::to_string(scanned.face_lines.size()) + " face lines but " +
                                std::to_string(mesh.faces.size()) + " faces read; a face line is malformed");
  if (mesh.faces.empty()) throw InputError(field, "'" + source + "' has no faces");
  return mesh;
}

ObjMesh read_obj_file(const std::string& path, const std::string& field) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error))
    throw InputError(field, "cannot read mesh file '" + path + "': no such file");
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error || size > kMaxObjBytes)
    throw InputError(field, "mesh file '" + path + "' is larger than " + std::to_string(kMaxObjBytes >> 20) + " MiB");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw InputError(field, "cannot read mesh file '" + path + "'");
  return parse_obj(text.str(), path, field);
}

}  // namespace seamcl
