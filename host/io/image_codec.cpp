#include "io/image_codec.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>

namespace seamcl {
namespace {

namespace fs = std::filesystem;

constexpr const char* kModuleName = "libseamcl_oiio.so";

// The folder of the binary (executable or shared object) that holds this code.
fs::path own_binary_folder() {
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&own_binary_folder), &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code error;
  const fs::path binary = fs::canonical(info.dli_fname, error);
  return error ? fs::path() : binary.parent_path();
}

std::vector<std::string> candidate_paths() {
  std::vector<std::string> paths;
  if (const char* chosen = std::getenv("SEAMCL_OIIO_MODULE"); chosen != nullptr && *chosen != '\0') {
    paths.emplace_back(chosen);  // the user's choice alone: no silent fallback to another module
    return paths;
  }
  if (const fs::path folder = own_binary_folder(); !folder.empty()) {
    paths.push_back((folder / kModuleName).string());
    // An installed binary: prefix/bin/seamcl beside prefix/<libdir>/seamcl/.
    paths.push_back((folder.parent_path() / SEAMCL_OIIO_MODULE_LIBDIR / "seamcl" / kModuleName).string());
  }
  paths.emplace_back(SEAMCL_OIIO_MODULE_BUILD_PATH);
  paths.emplace_back(SEAMCL_OIIO_MODULE_INSTALL_PATH);
  return paths;
}

const ImageCodec* load() {
  std::string tried;
  for (const std::string& path : candidate_paths()) {
    std::error_code error;
    if (!fs::is_regular_file(path, error)) {
      tried += "\n  " + path + ": no such file";
      continue;
    }
    // RTLD_LOCAL: OpenImageIO's symbols stay the module's, whatever else the process loads.
    void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (module == nullptr) {
      const char* why = dlerror();
      tried += "\n  " + path + ": " + (why != nullptr ? why : "not loadable");
      continue;
    }
    using Entry = const ImageCodec* (*)(const char*);
    auto entry = reinterpret_cast<Entry>(dlsym(module, "seamcl_image_codec"));
    const ImageCodec* codec = entry != nullptr ? entry(kImageCodecAbi) : nullptr;
    if (codec != nullptr) return codec;  // never unloaded: the codec lives as long as the process
    tried += "\n  " + path + (entry == nullptr ? ": no seamcl_image_codec entry" : ": built for another interface");
    dlclose(module);
  }
  throw std::runtime_error(
      "image files need seamcl's OpenImageIO module (" + std::string(kModuleName) +
      "), which did not load; set SEAMCL_OIIO_MODULE to its path. Looked at:" + tried);
}

}  // namespace

const ImageCodec& image_codec() {
  // A failed load is not cached: a later call may find the module put in place meanwhile.
  static std::mutex mutex;
  static const ImageCodec* codec = nullptr;
  std::lock_guard<std::mutex> lock(mutex);
  if (codec == nullptr) codec = load();
  return *codec;
}

}  // namespace seamcl
