#include <seamcl/eval/reference.h>

#include <algorithm>
#include <condition_variable>
#include <exception>
#include <memory>
#include <mutex>
#include <functional>
#include <map>
#include <optional>
#include <set>
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

#include <nlohmann/json.hpp>

#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include <seamcl/version.h>
#include "io/image_codec.h"
#include "cl/kernel_sources.h"
#include "pipeline/stages/downsample_twin.h"

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

}  // namespace

std::string scene_content_hash(const Scene& scene) {
  Fnv64 f;
  f.value(scene.positions.size());
  for (const glm::vec3& p : scene.positions) f.value(p);
  f.value(scene.faces.size());
  for (size_t i = 0; i < scene.faces.size(); ++i) {
    const Face& face = scene.faces[i];
    f.value(face.vertices);
    f.value(face.texture.levels.size());
    if (!face.texture.levels.empty()) {
      // Level 0 determines the chain (build_mip_chain). A deferred face's is made and hashed
      // (then dropped): the key of a scene is the same whether its textures are deferred or not.
      const MipChain made = is_deferred(face.texture) ? face_texture(scene, i) : MipChain{};
      const TextureLevel& level = (made.levels.empty() ? face.texture : made).levels.front();
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

namespace {

std::string text_hash(const std::string& text) {
  Fnv64 f;
  f.bytes(text.data(), text.size());
  return f.hex();
}

// Reads a cached reference; nullopt when missing, unreadable, the wrong size, another key or not
// all finite.
std::optional<std::vector<glm::vec4>> read_cached(const std::string& path, const std::string& key, int width,
                                                  int height) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return std::nullopt;
  std::unique_ptr<ImageSource> input;
  std::vector<glm::vec4> pixels;
  try {
    input = image_codec().open(path);
    if (input->width() != width || input->height() != height || input->channels() != 4 ||
        input->attribute("seamcl:reference_key") != key) {
      return std::nullopt;
    }
    pixels.resize(static_cast<size_t>(width) * static_cast<size_t>(height));
    input->read(pixels.data(), false);
  } catch (const std::runtime_error&) {
    return std::nullopt;
  }
  // A render holds finite values only; a NaN reference would score every method's error as 0.
  const auto finite = [](const glm::vec4& p) {
    return std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b) && std::isfinite(p.a);
  };
  if (!std::all_of(pixels.begin(), pixels.end(), finite)) return std::nullopt;
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
  try {
    ImageLevel level{width, height, StoredPixels::Float, pixels.data()};
    ImageWriteOptions options;
    options.compression = "zip";
    options.text_attributes = {{"seamcl:reference_key", key}};
    image_codec().write(temp, "", {level}, options, nullptr);
  } catch (const std::runtime_error&) {
    fs::remove(temp, ec);
    return false;
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

std::optional<ReferenceKind> parse_reference_kind(std::string_view name) {
  if (name == "paper") return ReferenceKind::Paper;
  if (name == "box") return ReferenceKind::Box;
  if (name == "analytic") return ReferenceKind::Analytic;
  if (name == "seamless") return ReferenceKind::Seamless;
  return std::nullopt;
}

std::string to_string(ReferenceKind kind) {
  switch (kind) {
    case ReferenceKind::Paper: return "paper";
    case ReferenceKind::Box: return "box";
    case ReferenceKind::Analytic: return "analytic";
    case ReferenceKind::Seamless: return "seamless";
  }
  return "paper";
}

std::vector<std::string> reference_kind_names() { return {"paper", "box", "analytic", "seamless"}; }

std::vector<ReferenceKind> parse_reference_kinds(const std::vector<std::string>& names) {
  std::vector<ReferenceKind> kinds;
  for (const std::string& name : names) {
    const std::optional<ReferenceKind> kind = parse_reference_kind(name);
    if (!kind) throw InputError("reference", "unknown reference '" + name + "' (one of paper, box, analytic, seamless)");
    if (std::find(kinds.begin(), kinds.end(), *kind) == kinds.end()) kinds.push_back(*kind);
  }
  if (kinds.empty()) throw InputError("reference", "name at least one reference");
  return kinds;
}

std::vector<glm::vec4> downsample_box(const std::vector<glm::vec4>& pixels, int width, int height, int factor) {
  if (factor < 1 || width < factor || height < factor || width % factor != 0 || height % factor != 0 ||
      pixels.size() != static_cast<size_t>(width) * static_cast<size_t>(height)) {
    throw std::invalid_argument("downsample_box: " + std::to_string(width) + "x" + std::to_string(height) +
                                " is not a multiple of " + std::to_string(factor));
  }
  const int out_w = width / factor, out_h = height / factor;
  std::vector<glm::vec4> out(static_cast<size_t>(out_w) * static_cast<size_t>(out_h));
  for (int y = 0; y < out_h; ++y) {
    for (int x = 0; x < out_w; ++x) {
      glm::dvec4 sum(0.0);  // in double: 64 terms, no order dependence worth the name
      for (int j = 0; j < factor; ++j)
        for (int i = 0; i < factor; ++i)
          sum += glm::dvec4(pixels[static_cast<size_t>(y * factor + j) * static_cast<size_t>(width) +
                                   static_cast<size_t>(x * factor + i)]);
      out[static_cast<size_t>(y) * static_cast<size_t>(out_w) + static_cast<size_t>(x)] =
          glm::vec4(sum / static_cast<double>(factor * factor));
    }
  }
  return out;
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
  return image_codec().resize(pixels, width, height, out_w, out_h, "mitchell", kMitchellWidth);
}

std::string default_reference_method() { return parse_method("traverse") ? "traverse" : "discard"; }

int default_reference_msaa(const std::string& method) { return method == "traverse" ? 1 : 16; }

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
  using nlohmann::json;
  const json key = {
      {"version", SEAMCL_VERSION},
      {"kernels", text_hash(all_kernel_sources())},
      {"scene", settings.scene_hash.empty() ? scene_content_hash(scene) : settings.scene_hash},
      {"camera",
       {camera.eye.x, camera.eye.y, camera.eye.z, camera.target.x, camera.target.y, camera.target.z, camera.up.x,
        camera.up.y, camera.up.z, camera.fov_y_degrees}},
      {"render", to_json(high)},
      {"scale", kReferenceScale},
      {"filter", settings.kind == ReferenceKind::Box
                     ? json{{"name", "box"}}
                     : json{{"name", "mitchell"}, {"width", kMitchellWidth}, {"B", kMitchellB}, {"C", kMitchellC}}},
  };
  return key.dump();
}

namespace {

// A reference being made: whoever asks for the same key meanwhile waits for it and shares it.
struct Flight {
  std::mutex mutex;
  std::condition_variable done_cv;
  bool done = false;
  std::optional<ReferenceImage> result;
  std::exception_ptr failure;
};

std::mutex flights_mutex;
std::map<std::string, std::shared_ptr<Flight>>& flights() {
  static std::map<std::string, std::shared_ptr<Flight>> in_flight;
  return in_flight;
}

// The high-resolution frame reduced to the frame's size: by the render itself (the device
// downsample) or on the host (a HighResRender that hands back the 8x image).
using ReducedRender = std::function<RenderResult(const RenderOptions& high, const DownsampleTaps& taps)>;

double device_ms(const StageTimes& t) {
  return t.setup + t.binning + t.raster + t.shade + t.readback + t.tessellate + t.downsample;
}

ReferenceImage make_reference(const Scene& scene, const Camera& camera, const RenderOptions& frame,
                              const ReferenceSettings& settings, const ReducedRender& reduced) {
  if (settings.kind != ReferenceKind::Paper && settings.kind != ReferenceKind::Box) {
    throw InputError("reference", "the " + to_string(settings.kind) + " reference is not a downsampled render "
                                  "(reference_images and seamless_reference make it)");
  }
  const RenderOptions high = reference_render_options(frame, settings);
  ReferenceImage ref;
  ref.kind = settings.kind;
  ref.width = frame.width;
  ref.height = frame.height;
  ref.method = to_string(high.method);
  ref.msaa = high.msaa;
  // The key names the reference for the cache and for requests made at the same time; without a
  // cache and without the scene's hash at hand it is not worth a hash of every face.
  const bool keyed = settings.use_cache || !settings.scene_hash.empty();
  const std::string key = keyed ? reference_cache_key(scene, camera, frame, settings) : std::string();

  std::shared_ptr<Flight> flight;
  bool leader = true;
  if (keyed) {
    std::lock_guard<std::mutex> lock(flights_mutex);
    std::shared_ptr<Flight>& slot = flights()[key];
    if (slot) {
      flight = slot;
      leader = false;
    } else {
      slot = flight = std::make_shared<Flight>();
    }
  }
  if (!leader) {
    std::unique_lock<std::mutex> lock(flight->mutex);
    flight->done_cv.wait(lock, [&] { return flight->done; });
    if (flight->failure) std::rethrow_exception(flight->failure);
    ReferenceImage shared = *flight->result;
    shared.shared = true;
    return shared;
  }
  // Whatever happens, the waiters are answered and the key leaves the table.
  auto finish = [&](const std::optional<ReferenceImage>& result, std::exception_ptr failure) {
    if (!flight) return;
    {
      std::lock_guard<std::mutex> lock(flights_mutex);
      flights().erase(key);
    }
    std::lock_guard<std::mutex> lock(flight->mutex);
    flight->result = result;
    flight->failure = failure;
    flight->done = true;
    flight->done_cv.notify_all();
  };
  try {
    if (settings.use_cache) {
      const std::string dir = settings.cache_dir.empty() ? default_cache_dir() : settings.cache_dir;
      ref.cache_path = (fs::path(dir) / ("reference-" + text_hash(key) + ".exr")).string();
      if (auto cached = read_cached(ref.cache_path, key, ref.width, ref.height)) {
        ref.pixels = std::move(*cached);
        ref.from_cache = true;
        std::error_code ec;  // the last use, for trim_reference_cache's LRU order
        fs::last_write_time(ref.cache_path, fs::file_time_type::clock::now(), ec);
        finish(ref, nullptr);
        return ref;
      }
    }
    const auto start = std::chrono::steady_clock::now();
    {
      const RenderResult small = reduced(high, settings.kind == ReferenceKind::Box ? box_taps() : mitchell_taps());
      if (small.width != frame.width || small.height != frame.height) {
        throw std::runtime_error("reference render returned " + std::to_string(small.width) + "x" +
                                 std::to_string(small.height) + ", asked for " + std::to_string(frame.width) + "x" +
                                 std::to_string(frame.height));
      }
      ref.pixels = small.pixels;
      ref.kernel_ms = device_ms(small.ms);
    }
    ref.render_ms = ms_since(start);
    if (settings.use_cache) {
      if (write_cached(ref.cache_path, key, ref.width, ref.height, ref.pixels)) {
        trim_reference_cache(fs::path(ref.cache_path).parent_path().string(), settings.cache_max_bytes,
                             settings.cache_max_entries);
      }
      std::error_code ec;
      if (!fs::is_regular_file(ref.cache_path, ec)) ref.cache_path.clear();
    }
  } catch (...) {
    finish(std::nullopt, std::current_exception());
    throw;
  }
  finish(ref, nullptr);
  return ref;
}

}  // namespace

DownsampleTaps mitchell_taps() {
  return separable_taps(kReferenceScale, kMitchellWidth / 2.0, [](double x) { return mitchell_netravali(x); });
}

DownsampleTaps box_taps() {
  return separable_taps(kReferenceScale, 0.5, [](double) { return 1.0; });
}

ReferenceImage reference_image(const Scene& scene, const Camera& camera, const RenderOptions& frame,
                               const ReferenceSettings& settings, const HighResRender& render) {
  return make_reference(scene, camera, frame, settings, [&](const RenderOptions& high, const DownsampleTaps&) {
    const RenderResult big = render(high);
    if (big.width != high.width || big.height != high.height) {
      throw std::runtime_error("reference render returned " + std::to_string(big.width) + "x" +
                               std::to_string(big.height) + ", asked for " + std::to_string(high.width) + "x" +
                               std::to_string(high.height));
    }
    RenderResult small;
    small.width = big.width / kReferenceScale;
    small.height = big.height / kReferenceScale;
    small.ms = big.ms;
    small.pixels = settings.kind == ReferenceKind::Box ? downsample_box(big.pixels, big.width, big.height, kReferenceScale)
                                                       : downsample_mitchell(big.pixels, big.width, big.height, kReferenceScale);
    return small;
  });
}

ReferenceImage reference_image(Renderer& renderer, const Camera& camera, const RenderOptions& frame,
                               const ReferenceSettings& settings) {
  return make_reference(renderer.scene(), camera, frame, settings, [&](const RenderOptions& high, const DownsampleTaps& taps) {
    RenderResult result = renderer.render_downsampled(camera, high, taps);
    // The 8x frame's buffers are 64x a frame's: not kept for the renders that follow.
    renderer.release_frame_buffers();
    return result;
  });
}

namespace {

// uv of a triangle's planes at a pixel-space point, perspective-correct: the interpolation the
// shade stage does (kernels/shade_resolve.cl, interpolate_uv), without the derivatives.
glm::vec2 plane_uv(const TriangleSetup& t, float x, float y) {
  const float dx = x - t.ref_x, dy = y - t.ref_y;
  const float inv_w = t.inv_w[0] + t.inv_w[1] * dx + t.inv_w[2] * dy;
  const float w = 1.0f / inv_w;
  return {(t.u_over_w[0] + t.u_over_w[1] * dx + t.u_over_w[2] * dy) * w,
          (t.v_over_w[0] + t.v_over_w[1] * dx + t.v_over_w[2] * dy) * w};
}

}  // namespace

std::vector<glm::vec4> analytic_image(Renderer& renderer, const Scene& scene) {
  if (!scene.albedo) {
    throw InputError("reference", "the analytic reference needs the function the textures were baked from; scene '" +
                                      scene.name + "' has none (its textures came from files)");
  }
  const FrameParams f = renderer.last_frame_params();
  if (f.sample_count != 1) throw std::logic_error("analytic_image: the frame must have 1 sample per pixel");
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  const PackedScene& packed = renderer.packed_scene();
  const glm::vec3 background(f.background[0], f.background[1], f.background[2]);
  std::vector<glm::vec4> image(static_cast<size_t>(f.width) * static_cast<size_t>(f.height));
  // Rows in parallel: the 8x frame of a 480x540 image is 16.6 million albedo evaluations.
  auto shade_rows = [&](int first, int step) {
    for (int y = first; y < f.height; y += step) {
      for (int x = 0; x < f.width; ++x) {
        const size_t pixel = static_cast<size_t>(y) * static_cast<size_t>(f.width) + static_cast<size_t>(x);
        glm::vec3 sum(0.0f);
        {
          const uint32_t slot = winners[pixel];
          if (slot == SEAMCL_NO_TRIANGLE) {
            image[pixel] = glm::vec4(background, 1.0f);
            continue;
          }
          const TriangleSetup& t = setups[slot];
          const glm::vec2 uv = plane_uv(t, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
          // The pixel centre lies inside its triangle, so uv is inside the face up to rounding.
          const glm::vec3 point = face_point(scene.corners(scene.faces[t.face]), std::clamp(uv.x, 0.0f, 1.0f),
                                             std::clamp(uv.y, 0.0f, 1.0f));
          const glm::vec4 albedo = scene.albedo(t.face, point);
          const FaceGpu& face = packed.faces[t.face];
          const float n_dot_l =
              face.normal[0] * f.light_dir[0] + face.normal[1] * f.light_dir[1] + face.normal[2] * f.light_dir[2];
          const float lighting = f.ambient + (1.0f - f.ambient) * std::fmax(n_dot_l, 0.0f);
          sum += glm::vec3(albedo.x * f.light_color[0], albedo.y * f.light_color[1], albedo.z * f.light_color[2]) *
                 lighting;
        }
        image[pixel] = glm::vec4(sum, 1.0f);
      }
    }
  };
  const int threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
  std::vector<std::thread> helpers;
  for (int t = 1; t < threads; ++t) helpers.emplace_back(shade_rows, t, threads);
  shade_rows(0, threads);
  for (std::thread& helper : helpers) helper.join();
  return image;
}

std::vector<ReferenceImage> reference_images(Renderer& renderer, const Camera& camera, const RenderOptions& frame,
                                             const ReferenceSettings& settings, const std::vector<ReferenceKind>& kinds) {
  // One 8x render, made when the first reference needs it and kept on the device until the last
  // is done; each kind reduces it with its own filter there.
  std::optional<RenderResult> high_res;
  auto render_once = [&](const RenderOptions& high, const DownsampleTaps& taps) {
    if (!high_res) {
      high_res = renderer.render_downsampled(camera, high, taps);
      return *high_res;
    }
    RenderResult again = renderer.downsample_last_frame(taps);
    again.ms.total += high_res->ms.total;
    return again;
  };
  std::vector<ReferenceImage> images;
  for (ReferenceKind kind : kinds) {
    ReferenceSettings kind_settings = settings;
    kind_settings.kind = kind;
    if (kind == ReferenceKind::Seamless) {
      throw InputError("reference", "the seamless reference is rendered per measured rate (seamless_reference)");
    }
    if (kind != ReferenceKind::Analytic) {
      images.push_back(make_reference(renderer.scene(), camera, frame, kind_settings, render_once));
      continue;
    }
    const Scene& scene = renderer.scene();
    if (!scene.albedo) {
      throw InputError("reference", "the analytic reference needs the function the textures were baked from; scene '" +
                                        scene.name + "' has none (its textures came from files)");
    }
    const auto start = std::chrono::steady_clock::now();
    // The subsamples are the 8x frame's pixel centres: one sample per pixel whatever the other
    // references use.
    kind_settings.msaa = 1;
    const RenderOptions high = reference_render_options(frame, kind_settings);
    // The analytic image reads the winners of the Renderer's last frame: render it now unless that
    // is this frame (the other references may have come from the cache).
    const FrameParams last = renderer.last_frame_params();
    if (!high_res || last.width != high.width || last.height != high.height || last.sample_count != 1) {
      high_res = renderer.render(camera, high);
    }
    const std::vector<glm::vec4> fine = analytic_image(renderer, scene);
    ReferenceImage ref;
    ref.kind = kind;
    ref.width = frame.width;
    ref.height = frame.height;
    ref.method = "albedo";
    ref.msaa = high.msaa;
    ref.pixels = downsample_mitchell(fine, high.width, high.height, kReferenceScale);
    ref.render_ms = ms_since(start);
    images.push_back(std::move(ref));
  }
  // The 8x frame's buffers are 64x a frame's: not kept for the renders that follow.
  renderer.release_frame_buffers();
  return images;
}

namespace {

// The grid position of every face of a seamless grid, or why there is none.
struct GridLayout {
  int columns = 0, rows = 0;
  std::vector<size_t> faces;  // row-major, row 0 at v = 0
  std::string why_not;
};

GridLayout grid_layout(const Scene& scene) {
  GridLayout grid;
  const size_t n = scene.faces.size();
  // Right neighbour: its corners 0 and 3 are this face's 1 and 2; upper: its 0 and 1 are 3 and 2.
  std::map<std::pair<uint32_t, uint32_t>, size_t> by_left_edge, by_bottom_edge;
  for (size_t f = 0; f < n; ++f) {
    const auto& v = scene.faces[f].vertices;
    by_left_edge[{v[0], v[3]}] = f;
    by_bottom_edge[{v[0], v[1]}] = f;
  }
  auto right_of = [&](size_t f) -> std::optional<size_t> {
    const auto& v = scene.faces[f].vertices;
    const auto it = by_left_edge.find({v[1], v[2]});
    return it == by_left_edge.end() ? std::nullopt : std::optional<size_t>(it->second);
  };
  auto above = [&](size_t f) -> std::optional<size_t> {
    const auto& v = scene.faces[f].vertices;
    const auto it = by_bottom_edge.find({v[3], v[2]});
    return it == by_bottom_edge.end() ? std::nullopt : std::optional<size_t>(it->second);
  };
  std::vector<bool> has_left(n, false), has_below(n, false);
  for (size_t f = 0; f < n; ++f) {
    if (auto r = right_of(f)) has_left[*r] = true;
    if (auto a = above(f)) has_below[*a] = true;
  }
  std::vector<size_t> origins;
  for (size_t f = 0; f < n; ++f)
    if (!has_left[f] && !has_below[f]) origins.push_back(f);
  if (origins.size() != 1) {
    grid.why_not = "its faces do not form one grid of consistently oriented quads";
    return grid;
  }
  // Walks stop after n faces: on a closed surface they would go round for ever.
  std::vector<size_t> row_start{origins[0]};
  while (row_start.size() <= n) {
    const auto a = above(row_start.back());
    if (!a) break;
    row_start.push_back(*a);
  }
  grid.rows = static_cast<int>(row_start.size());
  for (size_t r = 0; r < row_start.size(); ++r) {
    std::vector<size_t> row{row_start[r]};
    while (row.size() <= n) {
      const auto next = right_of(row.back());
      if (!next) break;
      row.push_back(*next);
    }
    if (r == 0) grid.columns = static_cast<int>(row.size());
    if (static_cast<int>(row.size()) != grid.columns) {
      grid.why_not = "its faces do not form a rectangular grid";
      return grid;
    }
    for (size_t c = 0; c < row.size(); ++c) {
      if (r > 0 && above(grid.faces[(r - 1) * row.size() + c]) != row[c]) {
        grid.why_not = "its faces do not form a rectangular grid";
        return grid;
      }
      grid.faces.push_back(row[c]);
    }
  }
  if (grid.faces.size() != n || std::set<size_t>(grid.faces.begin(), grid.faces.end()).size() != n) {
    grid.why_not = "not every face belongs to the grid once";
  }
  return grid;
}

InputError seamless_refusal(const Scene& scene, const std::string& why) {
  return InputError("reference", "the seamless reference needs a planar grid of equal-resolution faces; scene '" +
                                     scene.name + "': " + why);
}

// The grid of a seamless-able scene with its faces' common size and the combined texture's, or
// the refusal (the corners' planarity is checked by seamless_scene, which places them).
struct SeamlessGrid {
  GridLayout grid;
  int face_width = 0, face_height = 0;
  int width = 0, height = 0;  // the combined texture
};

SeamlessGrid seamless_grid(const Scene& scene) {
  SeamlessGrid out;
  out.grid = grid_layout(scene);
  if (!out.grid.why_not.empty()) throw seamless_refusal(scene, out.grid.why_not);
  const int w = scene.faces[out.grid.faces[0]].texture.width(), h = scene.faces[out.grid.faces[0]].texture.height();
  for (size_t f : out.grid.faces) {
    if (scene.faces[f].texture.width() != w || scene.faces[f].texture.height() != h) {
      throw seamless_refusal(scene, "its faces' textures differ in size");
    }
  }
  const int W = w * out.grid.columns, H = h * out.grid.rows;
  if ((W & (W - 1)) != 0 || (H & (H - 1)) != 0) {
    throw seamless_refusal(scene, "the combined texture (" + std::to_string(W) + "x" + std::to_string(H) +
                                      ") is not a power of two");
  }
  out.face_width = w;
  out.face_height = h;
  out.width = W;
  out.height = H;
  return out;
}

}  // namespace

std::pair<int, int> seamless_texture_size(const Scene& scene) {
  const SeamlessGrid grid = seamless_grid(scene);
  return {grid.width, grid.height};
}

Scene seamless_scene(const Scene& scene) {
  auto refuse = [&](const std::string& why) { return seamless_refusal(scene, why); };
  const SeamlessGrid layout = seamless_grid(scene);
  const GridLayout& grid = layout.grid;
  const int w = layout.face_width, h = layout.face_height, W = layout.width, H = layout.height;
  // The grid's vertices on a parallelogram lattice: corner (i, j) at p00 + i a + j b.
  auto corner = [&](int i, int j) {
    const int c = std::min(i, grid.columns - 1), r = std::min(j, grid.rows - 1);
    const Face& face = scene.faces[grid.faces[static_cast<size_t>(r * grid.columns + c)]];
    const int k = (i > c ? 1 : 0) + (j > r ? 2 : 0);  // 0: corner 0, 1: corner 1, 2: corner 3, 3: corner 2
    const int index[4] = {0, 1, 3, 2};
    return scene.positions[face.vertices[static_cast<size_t>(index[k])]];
  };
  const glm::vec3 p00 = corner(0, 0);
  const glm::vec3 a = corner(1, 0) - p00, b = corner(0, 1) - p00;
  const float tolerance = 1e-5f * (glm::length(a) * static_cast<float>(grid.columns) + glm::length(b) * static_cast<float>(grid.rows));
  for (int j = 0; j <= grid.rows; ++j)
    for (int i = 0; i <= grid.columns; ++i)
      if (glm::length(corner(i, j) - (p00 + static_cast<float>(i) * a + static_cast<float>(j) * b)) > tolerance)
        throw refuse("its corners are not a planar, evenly spaced grid");
  TextureLevel combined{W, H, std::vector<glm::vec4>(static_cast<size_t>(W) * static_cast<size_t>(H))};
  for (int r = 0; r < grid.rows; ++r)
    for (int c = 0; c < grid.columns; ++c) {
      const size_t f = grid.faces[static_cast<size_t>(r * grid.columns + c)];
      const MipChain made = is_deferred(scene.faces[f].texture) ? face_texture(scene, f) : MipChain{};  // deferred: made here
      const TextureLevel& level = (made.levels.empty() ? scene.faces[f].texture : made).levels.front();
      for (int j = 0; j < h; ++j)
        for (int i = 0; i < w; ++i)
          combined.texels[static_cast<size_t>(r * h + j) * static_cast<size_t>(W) + static_cast<size_t>(c * w + i)] =
              level.at(i, j);
    }
  Scene out;
  out.name = scene.name + "-seamless";
  out.positions = {corner(0, 0), corner(grid.columns, 0), corner(grid.columns, grid.rows), corner(0, grid.rows)};
  out.faces.push_back({{0, 1, 2, 3}, build_mip_chain(std::move(combined))});
  out.camera = scene.camera;
  out.orbit = scene.orbit;
  out.light = scene.light;
  out.background = scene.background;
  validate_scene(out);
  return out;
}

ReferenceImage seamless_reference(Renderer& seamless, const Camera& camera, const RenderOptions& frame) {
  const auto start = std::chrono::steady_clock::now();
  RenderOptions options = frame;
  options.method = Method::Discard;
  ReferenceImage ref;
  ref.kind = ReferenceKind::Seamless;
  ref.width = frame.width;
  ref.height = frame.height;
  ref.method = to_string(options.method);
  ref.msaa = frame.msaa;
  ref.pixels = seamless.render(camera, options).pixels;
  ref.render_ms = ms_since(start);
  return ref;
}

void check_reference_cache_dir(const std::string& dir, const std::string& field) {
  const std::string path = dir.empty() ? default_cache_dir() : dir;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (fs::exists(status) && !fs::is_directory(status))
    throw InputError(field, "'" + path + "' is not a directory (the reference cache is a directory of EXR files)");
}

nlohmann::json reference_json(const ReferenceImage& reference, bool with_cache_path) {
  if (reference.kind == ReferenceKind::Seamless) {
    return {{"name", "seamless"}, {"method", reference.method}, {"msaa", reference.msaa}, {"scale", 1},
            {"filter", "the measured frame's"}, {"from_cache", false}, {"ms", reference.render_ms}};
  }
  nlohmann::json out = {{"name", to_string(reference.kind)}, {"method", reference.method}, {"msaa", reference.msaa},
                        {"scale", kReferenceScale},          {"from_cache", reference.from_cache},
                        {"ms", reference.render_ms}};
  if (reference.kind == ReferenceKind::Box) {
    out["filter"] = "box";
  } else {
    out["filter"] = "mitchell";
    out["filter_width"] = kMitchellWidth;
    out["B"] = kMitchellB;
    out["C"] = kMitchellC;
  }
  if (with_cache_path) {
    out["cache_path"] = reference.cache_path;
    // The command line's timing figures; the service's schema (server/openapi.json) lists its keys.
    out["kernel_ms"] = reference.kernel_ms;
    out["shared"] = reference.shared;
  }
  return out;
}

}  // namespace seamcl
