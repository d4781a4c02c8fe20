#include "http_server.h"

#include "api_documents.h"

#include "connection.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <set>

#include <unistd.h>
#include <utility>

#include <httplib.h>

#include <seamcl/core/cancelled.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/json_document.h>
#include <seamcl/core/over_budget.h>
#include <seamcl/memory/compare_memory.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/io/image_io.h>
#include <seamcl/jobs/compare_job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>

namespace seamcl::server {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// ---- What an error body may echo. A client can send any bytes of any length: invalid UTF-8
// decoded from %XX in the path or query, a header byte, a 1 MiB name. An error body must be valid
// UTF-8 (nlohmann's dump throws otherwise, and that throw inside cpp-httplib's error handler was
// std::terminate) and small, so every echoed value goes through echo().
constexpr size_t kMaxEchoChars = 100;   // one echoed value, in characters
constexpr size_t kMaxErrorChars = 300;  // a whole message: fixed text and its echoes
constexpr std::string_view kReplacementCharacter = "\xEF\xBF\xBD";  // U+FFFD
constexpr std::string_view kEllipsis = "\xE2\x80\xA6";               // U+2026

// The length of the well-formed UTF-8 sequence at text[at] (Unicode table 3-7: no overlong forms,
// no surrogates, nothing above U+10FFFF), or 0 when the byte there starts none.
size_t utf8_sequence_length(std::string_view text, size_t at) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[at + k]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return 1;
  size_t length = 0;
  unsigned char second_lo = 0x80, second_hi = 0xBF;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) second_lo = 0xA0;  // overlong
    if (lead == 0xED) second_hi = 0x9F;  // surrogates
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) second_lo = 0x90;  // overlong
    if (lead == 0xF4) second_hi = 0x8F;  // above U+10FFFF
  } else {
    return 0;  // a continuation byte, C0/C1 (overlong) or F5..FF
  }
  if (at + length > text.size()) return 0;
  for (size_t k = 1; k < length; ++k) {
    const unsigned char lo = k == 1 ? second_lo : 0x80, hi = k == 1 ? second_hi : 0xBF;
    if (byte(k) < lo || byte(k) > hi) return 0;
  }
  return length;
}

bool is_valid_utf8(std::string_view text) {
  for (size_t i = 0; i < text.size();) {
    const size_t length = utf8_sequence_length(text, i);
    if (length == 0) return false;
    i += length;
  }
  return true;
}

