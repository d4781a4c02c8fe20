// The OpenCL program's source: the files of kernels/, embedded at build time
// (cmake/embed_kernels.cmake), or read from $SEAMCL_KERNEL_DIR when set (for development).
#pragma once
#include <string>
#include <vector>

namespace seamcl {

struct KernelSourceFile {
  const char* name;
  const char* text;
};

const std::vector<KernelSourceFile>& embedded_kernel_sources();

// The whole program text, files concatenated in build order, each preceded by a #line marker so
// that build-log positions name the real file.
std::string program_source();

}  // namespace seamcl
