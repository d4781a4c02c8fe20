#include "cl/kernel_sources.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace seamcl {
namespace {

std::string file_text(const KernelSourceFile& file) {
  const char* dir = std::getenv("SEAMCL_KERNEL_DIR");
  if (dir == nullptr || *dir == '\0') return file.text;
  const std::string path = std::string(dir) + "/" + file.name;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("SEAMCL_KERNEL_DIR: cannot read " + path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::string concatenated(const std::vector<std::string>& names) {
  std::string source;
  for (const KernelSourceFile& file : embedded_kernel_sources()) {
    if (std::find(names.begin(), names.end(), file.name) == names.end()) continue;
    source += "#line 1 \"" + std::string(file.name) + "\"\n" + file_text(file) + "\n";
  }
  return source;
}

}  // namespace

std::vector<std::string> kernel_program_files(KernelProgram program) {
  switch (program) {
    case KernelProgram::Geometry:
      // tessellated_setup sets up its micro-triangles with triangle_setup.cl's functions.
      return {"seamcl_types.h", "sample_pattern.h", "tessellation_grid.h", "triangle_setup.cl", "binning.cl", "raster.cl",
              "tessellate.cl"};
    case KernelProgram::Shading:
      // ptex_filter.cl compiles to nothing outside the Ptex variant (SEAMCL_FILTER_PTEX), shade_inspect.cl
      // outside the inspector's (SEAMCL_INSPECT).
      // tessellation_grid.h: a displaced render's micro-triangles, lit with their vertices' normals.
      return {"seamcl_types.h", "sample_pattern.h", "tessellation_grid.h", "texture_sample.cl", "cube_sample.cl",
              "ptex_filter.cl", "shade_resolve.cl", "shade_inspect.cl"};
    case KernelProgram::Sampling: return {"seamcl_types.h", "texture_sample.cl", "cube_sample.cl", "lookup_batch.cl"};
    case KernelProgram::PtexFilter: return {"seamcl_types.h", "ptex_filter.cl", "ptex_lookup_batch.cl"};
    case KernelProgram::Downsample: return {"seamcl_types.h", "downsample.cl"};
  }
  throw std::logic_error("kernel_program_files: unknown program");
}

std::string program_source(KernelProgram program) {
  // Listed names come back in build order, and each must be an embedded file.
  const std::vector<std::string> names = kernel_program_files(program);
  for (const std::string& name : names) {
    const auto& files = embedded_kernel_sources();
    if (std::none_of(files.begin(), files.end(), [&](const KernelSourceFile& f) { return name == f.name; })) {
      throw std::logic_error(std::string("kernel program ") + kernel_program_name(program) + " names " + name +
                             ", which is not embedded (CMakeLists.txt SEAMCL_KERNEL_FILES)");
    }
  }
  return concatenated(names);
}

std::string all_kernel_sources() {
  std::vector<std::string> names;
  for (const KernelSourceFile& file : embedded_kernel_sources()) names.emplace_back(file.name);
  return concatenated(names);
}

}  // namespace seamcl