// `text` as it may appear in an error body: valid UTF-8 (each byte that starts no well-formed
// sequence becomes U+FFFD) and at most `max_chars` characters, cut on a character boundary and
// ending in an ellipsis when cut. Reads at most max_chars + 1 characters of `text`.
std::string echo(std::string_view text, size_t max_chars = kMaxEchoChars) {
  std::string out;
  size_t chars = 0;
  size_t cut = 0;  // out's size after max_chars - 1 characters: where an ellipsis goes
  for (size_t i = 0; i < text.size();) {
    if (chars == max_chars - 1) cut = out.size();
    if (chars == max_chars) {
      out.resize(cut);
      out += kEllipsis;
      return out;
    }
    const size_t length = utf8_sequence_length(text, i);
    if (length == 0) {
      out += kReplacementCharacter;
      i += 1;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
    ++chars;
  }
  return out;
}

// A whole error message, whoever wrote it (the library's parsers quote the values they echo):
// every quoted run ('...' or "...") is echoed, then the message as a whole.
std::string bounded_message(std::string_view message) {
  std::string out;
  for (size_t i = 0; i < message.size();) {
    const char c = message[i];
    const size_t close = c == '\'' || c == '"' ? message.find(c, i + 1) : std::string_view::npos;
    if (close == std::string_view::npos) {
      out += c;
      ++i;
      continue;
    }
    out += c;
    out += echo(message.substr(i + 1, close - i - 1));
    out += c;
    i = close + 1;
  }
  return echo(out, kMaxErrorChars);
}

// Every JSON answer is dumped with this: it cannot throw (invalid UTF-8 that got past echo()
// becomes U+FFFD rather than an exception inside cpp-httplib).
std::string json_text(const json& value) { return value.dump(-1, ' ', false, json::error_handler_t::replace); }

// {"error", "field"} with its status. Never throws on the client's bytes: it runs inside
// cpp-httplib's error and exception handlers, where an exception terminates the process.
void send_error(httplib::Response& res, int status, std::string_view field, std::string_view message) {
  res.status = status;
  res.set_content(json_text(json{{"error", bounded_message(message)}, {"field", echo(field)}}), "application/json");
}

// An InputError's message without its "<field>: " prefix. what() is a C string, so a NUL byte
// that a client put in a key or value (JSON's \u0000, the query's %00) cuts it short: then only
// what is left after the prefix, possibly nothing.
std::string input_error_message(const InputError& e) {
  const std::string_view what = e.what();
  const size_t prefix = e.field().size() + 2;
  if (what.size() < prefix) return "refused (the message was cut at a NUL byte)";
  return std::string(what.substr(prefix));
}

// Whether a request carries a body that cpp-httplib reads only when the request is routed: a
// refusal before routing leaves it on the connection, where it would be parsed as the next request.
bool carries_body(const httplib::Request& req) {
  return req.has_header("Transfer-Encoding") ||
         (req.has_header("Content-Length") && req.get_header_value("Content-Length") != "0");
}

// The media type of a Content-Type value: before any parameter, without surrounding spaces, in
// lower case (RFC 9110 8.3.1: type and subtype are case-insensitive).
std::string media_type(std::string_view content_type) {
  std::string_view type = content_type.substr(0, content_type.find(';'));
  while (!type.empty() && (type.front() == ' ' || type.front() == '\t')) type.remove_prefix(1);
  while (!type.empty() && (type.back() == ' ' || type.back() == '\t')) type.remove_suffix(1);
  std::string lower(type);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

bool is_json_media_type(std::string_view content_type) { return media_type(content_type) == "application/json"; }

// POST /v1/compare without a size: the render default (480x540) is over the compare limit, so
// the largest size of the default's aspect within max_pixels (each side floored, at least 1).
std::string default_compare_size(long long max_pixels) {
  const RenderOptions defaults;
  long long width = defaults.width, height = defaults.height;
  if (width * height > max_pixels) {
    const double scale = std::sqrt(static_cast<double>(max_pixels) / static_cast<double>(width * height));
    width = std::max(1LL, static_cast<long long>(std::floor(static_cast<double>(defaults.width) * scale)));
    height = std::max(1LL, static_cast<long long>(std::floor(static_cast<double>(defaults.height) * scale)));
    while (width * height > max_pixels && (width > 1 || height > 1)) (width >= height ? width : height) -= 1;
  }
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string scene_key(const std::string& name, bool tint) { return tint ? name + "+tint" : name; }

// The paths the server answers and the methods each allows (others: 405).
const std::map<std::string, std::vector<std::string>>& known_paths() {
  static const std::map<std::string, std::vector<std::string>> paths = {
      {"/", {"GET"}},           {"/health", {"GET"}},          {"/v1/scenes", {"GET"}}, {"/v1/assets", {"GET"}},
      {"/v1/methods", {"GET"}}, {"/v1/render", {"GET", "POST"}}, {"/v1/compare", {"POST"}}, {"/v1/reference", {"POST"}},
      {"/openapi.json", {"GET"}}, {"/ready", {"GET"}}};
  return paths;
}

// 405 for `method` on a known path that does not route it, with the Allow header listing what does.
void send_method_not_allowed(httplib::Response& res, const std::string& method, const std::string& path,
                             const std::vector<std::string>& allowed) {
  std::string allow;
  for (const std::string& m : allowed) allow += (allow.empty() ? "" : ", ") + m;
  res.set_header("Allow", allow);
  send_error(res, 405, "method", echo(method) + " is not allowed on " + echo(path) + " (allowed: " + allow + ")");
}

std::string method_description(const std::string& name) {
  if (name == "clamp") return "taps outside the face read the nearest edge texel (seams show)";
  if (name == "black") return "taps outside the face weigh zero, no renormalisation (edges darken)";
  if (name == "discard") return "taps outside the face weigh zero, the rest are renormalised (Toth 2013)";
  if (name == "traverse") {
    return "taps outside the face are fetched from the edge-adjacent faces and, past valence-4 corners, the diagonal "
           "face (McDonald 2013, with Ptex's corners)";
  }
  if (name == "traverse-edges") return "taps outside the face are fetched from the edge-adjacent faces only (McDonald 2013, as the paper compares)";
  if (name == "guardband") return "each mip level carries a band of texels from its neighbours (McDonald and Burley 2011)";
  return "";
}

// A query string as the JSON object the shared parser reads: integers and true/false become
// JSON numbers and booleans, everything else stays a string (the parser then names the field
// whose type is wrong).
json query_to_json(const httplib::Params& params) {
  json out = json::object();
  for (const auto& [key, value] : params) {
    // %XX decodes to any byte: refused here, naming the key, before anything echoes it.
    if (!is_valid_utf8(key)) throw InputError(echo(key), "this query key is not valid UTF-8");
    if (!is_valid_utf8(value)) throw InputError(key, "not valid UTF-8: '" + echo(value) + "'");
    if (out.contains(key)) throw InputError(key, "given more than once");
    long long number = 0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
    if (!value.empty() && error == std::errc() && end == value.data() + value.size()) {
      out[key] = number;
    } else if (value == "true" || value == "false") {
      out[key] = value == "true";
    } else {
      out[key] = value;
    }
  }
  return out;
}

// The reference cache of POST /v1/compare: the server's own directory, not a user's ~/.cache.
std::string server_cache_dir(const std::string& configured) {
  if (!configured.empty()) return configured;
  if (const char* dir = std::getenv("SEAMCL_CACHE_DIR"); dir && *dir) return dir;
  return (std::filesystem::temp_directory_path() / "seamcl-serve-cache").string();
}

// An inline scene with every face texture's width and height that is a power of two in 1..4096
// (what the parser accepts) replaced by 1: the same structure to validate, at no cost. Sizes the
// parser refuses are kept, so it still refuses them.
json with_tiny_textures(json scene) {
  if (!scene.is_object() || !scene.contains("faces") || !scene.at("faces").is_array()) return scene;
  for (json& face : scene.at("faces")) {
    if (!face.is_object() || !face.contains("texture") || !face.at("texture").is_object()) continue;
    json& texture = face.at("texture");
    for (const char* side : {"width", "height"}) {
      if (!texture.contains(side) || !texture.at(side).is_number_integer()) continue;
      const long long size = texture.at(side).get<long long>();
      if (size >= 1 && size <= 4096 && (size & (size - 1)) == 0) texture[side] = 1;
    }
  }
  return scene;
}

// An inline scene object taken out of a request (the rest goes to the option parser); null when
// `scene` is a built-in name or absent.
json take_inline_scene(json& rest) {
  json scene;
  if (rest.contains("scene") && rest.at("scene").is_object()) {
    scene = rest.at("scene");
    rest.erase("scene");
  }
  return scene;
}

// The answer's image format, taken out of a request: png unless `format` says exr.
ImageFormat take_image_format(json& rest) {
  if (!rest.contains("format")) return ImageFormat::Png;
  const json& value = rest.at("format");
  const auto parsed = value.is_string() ? parse_image_format(value.get<std::string>()) : std::nullopt;
  if (!parsed) throw InputError("format", "must be \"png\" or \"exr\", got " + echo(json_text(value)));
  rest.erase("format");
  return *parsed;
}

std::string mebibytes(size_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1 << 20));
  return text;
}

// The request field to change when the library names what drives a figure: a built-in scene
// cannot be changed by the client, but its texel format can (`texels`); an inline scene or an
// asset is the client's own (`scene`), held to the budgets as one.
std::string budget_field(const std::string& library_field, bool builtin_scene) {
  return library_field == "scene" && builtin_scene ? "texels" : library_field;
}

}  // namespace

// A refusal: status, the field at fault and a message, answered as {"error", "field"}.
struct HttpServer::HttpError {
  int status;
  std::string field;
  std::string message;
  int retry_after_s = 0;  // > 0: a Retry-After header (503)
};

// One render slot: the Renderers one worker uses, one per built-in scene (and tint) and a scratch
// one for inline scenes, which reloads its scene on every request.
struct HttpServer::Slot {
  std::map<std::string, std::unique_ptr<Renderer>> renderers;
  std::unique_ptr<Renderer> scratch;
};

struct HttpServer::SlotLease {
  HttpServer* server;
  Slot* slot;
  SlotLease(HttpServer* s, Slot* sl) : server(s), slot(sl) {}
  ~SlotLease() { server->release_slot(slot); }
  SlotLease(const SlotLease&) = delete;
  SlotLease& operator=(const SlotLease&) = delete;
};

namespace {

ConnectionLimits connection_limits(const ServerOptions& options) {
  ConnectionLimits limits;
  limits.max_connections = options.max_connections;
  limits.request_read_timeout = std::chrono::milliseconds(options.request_read_timeout_ms);
  limits.idle_timeout = std::chrono::milliseconds(options.idle_timeout_ms);
  // A chunked body's framing is counted too: room for the body at twice its limit, plus headers.
  limits.max_request_bytes = 2 * options.max_body_bytes + (64 << 10);
  return limits;
}

}  // namespace

