#include <seamcl/assets/obj_mesh.h>

#include <charconv>
#include <cmath>
#include <string_view>

#include <tiny_obj_loader.h>

#include <seamcl/core/input_error.h>
#include <seamcl/core/regular_file.h>

namespace seamcl {
namespace {

// Calls visit(line) for each line of `text`, split where tinyobjloader splits it: at "\n", at "\r\n"
// and at a lone "\r", so that the lines checked here are the lines it reads.
template <class Visit>
void for_each_line(std::string_view text, Visit&& visit) {
  while (!text.empty()) {
    const size_t end = text.find_first_of("\r\n");
    visit(text.substr(0, end));
    if (end == std::string_view::npos) break;
    const size_t next = text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n' ? end + 2 : end + 1;
    text.remove_prefix(next);
  }
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// The next word of `rest` (empty when there is none); `rest` moves past it.
std::string_view next_word(std::string_view& rest) {
  size_t begin = 0;
  while (begin < rest.size() && is_space(rest[begin])) ++begin;
  size_t end = begin;
  while (end < rest.size() && !is_space(rest[end])) ++end;
  const std::string_view word = rest.substr(begin, end - begin);
  rest.remove_prefix(end);
  return word;
}

std::string_view first_word(std::string_view line) { return next_word(line); }

// The line up to its first word that starts with '#' (a comment after the data). tinyobjloader
// reads no further than a vertex's numbers, but would read a comment after a face's corners as
// more corners.
std::string_view without_comment(std::string_view line) {
  std::string_view rest = line;
  for (std::string_view word = next_word(rest); !word.empty(); word = next_word(rest)) {
    if (word.front() == '#') return line.substr(0, static_cast<size_t>(word.data() - line.data()));
  }
  return line;
}

size_t word_count(std::string_view line) {
  size_t count = 0;
  while (!next_word(line).empty()) ++count;
  return count;
}

// A word of the file as a message quotes it: cut short and with control characters replaced, so that
// a hostile file cannot make a message long or break it over lines.
std::string quoted(std::string_view word) {
  constexpr size_t kShown = 40;
  std::string out = "'";
  for (const char c : word.substr(0, kShown)) out += static_cast<unsigned char>(c) < 0x20 || c == 0x7f ? '?' : c;
  if (word.size() > kShown) out += "...";
  return out + "'";
}

std::string face_name(size_t face, size_t line) {
  return "face " + std::to_string(face) + " (0-based; line " + std::to_string(line) + ")";
}

std::string vertex_name(size_t vertex, size_t line) {
  return "vertex " + std::to_string(vertex) + " (0-based; line " + std::to_string(line) + ")";
}

// A number as tinyobjloader reads it may start with '+'; std::from_chars takes no '+'.
std::string_view without_plus(std::string_view word) {
  if (word.size() > 1 && word.front() == '+' && word[1] != '+' && word[1] != '-') word.remove_prefix(1);
  return word;
}

// The largest magnitude of a vertex's number: the mesh's extent, its faces' areas (a length of a
// cross product of diagonals, whose square grows as a coordinate's fourth power) and the camera
// framed on it are computed in float, and larger coordinates overflow them to infinity.
constexpr double kMaxVertexNumber = 1e9;

// Why `word` is not a coordinate (a finite 32-bit float written in decimal, whole, at most
// kMaxVertexNumber in magnitude), or empty if it is one. tinyobjloader reads the longest prefix
// that looks like a number and 0 when there is none, so "1,5" would be 1 and "0x10", "nan" and
// "inf" would be 0.
std::string coordinate_problem(std::string_view word) {
  const std::string_view digits = without_plus(word);
  const char* const last = digits.data() + digits.size();
  double value = 0.0;
  const auto [end, error] = std::from_chars(digits.data(), last, value);
  if (error == std::errc::invalid_argument || end != last) return "is not a decimal number";
  if (error == std::errc::result_out_of_range) return "is out of the range of a 32-bit float";
  if (!std::isfinite(value)) return "is not a finite number";
  if (!std::isfinite(static_cast<float>(value))) return "is out of the range of a 32-bit float";
  if (std::fabs(value) > kMaxVertexNumber) return "is larger in magnitude than 1e9";
  return {};
}

// How many elements of each kind a face corner can name.
struct ElementCounts {
  size_t positions = 0, texcoords = 0, normals = 0, faces = 0;
};

struct ElementKind {
  const char* one;
  const char* many;
};
constexpr ElementKind kPosition{"vertex", "vertices"};
constexpr ElementKind kTexcoord{"texture coordinate", "texture coordinates"};
constexpr ElementKind kNormal{"normal", "normals"};

// Counts `v`, `vt`, `vn` and `f` lines as a line's first word.
void count_element(std::string_view word, ElementCounts& counts) {
  if (word == "v") ++counts.positions;
  else if (word == "vt") ++counts.texcoords;
  else if (word == "vn") ++counts.normals;
  else if (word == "f") ++counts.faces;
}

// What the reader learns from the text itself before tinyobjloader sees it: the line of every
// face (tinyobjloader keeps none), each face's vertex count, and the text without the lines that
// are not OBJ. Every `v` line's numbers and every `f` line's indices are checked here, because
// tinyobjloader reads a number that is not one as 0 or as its prefix and an index with atoi.
struct Prescan {
  std::string text;
  std::vector<size_t> face_lines;  // 1-based
  size_t vertices = 0;             // `v` lines
};

class Prescanner {
 public:
  Prescanner(const std::string& source, const std::string& field) : source_(source), field_(field) {}

  Prescan run(const std::string& text) {
    // Positive indices may name elements defined further on; their bound is the file's count.
    for_each_line(text, [&](std::string_view line) { count_element(first_word(line), total_); });
    // Before anything is built: tinyobjloader and the scene hold hundreds of bytes a face.
    if (total_.faces > kMaxObjFaces)
      refuse("has " + std::to_string(total_.faces) + " face lines, more than the limit of " +
             std::to_string(kMaxObjFaces));
    Prescan out;
    out.text.reserve(text.size());
    for_each_line(text, [&](std::string_view line) {
      ++line_number_;
      const std::string_view word = first_word(line);
      // Written by the tools that made the Ptex samples; blanked so line numbers stay true.
      if (word == "version" || word == "surface") {
        out.text += '\n';
        return;
      }
      if (word == "v") check_vertex(line);
      if (word == "f") {
        line = without_comment(line);
        const std::string face = face_name(out.face_lines.size(), line_number_);
        const size_t corners = word_count(line) - 1;
        if (corners != 4) refuse(face + " has " + std::to_string(corners) + " vertices; only quads are supported");
        check_face(line, face);
        out.face_lines.push_back(line_number_);
      }
      count_element(word, so_far_);
      out.text.append(line);
      out.text += '\n';
    });
    out.vertices = so_far_.positions;
    return out;
  }

 private:
  [[noreturn]] void refuse(const std::string& what) const {
    throw InputError(field_, "'" + source_ + "': " + what);
  }

  // x y z, x y z w, or x y z r g b (tinyobjloader's vertex colours), each a finite float; a word that
  // starts with '#' begins a comment, as tinyobjloader reads one.
  void check_vertex(std::string_view line) const {
    const std::string vertex = vertex_name(so_far_.positions, line_number_);
    std::string_view rest = line;
    next_word(rest);  // "v"
    size_t numbers = 0;
    for (std::string_view word = next_word(rest); !word.empty() && word.front() != '#'; word = next_word(rest)) {
      const std::string problem = coordinate_problem(word);
      if (!problem.empty()) refuse(vertex + ": " + quoted(word) + " " + problem);
      ++numbers;
    }
    if (numbers != 3 && numbers != 4 && numbers != 6)
      refuse(vertex + " has " + std::to_string(numbers) + " numbers; a vertex is x y z, x y z w or x y z r g b");
  }

  void check_face(std::string_view line, const std::string& face) const {
    std::string_view rest = line;
    next_word(rest);  // "f"
    for (std::string_view corner = next_word(rest); !corner.empty(); corner = next_word(rest)) check_corner(corner, face);
  }

  // "i", "i/j", "i//k" or "i/j/k": a vertex, a texture coordinate and a normal.
  void check_corner(std::string_view corner, const std::string& face) const {
    std::string_view parts[3];
    size_t count = 0;
    std::string_view rest = corner;
    for (;;) {
      const size_t slash = rest.find('/');
      if (count == 3) refuse(face + " has a corner " + quoted(corner) + " that is not i, i/j, i//k or i/j/k");
      parts[count++] = rest.substr(0, slash);
      if (slash == std::string_view::npos) break;
      rest.remove_prefix(slash + 1);
    }
    // Only the texture coordinate of i//k may be left out.
    const bool empty_part = parts[0].empty() || (count == 2 && parts[1].empty()) || (count == 3 && parts[2].empty());
    if (empty_part) refuse(face + " has a corner " + quoted(corner) + " that is not i, i/j, i//k or i/j/k");
    check_index(parts[0], corner, face, kPosition, so_far_.positions, total_.positions, true);
    // Texture coordinates and normals are never read (only positions are): their indices must be
    // integers, but may name lines a careless exporter left out, as tinyobjloader allows.
    if (count >= 2 && !parts[1].empty()) check_index(parts[1], corner, face, kTexcoord, so_far_.texcoords, total_.texcoords, false);
    if (count == 3) check_index(parts[2], corner, face, kNormal, so_far_.normals, total_.normals, false);
  }

  // A whole integer, not 0: a positive one names the file's element of that number (forward references
  // are allowed, as tinyobjloader allows them), a negative one counts back from the elements before the
  // line; with must_exist, the element must be there. Messages are made only for a refusal (a large
  // file has tens of millions of indices).
  void check_index(std::string_view part, std::string_view corner, const std::string& face, ElementKind kind,
                   size_t before, size_t total, bool must_exist) const {
    const auto in_corner = [&] { return part.size() == corner.size() ? std::string() : " in corner " + quoted(corner); };
    const std::string_view digits = without_plus(part);
    const char* const last = digits.data() + digits.size();
    long long index = 0;
    const auto [end, error] = std::from_chars(digits.data(), last, index);
    if (error == std::errc::invalid_argument || end != last)
      refuse(face + " has a " + kind.one + " index " + quoted(part) + in_corner() + " that is not an integer");
    if (error == std::errc{} && index == 0)
      refuse(face + " names " + kind.one + " " + quoted(part) + in_corner() + "; OBJ indices start at 1, or at -1 counting back");
    if (!must_exist) {
      if (error != std::errc{}) refuse(face + " has a " + kind.one + " index " + quoted(part) + in_corner() + " out of range");
      return;
    }
    const bool negative = digits.front() == '-';
    const auto missing = [&] { return face + " names a " + kind.one + " that does not exist: " + quoted(part) + in_corner(); };
    if (negative && (error != std::errc{} || static_cast<unsigned long long>(-(index + 1)) >= before))
      refuse(missing() + " counts back past the " + std::to_string(before) + " " + (before == 1 ? kind.one : kind.many) +
             " before line " + std::to_string(line_number_));
    if (!negative && (error != std::errc{} || static_cast<unsigned long long>(index) > total))
      refuse(missing() + "; the file has " + std::to_string(total) + " " + (total == 1 ? kind.one : kind.many));
  }

  const std::string& source_;
  const std::string& field_;
  ElementCounts total_;
  ElementCounts so_far_;  // before the line being read
  size_t line_number_ = 0;
};

}  // namespace

ObjMesh parse_obj(const std::string& text, const std::string& source, const std::string& field) {
  const Prescan scanned = Prescanner(source, field).run(text);
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
  // Every `v` line was checked above; a vertex more or less would shift every index.
  if (mesh.positions.size() != scanned.vertices)
    throw InputError(field, "'" + source + "': " + std::to_string(scanned.vertices) + " vertex lines but " +
                                std::to_string(mesh.positions.size()) + " vertices read; a vertex line is malformed");
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
  // Opened and checked as one file (core/regular_file.h); tinyobjloader parses the text read here.
  RegularFile file(path);
  if (file.refusal() != RegularFile::Refusal::None)
    throw InputError(field, "cannot read mesh file '" + path + "': " + file.refusal_text());
  const auto too_large = [&] {
    return InputError(field, "mesh file '" + path + "' is larger than " + std::to_string(kMaxObjBytes >> 20) + " MiB");
  };
  if (file.size() > kMaxObjBytes) throw too_large();  // before any of it is read
  std::string text;
  if (!file.read_all(text, kMaxObjBytes))
    throw InputError(field, "cannot read mesh file '" + path + "': " + file.refusal_text());
  if (text.size() > kMaxObjBytes) throw too_large();  // grown since it was opened
  return parse_obj(text, path, field);
}

}  // namespace seamcl
