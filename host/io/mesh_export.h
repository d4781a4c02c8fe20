// A displaced render's tessellation as a mesh file: every patch's (T+1)^2 grid of displaced
// vertices, in the tessellation stage's order, one quad per grid cell. The patches' vertices are
// deliberately not merged: each patch keeps its own grid, so a reader can compare the vertices two
// patches make for one shared edge and see whether the surface is watertight.
//
//   .ply  binary little-endian: float32 x, y, z per vertex, faces as a uchar count (4) and four
//         uint32 vertex indices;
//   .obj  text: "v x y z" with 9 significant digits (enough for a float to read back to the same
//         bits), "f a b c d" with 1-based indices.
//
// Vertex k of patch p at grid point (i, j) is p * (T+1)^2 + j * (T+1) + i; the quad of cell (i, j)
// runs (i, j), (i+1, j), (i+1, j+1), (i, j+1), the patch's own corner order.
#pragma once
#include <string>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>

namespace seamcl {

enum class MeshFormat { Obj, Ply };

// The format named by the file's extension (.obj, .ply, any case); InputError(field) otherwise.
MeshFormat mesh_format_for_path(const std::string& path, const std::string& field = "export_mesh");

// Refuses, before any work, a path that cannot be written: empty, a bad extension, a directory
// that does not exist, or an existing directory at the path itself; InputError(field).
void check_mesh_path(const std::string& path, const std::string& field = "export_mesh");

// The file's bytes for `vertices` (patches * (T+1)^2 of them, T = tessellation). Throws
// std::invalid_argument when the count is not a whole number of patch grids.
std::string encode_patch_mesh(MeshFormat format, const std::vector<TessVertex>& vertices, int tessellation);

// Writes encode_patch_mesh's bytes to a temporary file beside `path` and renames it over `path`,
// so a failed write leaves no partial file (and the temporary is removed). InputError(field) when
// the path is refused (check_mesh_path) or cannot be written.
void write_patch_mesh(const std::string& path, const std::vector<TessVertex>& vertices, int tessellation,
                      const std::string& field = "export_mesh");

}  // namespace seamcl