HttpServer::HttpServer(ClRuntime& runtime, ServerOptions options)
    : runtime_(runtime), options_(std::move(options)), http_(std::make_unique<GuardedHttpServer>(connection_limits(options_))) {
  if (options_.threads < 1) throw InputError("threads", "must be at least 1");
  if (options_.queue < 0) throw InputError("queue", "must be at least 0");
  if (options_.max_connections < 1) throw InputError("max_connections", "must be at least 1");
  if (options_.request_read_timeout_ms < 1) throw InputError("request_read_timeout_ms", "must be at least 1");
  if (options_.deadline_ms < 0) throw InputError("deadline", "must be at least 0 (0: none)");
  options_.cache_dir = server_cache_dir(options_.cache_dir);
  if (!options_.assets_dir.empty()) assets_ = std::make_unique<AssetDirectory>(options_.assets_dir, options_.asset_cache);

  // The built-in scenes are generated on first use (builtin_scene), the default one by the
  // warm-up, so the port is bound without waiting for them. One slot per thread: their Renderers
  // are made and warmed after bind() (warm_up()); a slot becomes free once warm, so early
  // renders wait for it rather than build kernels themselves.
  for (int i = 0; i < options_.threads; ++i) slots_.push_back(std::make_unique<Slot>());
  total_variants_ = options_.warm_all_methods ? static_cast<int>(method_names().size() * filter_names().size()) : 1;

  install_routes();
}

HttpServer::~HttpServer() {
  stop();
  if (warm_thread_.joinable()) warm_thread_.join();
}

int HttpServer::bind() {
  if (options_.port == 0) {
    port_ = http_->bind_to_any_port(options_.host);
  } else {
    port_ = http_->bind_to_port(options_.host, options_.port) ? options_.port : -1;
  }
  if (port_ >= 0 && !warm_thread_.joinable()) {
    started_ = Clock::now();
    warm_thread_ = std::thread([this] { warm_up(); });
  }
  return port_;
}

void HttpServer::warm_up() {
  const Clock::time_point start = Clock::now();
  const RenderOptions defaults;
  const std::string default_key = scene_key(defaults.scene, false);
  try {
    // Not cut short by stop(): requests already admitted wait for these slots and are answered.
    for (size_t i = 0; i < slots_.size(); ++i) {
      log_line("warming: slot " + std::to_string(i + 1) + "/" + std::to_string(slots_.size()) + ", scene " +
               defaults.scene + ", " + to_string(defaults.method) + " " + to_string(defaults.filter));
      auto renderer = std::make_unique<Renderer>(runtime_);
      renderer->load_scene(*builtin_scene(defaults.scene, false), defaults.texels);
      renderer->warm_up(defaults);
      {
        std::lock_guard lock(slots_mutex_);
        slots_[i]->renderers[default_key] = std::move(renderer);
        free_slots_.push_back(slots_[i].get());
        ready_slots_.fetch_add(1);  // under the lock, before the notification: wait_ready() sees it
      }
      slot_freed_.notify_all();
    }
    warmed_variants_.store(1);
    char line[160];
    std::snprintf(line, sizeof line, "ready: %d slots warm in %.0f ms", ready_slots_.load(), ms_since(start));
    log_line(line);
    // The other variants on a Renderer of their own: the programs land in the shared ClRuntime
    // (and PoCL's cache), so the slots find them built; renders go on meanwhile.
    if (options_.warm_all_methods) {
      Renderer renderer(runtime_);
      renderer.load_scene(*builtin_scene(defaults.scene, false), defaults.texels);
      for (const std::string& method : method_names()) {
        for (const std::string& filter : filter_names()) {
          if (stopping_.load()) return;
          const RenderOptions variant = parse_render_options({{"method", method}, {"filter", filter}});
          if (variant.method == defaults.method && variant.filter == defaults.filter) continue;
          log_line("warming: " + method + " " + filter + " (" + std::to_string(warmed_variants_.load() + 1) + "/" +
                   std::to_string(total_variants_) + ")");
          renderer.warm_up(variant);
          warmed_variants_.fetch_add(1);
        }
      }
      std::snprintf(line, sizeof line, "warm: %d variants in %.0f ms", warmed_variants_.load(), ms_since(start));
      log_line(line);
    }
  } catch (const std::exception& e) {
    const std::string message = describe_cl_exception(e);
    log_line("error: warm-up failed: " + message);
    {
      std::lock_guard lock(slots_mutex_);
      // With some slots warm the service goes on with those (and says so in /health); with
      // none, renders are refused rather than left waiting.
      if (ready_slots_.load() == 0) warm_error_ = message;
      failed_slots_.store(options_.threads - ready_slots_.load());
    }
    slot_freed_.notify_all();
  }
}

bool HttpServer::wait_ready(std::chrono::milliseconds timeout) {
  std::unique_lock lock(slots_mutex_);
  slot_freed_.wait_for(lock, timeout, [&] { return ready() || !warm_error_.empty(); });
  return ready();
}

bool HttpServer::listen_after_bind() { return http_->listen_after_bind(); }

void HttpServer::stop() {
  stopping_.store(true);
  if (http_) {
    http_->stop();
    http_->begin_shutdown();
  }
  slot_freed_.notify_all();
}

bool HttpServer::is_running() const { return http_ && http_->is_running(); }

