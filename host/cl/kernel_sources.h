// The OpenCL programs' sources: the files of kernels/, embedded at build time
// (cmake/embed_kernels.cmake), or read from $SEAMCL_KERNEL_DIR when set (for development).
#pragma once
#include <string>
#include <vector>

#include <seamcl/cl/kernel_program.h>

namespace seamcl {

struct KernelSourceFile {
  const char* name;
  const char* text;
};

const std::vector<KernelSourceFile>& embedded_kernel_sources();

// The files `program` is built from, in build order.
std::vector<std::string> kernel_program_files(KernelProgram program);

// `program`'s text: its files concatenated in build order, each preceded by a #line marker so
// that build-log positions name the real file.
std::string program_source(KernelProgram program);

// Every kernel file concatenated: what the code version of cached results hashes.
std::string all_kernel_sources();

}  // namespace seamcl
