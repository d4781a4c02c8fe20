#include "cl/kernel_sources.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace seamcl {

std::string program_source() {
  const char* dir = std::getenv("SEAMCL_KERNEL_DIR");
  std::string source;
  for (const KernelSourceFile& file : embedded_kernel_sources()) {
    std::string text = file.text;
    if (dir != nullptr && *dir != '\0') {
      const std::string path = std::string(dir) + "/" + file.name;
      std::ifstream in(path);
      if (!in) throw std::runtime_error("SEAMCL_KERNEL_DIR: cannot read " + path);
      std::stringstream buffer;
      buffer << in.rdbuf();
      text = buffer.str();
    }
    source += "#line 1 \"" + std::string(file.name) + "\"\n" + text + "\n";
  }
  return source;
}

}  // namespace seamcl
