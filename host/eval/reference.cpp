#include <seamcl/eval/reference.h>

#include <algorithm>
#include <functional>
#include <thread>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <unistd.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <seamcl/core/input_error.h>
#include <seamcl/version.h>
#include "cl/kernel_sources.h"

namespace seamcl {
namespace {

namespace fs = std::filesystem;

// FNV-1a, 64 bit: stable across runs and compilers (std::hash is not), good enough for cache keys.
struct Fnv64 {
  uint64_t h = 0xcbf29ce484222325ULL;
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) {
      h ^= p[i];
      h *= 0x100000001b3ULL;
    }
  }
  template <typename T>
  void value(const T& v) {
    bytes(&v, sizeof(T));
  }
  std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
    return text;
  }
};

std::string scene_content_hash(const Scene& scene) {
  Fnv64 f;
  f.value(scene.positions.size());
  for (const glm::vec3& p : scene.positions) f.value(p);
  f.value(scene.faces.size());
  for (const Face& face : scene.faces) {
    f.value(face.vertices);
    f.value(face.texture.levels.size());
    if (!face.texture.levels.empty()) {
      // Level 0 determines the chain (build_mip_chain).
      const TextureLevel& level = face.texture.levels.front();
      f.value(level.width);
      f.value(level.height);
      f.bytes(level.texels.data(), level.texels.size() * sizeof(glm::vec4));
    }
  }
  f.value(scene.light.to_light);
  f.value(scene.light.color);
  f.value(scene.light.ambient);
  f.value(scene.background);
  return f.hex();
}

std::string text_hash(const std::string& text) {
  Fnv64 f;
  f.bytes(text.data(), text.size());
  return f.hex();
}

// Reads a cached reference; nullopt when missing, unreadable, the wrong size or another key.
std::optional<std::vector<glm::vec4>> read_cached(const std::string& path, const std::string& key, int width,
                                                  int height) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  auto input = OIIO::ImageInput::open(path);
  if (!input) {
    (void)OIIO::geterror();  // clear the global error
    return std::nullopt;
  }
  const OIIO::ImageSpec& spec = input->spec();
  if (spec.width != width || spec.height != height || spec.nchannels != 4 ||
      spec.get_string_attribute("seamcl:reference_key") != key) {
    return std::nullopt;
  }
  std::vector<glm::vec4> pixels(static_cast<size_t>(width) * static_cast<size_t>(height));
  if (!input->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, pixels.data())) {
    (void)input->geterror();
    return std::nullopt;
  }
  return pixels;
}

// Writes float RGBA EXR with the key in its header, through a temporary file and a rename. A
// failure to cache is not an error of the comparison: it returns false.
bool write_cached(const std::string& path, const std::string& key, int width, int height,
                  const std::vector<glm::vec4>& pixels) {
  std::error_code ec;
  fs::create_directories(fs::path(path).parent_path(), ec);
  // Unique per process and thread, so concurrent writers of one entry never share a temp file.
  const std::string temp = path + ".tmp" + std::to_string(::getpid()) + "-" +
                           std::to_string(std::hash<std::thread::id>{}(std::this_thread::get_id())) + ".exr";
  {
    auto output = OIIO::ImageOutput::create(temp);
    if (!output) return false;
    OIIO::ImageSpec spec(width, height, 4, OIIO::TypeDesc::FLOAT);
    spec.attribute("seamcl:reference_key", key);
    spec.attribute("compression", "zip");
    if (!output->open(temp, spec) || !output->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) || !output->close()) {
      fs::remove(temp, ec);
      return false;
    }
  }
  fs::rename(temp, path, ec);
  if (ec) {
    fs::remove(temp, ec);
    return false;
  }
  return true;
}

bool is_reference_file(const std::string& name) {
  return name.rfind("reference-", 0) == 0 && name.size() > 14 && name.compare(name.size() - 4, 4, ".exr") == 0 &&
         name.find(".tmp") == std::string::npos;
}

bool is_reference_temp_file(const std::string& name) {
  return name.rfind("reference-", 0) == 0 && name.find(".exr.tmp") != std::string::npos;
}

}  // namespace

