// Quad meshes from Wavefront OBJ files, read through tinyobjloader (Debian's libtinyobjloader-dev).
// Only what a Ptex-style scene needs is kept: vertex positions and faces of exactly four vertices,
// in file order (face i of the OBJ is face i of its .ptx). Texture coordinates, normals, groups
// and materials are ignored.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace seamcl {

struct ObjMesh {
  std::vector<glm::vec3> positions;
  std::vector<std::array<uint32_t, 4>> faces;  // counter-clockwise, as seamcl's Face::vertices
};

// A bound on the text read, so that a file cannot make the reader hold more than this.
inline constexpr size_t kMaxObjBytes = size_t{1} << 28;
// A bound on the faces, checked before any is parsed: reading and rendering a mesh costs hundreds of
// bytes a face (4M quads, the bound, about 2 GB), where the text alone could name 25M.
inline constexpr size_t kMaxObjFaces = size_t{1} << 22;

// Parses OBJ text. Lines whose first word is `version` or `surface` (written by the tools that
// made the Ptex samples; not OBJ) are skipped. A face that is not a quad, an index out of range
// or a non-finite position is InputError(field, ...) naming `source` and the face by its 0-based
// index among the file's faces (the Ptex face id) and its 1-based line number. Every `v` line must
// hold x y z, x y z w or x y z r g b, each a whole decimal number that is a finite float; every face
// corner must be i, i/j, i//k or i/j/k of whole non-zero integers naming elements that exist (a
// positive index counts from the file's first element, so forward references are allowed; a negative
// one counts back from the line). A bad one is InputError naming `source`, the vertex or face, its
// line and the word at fault. A text of more than kMaxObjFaces `f` lines is refused before any is
// read. Lines end at "\n", "\r\n" or a lone "\r", as tinyobjloader reads them.
ObjMesh parse_obj(const std::string& text, const std::string& source = "mesh",
                  const std::string& field = "scene");

// Reads and parses a file; an unreadable or oversized file is InputError(field) naming the path.
ObjMesh read_obj_file(const std::string& path, const std::string& field = "scene");

}  // namespace seamcl