void HttpServer::log_line(const std::string& line) const {
  if (options_.log) {
    options_.log(line);
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
}

std::unique_ptr<HttpServer::SlotLease> HttpServer::acquire_slot(Clock::time_point arrived) {
  const int capacity = options_.threads + options_.queue;
  if (admitted_.fetch_add(1) >= capacity) {
    admitted_.fetch_sub(1);
    throw HttpError{503, "queue",
                    "busy: " + std::to_string(options_.threads) + " renders running and " +
                        std::to_string(options_.queue) + " waiting; retry later",
                    1};
  }
  std::unique_lock lock(slots_mutex_);
  // Wait for a slot, until the deadline, waking now and then to see whether the client has gone.
  const Clock::time_point deadline =
      options_.deadline_ms > 0 ? arrived + std::chrono::milliseconds(options_.deadline_ms) : Clock::time_point::max();
  const auto usable = [&] { return !free_slots_.empty() || !warm_error_.empty(); };
  while (!usable()) {
    const Clock::time_point wake = std::min(deadline, Clock::now() + std::chrono::milliseconds(200));
    slot_freed_.wait_until(lock, wake, usable);
    if (usable()) break;
    if (Clock::now() >= deadline || GuardedHttpServer::client_gone()) {
      admitted_.fetch_sub(1);
      if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
      throw HttpError{503, "deadline",
                      "no render slot free within this server's deadline of " + std::to_string(options_.deadline_ms) + " ms",
                      1};
    }
  }
  if (free_slots_.empty()) {
    admitted_.fetch_sub(1);
    throw HttpError{503, "server", "the server could not warm its kernels: " + warm_error_, 0};
  }
  Slot* slot = free_slots_.back();
  free_slots_.pop_back();
  return std::make_unique<SlotLease>(this, slot);
}

void HttpServer::release_slot(Slot* slot) {
  {
    std::lock_guard lock(slots_mutex_);
    free_slots_.push_back(slot);
  }
  admitted_.fetch_sub(1);
  slot_freed_.notify_one();
}

json HttpServer::health_json() const {
  std::string status = ready() ? "ready" : "starting";
  {
    std::lock_guard lock(slots_mutex_);
    if (!warm_error_.empty()) status = "failed";
  }
  return {{"status", status},
          {"warming", {{"slots_ready", ready_slots_.load()}, {"variants_ready", warmed_variants_.load()},
                       {"variants", total_variants_}}},
          {"open_connections", http_->open_connections()},
          {"device", runtime_.device_description()},
          {"uptime_s", std::chrono::duration<double>(Clock::now() - started_).count()},
          {"requests_served", served_.load()},
          {"renders_admitted", admitted_.load()},
          {"threads", options_.threads},
          {"queue", options_.queue}};
}

json HttpServer::assets_json() const {
  json list = json::array();
  if (assets_) {
    for (const AssetEntry& entry : assets_->list())
      list.push_back({{"name", entry.name}, {"kind", to_string(entry.kind)}, {"bytes", entry.bytes}});
  }
  return {{"enabled", assets_ != nullptr}, {"assets", list}};
}

json HttpServer::scenes_json() const {
  json list = json::array();
  const std::string default_scene = RenderOptions{}.scene;
  for (const GeneratorInfo& g : scene_generators()) {
    const Scene& scene = *builtin_scene(g.name, false);
    list.push_back({{"name", g.name},
                    {"description", g.description},
                    {"faces", scene.faces.size()},
                    {"triangles", scene.triangle_count()},
                    {"texels", scene.texel_count()},
                    {"orbit", scene.orbit.has_value()},
                    {"default", g.name == default_scene}});
  }
  return {{"scenes", list}};
}

json HttpServer::methods_json() const {
  // Made on first use (from the default scene's sizes), which the start need not wait for.
  std::call_once(methods_once_, [this] { methods_cache_ = make_methods_json(); });
  return methods_cache_;
}

json HttpServer::make_methods_json() const {
  const RenderOptions defaults;
  // The /v1/methods answer: texture memory of each method on the default scene, as packed for
  // the device (rgba8; rgba32f stores the same texels at 16 bytes each).
  const Scene& default_scene = *builtin_scene(defaults.scene, false);
  json methods = json::array();
  // From the sizes (exactly what pack_scene stores, render_memory.h): nothing is baked or packed.
  const SceneSizes default_sizes = scene_sizes(default_scene);
  for (const std::string& name : method_names()) {
    const Method method = *parse_method(name);
    const PackedTextureMemory packed =
        packed_texture_memory(default_sizes, TexelFormat::Rgba8, method == Method::Guardband ? defaults.guard_band : 0);
    const size_t float_texel_bytes = 4 * sizeof(float);
    methods.push_back({{"name", name},
                       {"description", method_description(name)},
                       {"texture_bytes", {{"rgba8", packed.texture_bytes}, {"rgba32f", packed.texels * float_texel_bytes}}},
                       {"padding_bytes", {{"rgba8", packed.padding_bytes}, {"rgba32f", packed.band_texels * float_texel_bytes}}},
                       {"adjacency_bytes", reads_adjacency(method) ? packed.adjacency_bytes : 0}});
  }
  std::vector<std::string> scene_names;
  for (const GeneratorInfo& g : scene_generators()) scene_names.push_back(g.name);
  return {
      {"scene", defaults.scene},
      {"methods", methods},
      {"options", options_document(scene_names, options_)},
      {"compare_options", compare_options_document(options_)},
      {"limits",
       {{"max_body_bytes", options_.max_body_bytes},
        {"max_samples", options_.max_samples},
        {"max_inline_faces", options_.max_inline_faces},
        {"max_inline_texels", options_.max_inline_texels},
        {"max_compare_pixels", options_.max_compare_pixels},
        {"max_compare_entries", options_.max_compare_entries},
        {"max_compare_repeat", options_.max_compare_repeat},
        {"max_reference_samples", options_.max_reference_samples}}}};

}

std::shared_ptr<const Scene> HttpServer::builtin_scene(const std::string& name, bool tint) const {
  const std::string key = scene_key(name, tint);
  std::lock_guard lock(scenes_mutex_);
  if (const auto found = scenes_.find(key); found != scenes_.end()) return found->second;
  const auto& generators = scene_generators();
  if (std::none_of(generators.begin(), generators.end(), [&](const GeneratorInfo& g) { return g.name == name; })) return nullptr;
  GeneratorOptions generator_options;
  generator_options.tint = tint;
  // Deferred: a slot's Renderer packs each face from the generator, so no float copy of the
  // scene's textures is held for the server's life (all of them together were about 700 MB).
  generator_options.defer_textures = true;
  auto scene = std::make_shared<const Scene>(generate_scene(name, generator_options));
  scenes_[key] = scene;
  return scene;
}

std::shared_ptr<const Scene> HttpServer::asset_scene(const RenderOptions& options) const {
  SceneSourceOptions source;
  source.generator.tint = options.tint;
  source.generator.defer_textures = true;  // a .ptx's faces decoded while packed, not held as floats
  // A file whose texels could not fit the host budget in any packing (4 bytes each, rgba8) is
  // refused by the reader before they are decoded; a deferred file never holds them all as floats.
  // A smaller asset is measured against the budgets like any scene.
  source.ptex_limits.max_texels = std::min<uint64_t>(source.ptex_limits.max_texels, options_.max_request_host_bytes / sizeof(uint32_t));
  return assets_->load(options.scene, options.texture, source);
}

// The scene: a built-in one, an asset of the --assets directory (names inside it only), or inline.
std::shared_ptr<const Scene> HttpServer::resolve_scene(const json& inline_scene, RenderOptions& options,
                                                       std::string& key) const {
  std::shared_ptr<const Scene> scene;
  key.clear();
  const bool builtin = inline_scene.is_null() && is_builtin_scene(options.scene);
  if (!options.texture.empty() && (builtin || !inline_scene.is_null()))
    throw HttpError{400, "texture", "goes with an .obj scene of the asset directory"};
  if (inline_scene.is_null() && !builtin && assets_) {
    scene = asset_scene(options);
    options.scene = scene->name;
    return scene;
  }
  if (!options.texture.empty()) throw HttpError{400, "texture", "this server has no asset directory (seamcl serve --assets DIR)"};
  if (inline_scene.is_null()) {
    const std::shared_ptr<const Scene> found =
        options.scene.find('+') == std::string::npos ? builtin_scene(options.scene, options.tint) : nullptr;
    if (!found) {
      std::string known;
      for (const GeneratorInfo& g : scene_generators()) known += (known.empty() ? "" : ", ") + g.name;
      throw HttpError{400, "scene", "unknown scene '" + options.scene + "' (built-in: " + known + "; or an inline scene object" +
                                        (assets_ ? "; or an asset (GET /v1/assets))" : ")")};
    }
    scene = found;
    key = scene_key(options.scene, options.tint);
  } else {
    // Its structure first, on a copy whose valid texture sizes are shrunk to 1x1 and whose
    // generator bakes nothing (so nothing big is built), so that a malformed scene is a 400
    // whatever its size; then the size limits, from the JSON, before any texture is made.
    GeneratorOptions deferred;
    deferred.defer_textures = true;
    try {
      Scene shape = parse_scene_json(with_tiny_textures(inline_scene), {}, deferred);
      validate_scene(shape);
    } catch (const InputError& e) {
      throw InputError("scene." + e.field(), input_error_message(e));
    }
    if (inline_scene.contains("faces") && inline_scene.at("faces").is_array()) {
      const json& faces = inline_scene.at("faces");
      if (faces.size() > options_.max_inline_faces) {
        throw HttpError{413, "scene.faces", std::to_string(faces.size()) + " faces exceed this server's limit of " +
                                                std::to_string(options_.max_inline_faces)};
      }
      long long texels = 0;
      for (size_t i = 0; i < faces.size(); ++i) {
        const json* texture = faces[i].is_object() && faces[i].contains("texture") ? &faces[i].at("texture") : nullptr;
        if (!texture || !texture->is_object()) continue;
        auto side = [&](const char* name) -> long long {
          if (!texture->contains(name) || !texture->at(name).is_number_integer()) return 1;
          return std::clamp<long long>(texture->at(name).get<long long>(), 1, 1 << 20);
        };
        texels += side("width") * side("height");
        if (texels > options_.max_inline_texels) {
          throw HttpError{413, "scene.faces[" + std::to_string(i) + "].texture",
                          "the scene's textures exceed this server's limit of " +
                              std::to_string(options_.max_inline_texels) + " texels at level 0"};
        }
      }
    }
    try {
      // A generator's textures deferred: the budgets are checked on the scene's sizes before any
      // texel exists, and a render packs each face's texels straight from the generator.
      GeneratorOptions generator_options = deferred;
      generator_options.tint = options.tint;
      Scene parsed = parse_scene_json(inline_scene, {}, generator_options);
      validate_scene(parsed);
      scene = std::make_shared<const Scene>(std::move(parsed));
    } catch (const InputError& e) {
      throw InputError("scene." + e.field(), input_error_message(e));
    }
    options.scene = scene->name;
  }
  return scene;
}

void HttpServer::refuse_over_budget(size_t device_bytes, const std::string& device_field, size_t host_bytes,
                                    const std::string& host_field, const std::string& what) const {
  if (device_bytes > options_.max_request_device_bytes) {
    throw HttpError{413, device_field,
                    what + " needs about " + mebibytes(device_bytes) + " of device memory, over this server's limit of " +
                        mebibytes(options_.max_request_device_bytes) + " per request"};
  }
  if (host_bytes > options_.max_request_host_bytes) {
    throw HttpError{413, host_field,
                    what + " needs about " + mebibytes(host_bytes) + " of host memory, over this server's limit of " +
                        mebibytes(options_.max_request_host_bytes) + " per request"};
  }
}

void HttpServer::refuse_over_budget(const MemoryShares& device_bytes, const MemoryShares& host_bytes, bool builtin_scene,
                                    const std::string& what) const {
  refuse_over_budget(device_bytes.total(), budget_field(device_bytes.field(), builtin_scene), host_bytes.total(),
                     budget_field(host_bytes.field(), builtin_scene), what);
}

void HttpServer::refuse_scene_over_budget(const Scene& scene, const RenderOptions& options, const json& inline_scene,
                                          const std::string& key) const {
  const bool builtin_scene = !key.empty();
  const SceneSizes sizes = scene_sizes(scene);
  const RenderMemory memory = scene_render_memory(sizes, options);
  const MemoryShares device = memory.device_shares(frame_buffers_field(1));  // scene_render_memory: one sample
  MemoryShares host = memory.host_shares();
  // The request holds its own copy of an inline scene or asset on top of the Renderer's (what its
  // texture_source keeps, a deferred .ptx's bytes, is shared by the copies: host_scene counts it).
  host.add("scene", builtin_scene ? 0 : scene_host_bytes(sizes));
  std::string device_field = budget_field(device.field(), builtin_scene), host_field = budget_field(host.field(), builtin_scene);
  // An inline generator's sizing options: the field is the first given, the message names them all.
  std::string sized_by;
  if (const auto given = inline_scene.is_object() ? inline_scene.find("options") : inline_scene.end();
      !inline_scene.is_null() && given != inline_scene.end() && given->is_object()) {
    for (const char* option : {"faces", "texture_scale_log2"})
      if (given->contains(option)) {
        const std::string field = std::string("scene.options.") + option;
        if (sized_by.empty()) {
          if (device_field == "scene") device_field = field;
          if (host_field == "scene") host_field = field;
        }
        sized_by += (sized_by.empty() ? ", sized by " : " and ") + field;
      }
  }
  refuse_over_budget(device.total(), device_field, host.total(), host_field,
                     "the scene (" + std::to_string(sizes.faces.size()) + " faces, " +
                         std::to_string(memory.textures.texels) + " packed texels" + sized_by + ")");
}

void HttpServer::handle_render(const json& request, httplib::Response& res) {
  const Clock::time_point start = Clock::now();
  if (!request.is_object()) throw HttpError{400, "body", "must be a JSON object"};

  // The service's own keys (format, an inline scene); the rest is the render job's request, but
  // the command line's timing keys: one answer is one image.
  json rest = request;
  const ImageFormat format = take_image_format(rest);
  const json inline_scene = take_inline_scene(rest);
  for (const char* key : {"repeat", "crack_orbit"})
    if (rest.contains(key)) throw HttpError{400, key, "is the command line's (seamcl render); a request renders one image"};
  const RenderJob job(rest);
  RenderOptions options = job.options();
  std::string key;
  const std::shared_ptr<const Scene> scene = resolve_scene(inline_scene, options, key);
  const bool inline_request = key.empty();  // an inline scene or an asset: held for this request only
  // Limits after every syntax check (a malformed request is a 400 whatever its size) and before
  // anything is packed or put on the device (an inline scene's own size is bounded by the face
  // and texel limits checked before it is parsed).
  if (static_cast<long long>(options.width) * options.height * options.msaa > options_.max_samples) {
    throw HttpError{413, "size",
                    "width x height x msaa = " + std::to_string(static_cast<long long>(options.width) * options.height * options.msaa) +
                        " exceeds this server's limit of " + std::to_string(options_.max_samples) + " samples"};
  }
  refuse_scene_over_budget(*scene, options, inline_scene, key);
  // The request's own copy of an inline scene or asset is held on top of the Renderer's.
  const JobPlan plan = job.plan(*scene, inline_request ? scene_host_bytes(scene_sizes(*scene)) : 0);
  refuse_over_budget(plan.device, plan.host, !inline_request, plan.what);

  // Wait for a render slot (or 503), render, and give the slot back before encoding.
  const Clock::time_point queued = Clock::now();
  RenderRun run;
  double queue_ms = 0;
  {
    const std::unique_ptr<SlotLease> lease = acquire_slot(start);
    queue_ms = ms_since(queued);
    // Queued for a client that has since hung up: nobody would read the image.
    if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
    Slot& slot = *lease->slot;
    std::unique_ptr<Renderer>& renderer = key.empty() ? slot.scratch : slot.renderers[key];
    try {
      if (!renderer) {
        renderer = std::make_unique<Renderer>(runtime_);
        if (!key.empty()) renderer->load_scene(*scene, options.texels);
      }
      // Tile lists grow with what a frame holds, past any estimate: bounded here.
      renderer->set_device_byte_limit(options_.max_request_device_bytes);
      if (key.empty()) renderer->load_scene(*scene, options.texels);
      JobControl control;
      control.device_byte_limit = options_.max_request_device_bytes;
      run = job.run(runtime_, *renderer, *scene, control);
      // Hold nothing request-sized between requests: the inline scene goes, large frames too.
      if (key.empty()) {
        renderer->release_scene();
      } else if (render_memory(scene_sizes(*scene), options).frame_device_bytes() > options_.keep_frame_bytes) {
        renderer->release_frame_buffers();
      }
    } catch (...) {
      renderer.reset();  // a failed Renderer is not reused: the next request gets a fresh one
      throw;
    }
  }
  const RenderResult& result = run.last;
  const Clock::time_point encode_start = Clock::now();
  std::string image = encode_image(format, result.width, result.height, result.pixels);
  const double encode_ms = ms_since(encode_start);

  res.set_header("X-Seamcl-Render-Ms", std::to_string(result.ms.total));
  res.set_header("X-Seamcl-Stage-Ms", json_text(RenderJob::stage_ms_json(result.ms)));
  res.set_header("X-Seamcl-Queue-Ms", std::to_string(queue_ms));
  res.set_header("X-Seamcl-Encode-Ms", std::to_string(encode_ms));
  res.set_header("X-Seamcl-Server-Ms", std::to_string(ms_since(start)));
  res.set_header("X-Seamcl-Options", json_text(to_json(options)));
  res.set_header("X-Seamcl-Fragments", std::to_string(result.stats.fragments));
  res.set_content(std::move(image), format == ImageFormat::Png ? "image/png" : "image/x-exr");
}


json HttpServer::parse_body(const httplib::Request& req) const {
  const std::string type = req.get_header_value("Content-Type");
  if (!is_json_media_type(type)) {
    throw HttpError{415, "Content-Type", "must be application/json, got '" + echo(type) + "'"};
  }
  // Parse with a depth limit (the library's error messages print values, recursively), and
  // without a key given twice or a NUL byte (either would pass unseen).
  try {
    return parse_json_document(req.body, options_.max_json_depth);
  } catch (const json::exception& e) {
    // The parser's message quotes what it last read: bounded_message cuts it (send_error).
    throw HttpError{400, "body", std::string("not valid JSON: ") + e.what()};
  } catch (const std::invalid_argument& e) {
    throw HttpError{400, "body", e.what()};
  }
}

// POST /v1/compare: the compare job (host/jobs/compare_job.h) on one frame, admitted as one
// request, answered as the JSON of `seamcl compare --json` (without server paths: no cache_path,
// no images).
void HttpServer::handle_compare(const json& request, httplib::Response& res) {
  const Clock::time_point start = Clock::now();
  if (!request.is_object()) throw HttpError{400, "body", "must be a JSON object"};
  json rest = request;
  if (rest.contains("format")) throw HttpError{400, "format", "compare answers JSON; format is for /v1/render"};
  const json inline_scene = take_inline_scene(rest);
  // No size: the render default would be over this server's compare limit, so compare's own
  // default fits it. The answer says which size was used and where it came from.
  const bool size_given = rest.contains("size");
  if (!size_given) rest["size"] = default_compare_size(options_.max_compare_pixels);
  const bool explicit_reference_msaa = rest.contains("reference_msaa");
  CompareJob job(rest);  // every syntax check, in seamcl compare's order
  const std::vector<MethodEntry>& entries = job.entries();
  const size_t methods = job.methods().size();
  if (entries.size() > static_cast<size_t>(options_.max_compare_entries)) {
    // Named after the longer list: the one to shorten.
    throw HttpError{400, job.rates().size() > methods ? "msaa" : "methods",
                    std::to_string(methods) + " methods x " + std::to_string(job.rates().size()) +
                        " msaa rates = " + std::to_string(entries.size()) +
                        " renders exceeds this server's limit of " + std::to_string(options_.max_compare_entries)};
  }
  if (job.repeat() > options_.max_compare_repeat)
    throw InputError("repeat", "must be an integer in 1.." + std::to_string(options_.max_compare_repeat) + ", got " +
                                   std::to_string(job.repeat()));
  ReferenceSettings& reference_settings = job.reference_settings();
  reference_settings.cache_dir = options_.cache_dir;
  reference_settings.cache_max_bytes = options_.cache_max_bytes;
  RenderOptions frame = job.frame();
  std::string key;
  const std::shared_ptr<const Scene> scene = resolve_scene(inline_scene, frame, key);
  // Limits after every syntax check: a malformed request is a 400 whatever its size.
  check_reference_limits(frame, reference_settings, explicit_reference_msaa);
  const long long pixels = static_cast<long long>(frame.width) * frame.height;
  for (const MethodEntry& entry : entries) {
    if (pixels * entry.options.msaa > options_.max_samples) {
      throw HttpError{413, "size",
                      "width x height x msaa = " + std::to_string(pixels * entry.options.msaa) +
                          " exceeds this server's limit of " + std::to_string(options_.max_samples) + " samples"};
    }
  }
  refuse_scene_over_budget(*scene, frame, inline_scene, key);
  const JobPlan plan = job.plan(*scene);
  refuse_over_budget(plan.device, plan.host, !key.empty(), plan.what);
  // Work for a client that has gone, or past the deadline, stops at the next entry or repeat.
  const Clock::time_point deadline =
      options_.deadline_ms > 0 ? start + std::chrono::milliseconds(options_.deadline_ms) : Clock::time_point::max();
  JobControl control;
  control.should_stop = [deadline] { return GuardedHttpServer::client_gone() || Clock::now() > deadline; };
  control.device_byte_limit = options_.max_request_device_bytes;

  // One admitted request for the whole compare, with a Renderer of its own (the job's): the 8x
  // reference's buffers are freed with it, and the slot's warm Renderers keep their scenes.
  const Clock::time_point queued = Clock::now();
  double queue_ms = 0;
  CompareRun run;
  {
    const std::unique_ptr<SlotLease> lease = acquire_slot(start);
    queue_ms = ms_since(queued);
    if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
    // Two compares of the same reference at once render it once: the second reads the first's.
    const ReferenceLock lock_reference = [this](const std::string& cache_key) {
      return std::unique_lock<std::mutex>(reference_locks_[std::hash<std::string>{}(cache_key) % reference_locks_.size()]);
    };
    try {
      run = job.run(runtime_, *scene, control, lock_reference);
    } catch (const Cancelled&) {
      if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
      throw HttpError{503, "deadline", "the compare ran past this server's deadline of " + std::to_string(options_.deadline_ms) + " ms", 1};
    }
  }
  json out = job.result_json(run, *scene, runtime_.device_description(), false);
  out["size_from"] = size_given ? "request" : "default";
  out["queue_ms"] = queue_ms;
  out["server_ms"] = ms_since(start);
  res.set_content(json_text(out), "application/json");
}

ReferenceSettings HttpServer::take_reference_settings(json& rest, bool& explicit_msaa) const {
  ReferenceSettings settings;
  settings.cache_dir = options_.cache_dir;
  settings.cache_max_bytes = options_.cache_max_bytes;
  if (rest.contains("reference_method")) {
    const json& value = rest.at("reference_method");
    if (!value.is_string()) throw InputError("reference_method", "must be a method name, got " + echo(json_text(value)));
    settings.method = value.get<std::string>();
    if (!parse_method(settings.method)) {
      throw InputError("reference_method", "unknown method '" + echo(settings.method) + "'");
    }
    rest.erase("reference_method");
  }
  explicit_msaa = false;
  if (rest.contains("reference_msaa")) {
    const json& value = rest.at("reference_msaa");
    if (!value.is_number_integer() || value.get<long long>() < 1 || value.get<long long>() > 16) {
      throw InputError("reference_msaa", "must be 1, 2, 4, 8 or 16, got " + echo(json_text(value)));
    }
    settings.msaa = value.get<int>();
    explicit_msaa = true;
    rest.erase("reference_msaa");
  }
  return settings;
}

void HttpServer::check_reference_limits(const RenderOptions& frame, const ReferenceSettings& settings, bool explicit_msaa) const {
  const long long pixels = static_cast<long long>(frame.width) * frame.height;
  if (pixels > options_.max_compare_pixels) {
    throw HttpError{413, "size",
                    std::to_string(frame.width) + "x" + std::to_string(frame.height) + " = " + std::to_string(pixels) +
                        " pixels exceeds this server's compare limit of " + std::to_string(options_.max_compare_pixels) +
                        " (the reference renders at " + std::to_string(kReferenceScale) + "x width and height)"};
  }
  const RenderOptions high = reference_render_options(frame, settings);
  const long long reference_samples = static_cast<long long>(high.width) * high.height * high.msaa;
  if (reference_samples > options_.max_reference_samples) {
    throw HttpError{413, explicit_msaa ? "reference_msaa" : "size",
                    "the reference renders " + std::to_string(high.width) + "x" + std::to_string(high.height) + " x " +
                        std::to_string(high.msaa) + " samples = " + std::to_string(reference_samples) +
                        ", over this server's limit of " + std::to_string(options_.max_reference_samples)};
  }
}

// POST /v1/reference: the image compare measures against (the 8x render, downsampled; from the
// cache when it is there), for viewers that show a method's error against it.
void HttpServer::handle_reference(const json& request, httplib::Response& res) {
  const Clock::time_point start = Clock::now();
  if (!request.is_object()) throw HttpError{400, "body", "must be a JSON object"};
  json rest = request;
  for (const char* key : {"method", "methods", "msaa", "repeat"}) {
    if (rest.contains(key)) {
      throw HttpError{400, key, std::string("the reference is one image of the frame; ") + key + " is for /v1/render or /v1/compare"};
    }
  }
  const ImageFormat format = take_image_format(rest);
  bool explicit_reference_msaa = false;
  ReferenceSettings settings = take_reference_settings(rest, explicit_reference_msaa);
  if (rest.contains("reference")) {
    const json& value = rest.at("reference");
    const std::optional<ReferenceKind> kind =
        value.is_string() ? parse_reference_kind(value.get<std::string>()) : std::nullopt;
    if (kind == ReferenceKind::Analytic || kind == ReferenceKind::Seamless) {
      throw InputError("reference", "the " + to_string(*kind) + " reference is not a downsampled render: /v1/compare measures against it");
    }
    if (!kind) throw InputError("reference", "must be paper or box, got " + echo(json_text(value)));
    settings.kind = *kind;
    rest.erase("reference");
  }
  const json inline_scene = take_inline_scene(rest);
  RenderOptions frame = parse_render_options(rest);
  std::string key;
  const std::shared_ptr<const Scene> scene = resolve_scene(inline_scene, frame, key);
  const Camera camera = frame.frame ? orbit_camera(*scene, *frame.frame, frame.frames) : scene->camera;
  check_reference_limits(frame, settings, explicit_reference_msaa);
  refuse_scene_over_budget(*scene, frame, inline_scene, key);
  const CompareMemory memory = compare_memory(scene_sizes(*scene), frame, {}, settings);
  refuse_over_budget(memory.device_shares, memory.host_shares, !key.empty(), "this reference");

  const Clock::time_point queued = Clock::now();
  double queue_ms = 0;
  ReferenceImage reference;
  {
    const std::unique_ptr<SlotLease> lease = acquire_slot(start);
    queue_ms = ms_since(queued);
    if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
    Renderer renderer(runtime_);
    renderer.set_device_byte_limit(options_.max_request_device_bytes);
    renderer.load_scene(*scene, frame.texels);
    settings.scene_hash = scene_content_hash(*scene);  // once for the lock's key and the cache's
    const std::string cache_key = reference_cache_key(*scene, camera, frame, settings);
    std::lock_guard lock(reference_locks_[std::hash<std::string>{}(cache_key) % reference_locks_.size()]);
    reference = reference_image(renderer, camera, frame, settings);
  }
  std::string image = encode_image(format, reference.width, reference.height, reference.pixels);
  res.set_header("X-Seamcl-Reference-Method", reference.method);
  res.set_header("X-Seamcl-Reference", reference_json(reference, false).dump());
  res.set_header("X-Seamcl-Queue-Ms", std::to_string(queue_ms));
  res.set_header("X-Seamcl-Server-Ms", std::to_string(ms_since(start)));
  res.set_content(std::move(image), format == ImageFormat::Png ? "image/png" : "image/x-exr");
}

void HttpServer::install_routes() {
  GuardedHttpServer& http = *http_;
  // Connections, threads, timeouts and byte budgets are server/connection.h's; bodies sent with
  // a Content-Length over the limit are refused by httplib (413).
  http.set_payload_max_length(options_.max_body_bytes);

  // Every handler runs inside this: refusals become {"error", "field"} with their status. The
  // field starts the message too, echoed like any client value (it can be a client's key).
  auto guarded = [this](auto handler) {
    return [this, handler](const httplib::Request& req, httplib::Response& res) {
      try {
        handler(req, res);
      } catch (const HttpError& e) {
        if (e.retry_after_s > 0) res.set_header("Retry-After", std::to_string(e.retry_after_s));
        send_error(res, e.status, e.field, echo(e.field) + ": " + e.message);
      } catch (const OverBudget& e) {
        send_error(res, 413, e.field(), echo(e.field()) + ": " + input_error_message(e));
      } catch (const InputError& e) {
        send_error(res, 400, e.field(), echo(e.field()) + ": " + input_error_message(e));
      } catch (const std::exception& e) {
        log_line(std::string("error: ") + describe_cl_exception(e));
        send_error(res, 500, "server", "render failed: " + describe_cl_exception(e));
      }
    };
  };

  // Per-request start time, for the log line (the logger runs on the same thread, after).
  static thread_local Clock::time_point request_start{};
  http.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
    request_start = Clock::now();
    const auto found = known_paths().find(req.path);
    if (found != known_paths().end() &&
        std::find(found->second.begin(), found->second.end(), req.method) == found->second.end()) {
      // A body is read first where cpp-httplib reads bodies (POST, PUT, DELETE, PATCH): the
      // not_routed handlers below answer after it has. It never reads one of GET, HEAD, OPTIONS,
      // TRACE or CONNECT, so there the client is told to close the connection instead.
      static const std::set<std::string> body_read = {"POST", "PUT", "DELETE", "PATCH"};
      if (carries_body(req) && body_read.contains(req.method)) return httplib::Server::HandlerResponse::Unhandled;
      if (carries_body(req)) res.set_header("Connection", "close");
      send_method_not_allowed(res, req.method, req.path, found->second);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });
  http.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    const double ms = request_start == Clock::time_point{} ? 0.0 : ms_since(request_start);
    request_start = Clock::time_point{};
    served_.fetch_add(1);
    char line[512];
    std::snprintf(line, sizeof line, "%s %s %d %zu B %.1f ms", req.method.c_str(), echo(req.path, 200).c_str(),
                  res.status, res.body.size(), ms);
    log_line(line);
  });
  // Statuses httplib sets itself (404, 413, 400 for a malformed request line) get the JSON body too.
  http.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request& req, httplib::Response& res) {
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    const auto route = known_paths().find(req.path);
    const bool routes_post = route != known_paths().end() &&
                             std::find(route->second.begin(), route->second.end(), "POST") != route->second.end();
    if (GuardedHttpServer::request_over_byte_limit()) {
      send_error(res, 413, "body", "the request exceeds this server's limit of bytes read per request");
    } else if (res.status == 404) {
      send_error(res, 404, "path", "no such endpoint: " + req.method + " " + echo(req.path));
    } else if (res.status == 400 && req.method == "POST" && routes_post && req.is_multipart_form_data()) {
      // cpp-httplib parses multipart bodies itself and answers 400 when that fails: the body is
      // of a media type these routes do not take, however well formed.
      send_error(res, 415, "Content-Type",
                 "Content-Type: must be application/json, got '" + echo(req.get_header_value("Content-Type")) + "'");
    } else if (res.status == 413) {
      send_error(res, 413, "body", "the request body exceeds this server's limit");
    } else {
      send_error(res, res.status, "request", "the request could not be handled (HTTP " + std::to_string(res.status) + ")");
    }
    return httplib::Server::HandlerResponse::Handled;
  }));
  http.set_exception_handler([](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
    send_error(res, 500, "server", "internal error");
  });

  http.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(viewer_html()), "text/html; charset=utf-8");
  });
  http.Get("/openapi.json", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(std::string(openapi_json()), "application/json");
  });
  http.Get("/health", guarded([this](const httplib::Request&, httplib::Response& res) {
             res.set_content(json_text(health_json()), "application/json");
           }));
  // Readiness for a load balancer's health check: 200 once every slot is warm, else 503 (the
  // balancer then sends nothing here); /health stays 200 from the moment the port listens.
  http.Get("/ready", guarded([this](const httplib::Request&, httplib::Response& res) {
             const json health = health_json();
             const bool is_ready = health.at("status") == "ready";
             res.status = is_ready ? 200 : 503;
             if (!is_ready) res.set_header("Retry-After", "1");
             res.set_content(json_text({{"ready", is_ready},
                                        {"status", health.at("status")},
                                        {"warming", health.at("warming")},
                                        {"uptime_s", health.at("uptime_s")}}),
                             "application/json");
           }));
  http.Get("/v1/scenes", guarded([this](const httplib::Request&, httplib::Response& res) {
             res.set_content(json_text(scenes_json()), "application/json");
           }));
  http.Get("/v1/assets", guarded([this](const httplib::Request&, httplib::Response& res) {
             res.set_content(json_text(assets_json()), "application/json");
           }));
  http.Get("/v1/methods", guarded([this](const httplib::Request&, httplib::Response& res) {
             res.set_content(json_text(methods_json()), "application/json");
           }));
  http.Get("/v1/render", guarded([this](const httplib::Request& req, httplib::Response& res) {
             handle_render(query_to_json(req.params), res);
           }));
  http.Post("/v1/render", guarded([this](const httplib::Request& req, httplib::Response& res) {
              handle_render(parse_body(req), res);
            }));
  http.Post("/v1/reference", guarded([this](const httplib::Request& req, httplib::Response& res) {
              handle_reference(parse_body(req), res);
            }));
  http.Post("/v1/compare", guarded([this](const httplib::Request& req, httplib::Response& res) {
              handle_compare(parse_body(req), res);
            }));
  // Last, for every other path and method cpp-httplib routes: 405 on a known path (reached only
  // with a body, which cpp-httplib has read by now), 404 elsewhere.
  const auto not_routed = [](const httplib::Request& req, httplib::Response& res) {
    const auto found = known_paths().find(req.path);
    if (found != known_paths().end()) {
      send_method_not_allowed(res, req.method, req.path, found->second);
    } else {
      send_error(res, 404, "path", "no such endpoint: " + req.method + " " + echo(req.path));
    }
  };
  http.Get(".*", not_routed);
  http.Post(".*", not_routed);
  http.Put(".*", not_routed);
  http.Delete(".*", not_routed);
  http.Patch(".*", not_routed);
  http.Options(".*", not_routed);
}

}  // namespace seamcl::server