CacheTrim trim_reference_cache(const std::string& dir, std::uintmax_t max_bytes, size_t max_entries) {
  struct Entry {
    fs::path path;
    std::uintmax_t bytes;
    fs::file_time_type used;
  };
  CacheTrim trim;
  std::vector<Entry> entries;
  std::error_code ec;
  const fs::file_time_type now = fs::file_time_type::clock::now();
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code entry_ec;
    if (!it->is_regular_file(entry_ec)) continue;
    const std::string name = it->path().filename().string();
    const fs::file_time_type used = it->last_write_time(entry_ec);
    if (entry_ec) continue;
    if (is_reference_temp_file(name)) {
      if (now - used > std::chrono::hours(1)) fs::remove(it->path(), entry_ec);
      continue;
    }
    if (!is_reference_file(name)) continue;
    const std::uintmax_t bytes = it->file_size(entry_ec);
    if (!entry_ec) entries.push_back({it->path(), bytes, used});
  }
  // Most recently used first; the name breaks ties so that the order is the same for everyone.
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.used != b.used ? a.used > b.used : a.path < b.path;
  });
  bool full = false;  // once one entry does not fit, no older one is kept either
  for (const Entry& e : entries) {
    full = full || (max_bytes != 0 && trim.kept_bytes + e.bytes > max_bytes) ||
           (max_entries != 0 && trim.kept_entries + 1 > max_entries);
    if (!full) {
      ++trim.kept_entries;
      trim.kept_bytes += e.bytes;
      continue;
    }
    std::error_code remove_ec;
    if (fs::remove(e.path, remove_ec)) {
      ++trim.removed_entries;
      trim.removed_bytes += e.bytes;
    }
  }
  return trim;
}

double mitchell_netravali(double x, double b, double c) {
  x = std::fabs(x);
  if (x < 1.0) return ((12 - 9 * b - 6 * c) * x * x * x + (-18 + 12 * b + 6 * c) * x * x + (6 - 2 * b)) / 6.0;
  if (x < 2.0) {
    return ((-b - 6 * c) * x * x * x + (6 * b + 30 * c) * x * x + (-12 * b - 48 * c) * x + (8 * b + 24 * c)) / 6.0;
  }
  return 0.0;
}

std::vector<glm::vec4> downsample_mitchell(const std::vector<glm::vec4>& pixels, int width, int height, int factor) {
  if (factor < 1 || width < factor || height < factor || width % factor != 0 || height % factor != 0 ||
      pixels.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    throw std::invalid_argument("downsample_mitchell: " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not a multiple of " + std::to_string(factor));
  }
  const int out_w = width / factor, out_h = height / factor;
  // Wraps the caller's pixels without copying (ImageBuf only reads them here).
  const OIIO::ImageSpec src_spec(width, height, 4, OIIO::TypeDesc::FLOAT);
  const OIIO::ImageBuf src(src_spec, const_cast<glm::vec4*>(pixels.data()));
  OIIO::ImageBuf dst(OIIO::ImageSpec(out_w, out_h, 4, OIIO::TypeDesc::FLOAT));
  if (!OIIO::ImageBufAlgo::resize(dst, src, "mitchell", kMitchellWidth)) {
    throw std::runtime_error("Mitchell downsample failed: " + dst.geterror());
  }
  std::vector<glm::vec4> out(static_cast<size_t>(out_w) * static_cast<size_t>(out_h));
  if (!dst.get_pixels(OIIO::ROI(0, out_w, 0, out_h, 0, 1, 0, 4), OIIO::TypeDesc::FLOAT, out.data())) {
    throw std::runtime_error("Mitchell downsample: " + dst.geterror());
  }
  return out;
}

std::string default_reference_method() { return parse_method("traverse") ? "traverse" : "discard"; }

int default_reference_msaa(const std::string& method) { return method == "traverse" ? 1 : 16; }

std::string default_cache_dir() {
  if (const char* dir = std::getenv("SEAMCL_CACHE_DIR"); dir && *dir) return dir;
  if (const char* home = std::getenv("HOME"); home && *home) return (fs::path(home) / ".cache" / "seamcl").string();
  return (fs::temp_directory_path() / "seamcl-cache").string();
}

RenderOptions reference_render_options(const RenderOptions& frame, const ReferenceSettings& settings) {
  const std::string method = settings.method.empty() ? default_reference_method() : settings.method;
  if (!parse_method(method)) {
    std::string names;
    for (const std::string& n : method_names()) names += (names.empty() ? "" : ", ") + n;
    throw InputError("reference_method", "unknown method '" + method + "' (one of " + names + ")");
  }
  const int msaa = settings.msaa == 0 ? default_reference_msaa(method) : settings.msaa;
  if (msaa < 1 || msaa > 16 || (msaa & (msaa - 1)) != 0) {
    throw InputError("reference_msaa", "must be 1, 2, 4, 8 or 16, got " + std::to_string(msaa));
  }
  const long long w = static_cast<long long>(frame.width) * kReferenceScale;
  const long long h = static_cast<long long>(frame.height) * kReferenceScale;
  if (w > kMaxImageSide || h > kMaxImageSide || w * h > kMaxReferencePixels || w * h * msaa > kMaxSamplesPerImage) {
    throw InputError("size", std::to_string(frame.width) + "x" + std::to_string(frame.height) +
                                 " is too large for a reference: it renders at " + std::to_string(w) + "x" +
                                 std::to_string(h) + " with " + std::to_string(msaa) + " samples (at most " +
                                 std::to_string(kMaxImageSide) + " a side, " + std::to_string(kMaxReferencePixels) +
                                 " pixels and " + std::to_string(kMaxSamplesPerImage) + " samples)");
  }
  nlohmann::json request = to_json(frame);
  request["method"] = method;
  request["msaa"] = msaa;
  request["shading"] = "pixel";
  request["size"] = std::to_string(w) + "x" + std::to_string(h);
  return parse_render_options(request);
}

std::string reference_cache_key(const Scene& scene, const Camera& camera, const RenderOptions& frame,
                                const ReferenceSettings& settings) {
  const RenderOptions high = reference_render_options(frame, settings);
  const nlohmann::json key = {
      {"version", SEAMCL_VERSION},
      {"kernels", text_hash(program_source())},
      {"scene", scene_content_hash(scene)},
      {"camera",
       {camera.eye.x, camera.eye.y, camera.eye.z, camera.target.x, camera.target.y, camera.target.z, camera.up.x,
        camera.up.y, camera.up.z, camera.fov_y_degrees}},
      {"render", to_json(high)},
      {"scale", kReferenceScale},
      {"filter", {{"name", "mitchell"}, {"width", kMitchellWidth}, {"B", kMitchellB}, {"C", kMitchellC}}},
  };
  return key.dump();
}

ReferenceImage reference_image(const Scene& scene, const Camera& camera, const RenderOptions& frame,
                               const ReferenceSettings& settings, const HighResRender& render) {
  const RenderOptions high = reference_render_options(frame, settings);
  ReferenceImage ref;
  ref.width = frame.width;
  ref.height = frame.height;
  ref.method = to_string(high.method);
  ref.msaa = high.msaa;
  std::string key;
  if (settings.use_cache) {
    key = reference_cache_key(scene, camera, frame, settings);
    const std::string dir = settings.cache_dir.empty() ? default_cache_dir() : settings.cache_dir;
    ref.cache_path = (fs::path(dir) / ("reference-" + text_hash(key) + ".exr")).string();
    if (auto cached = read_cached(ref.cache_path, key, ref.width, ref.height)) {
      ref.pixels = std::move(*cached);
      ref.from_cache = true;
      std::error_code ec;  // the last use, for trim_reference_cache's LRU order
      fs::last_write_time(ref.cache_path, fs::file_time_type::clock::now(), ec);
      return ref;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  {
    const RenderResult big = render(high);
    if (big.width != high.width || big.height != high.height) {
      throw std::runtime_error("reference render returned " + std::to_string(big.width) + "x" +
                               std::to_string(big.height) + ", asked for " + std::to_string(high.width) + "x" +
                               std::to_string(high.height));
    }
    ref.pixels = downsample_mitchell(big.pixels, big.width, big.height, kReferenceScale);
  }
  ref.render_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (settings.use_cache) {
    if (write_cached(ref.cache_path, key, ref.width, ref.height, ref.pixels)) {
      trim_reference_cache(fs::path(ref.cache_path).parent_path().string(), settings.cache_max_bytes,
                           settings.cache_max_entries);
    }
    std::error_code ec;
    if (!fs::is_regular_file(ref.cache_path, ec)) ref.cache_path.clear();
  }
  return ref;
}

ReferenceImage reference_image(Renderer& renderer, const Camera& camera, const RenderOptions& frame,
                               const ReferenceSettings& settings) {
  return reference_image(renderer.scene(), camera, frame, settings, [&](const RenderOptions& high) {
    RenderResult result = renderer.render(camera, high);
    // The 8x frame's buffers are 64x a frame's: not kept for the renders that follow.
    renderer.release_frame_buffers();
    return result;
  });
}

nlohmann::json reference_json(const ReferenceImage& reference, bool with_cache_path) {
  nlohmann::json out = {{"method", reference.method},     {"msaa", reference.msaa},      {"scale", kReferenceScale},
                        {"filter", "mitchell"},           {"filter_width", kMitchellWidth}, {"B", kMitchellB},
                        {"C", kMitchellC},                {"from_cache", reference.from_cache},
                        {"ms", reference.render_ms}};
  if (with_cache_path) out["cache_path"] = reference.cache_path;
  return out;
}

}  // namespace seamcl
