// The HTTP service: a translation layer between HTTP requests and the library (the shared option
// parser, the scene loaders, Renderer, encode_image). It computes nothing itself.
//
// Device sharing: the server owns no OpenCL state of its own beyond one ClRuntime (context,
// queue, compiled programs), which every render shares; contexts, queues and programs are
// thread-safe. Kernel arguments are not (clSetKernelArg on one kernel object from two threads
// races), so each render slot owns its own Renderer objects (kernel objects and buffers) and a
// slot serves one request at a time. There are --threads slots.
//
// Admission: connections are served by server/connection.h (a thread each, bounded, with read
// deadlines); renders are counted here: at most `threads` render at once and at most `queue` wait
// for a slot; any render beyond that is answered 503 with Retry-After at once, and /health and
// refusals never wait behind renders.
// A compare (POST /v1/compare) is one admitted request like a render: it holds one slot for its
// whole run (seam mask, 8x reference or cache hit, every method x rate).
#pragma once
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/assets/asset_directory.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/eval/reference.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/options/render_options.h>

namespace httplib {
class Server;
struct Request;
struct Response;
}  // namespace httplib

namespace seamcl {
class Renderer;
struct Scene;
}  // namespace seamcl

namespace seamcl::server {

class GuardedHttpServer;

struct ServerOptions {
  std::string host = "127.0.0.1";  // loopback unless asked otherwise
  int port = 8080;                 // 0: any free port (see HttpServer::port)
  int threads = 2;                 // render slots (one Renderer set each)
  int queue = 8;                   // renders allowed to wait for a slot; more get 503
  size_t max_body_bytes = size_t{1} << 20;              // larger bodies: 413
  long long max_samples = 2048LL * 2048 * 4;            // width * height * msaa per request: 413 "size"
  size_t max_inline_faces = 1024;                       // inline scene faces: 413 "scene.faces"
  long long max_inline_texels = 1LL << 21;              // inline scene texels at level 0: 413
  int max_json_depth = 32;                              // deeper request JSON: 400 "body"
  // POST /v1/compare renders an 8x reference (64x the pixels), so its frames are much smaller.
  long long max_compare_pixels = 256LL * 256;           // width * height per compare: 413 "size"
  int max_compare_entries = 16;                         // methods x msaa rates: 400 "methods"
  int max_compare_repeat = 10;                          // timed renders per entry: 400 "repeat"
  long long max_reference_samples = 2048LL * 2048 * 4;  // 8W * 8H * reference_msaa: 413
  // Reference cache of POST /v1/compare. Empty: $SEAMCL_CACHE_DIR, else <temp>/seamcl-serve-cache.
  std::string cache_dir;
  std::uintmax_t cache_max_bytes = std::uintmax_t{256} << 20;  // least recently used entries go; 0: no bound
  // Memory one request may need, estimated before anything is allocated (render_memory.h,
  // compare_memory.h): textures in the chosen format with guard bands, frame buffers at the
  // sample count, the 8x reference. Over either: 413 naming the field that drives it.
  size_t max_request_device_bytes = size_t{1} << 30;
  size_t max_request_host_bytes = size_t{1} << 30;
  // A slot's Renderer keeps its frame buffers between requests up to this size; larger ones are
  // freed after the request, so one big request does not stay held.
  size_t keep_frame_bytes = size_t{64} << 20;
  bool warm_all_methods = true;    // after start, build every method x filter (rgba8) in the background
  // Connections (server/connection.h): open at once, read deadline of one request, keep-alive wait.
  int max_connections = 256;
  int request_read_timeout_ms = 10'000;
  int idle_timeout_ms = 2'000;
  // A request that has not started rendering this long after it arrived is answered 503
  // ("deadline") instead; 0: no deadline. Long work also stops when the client has gone.
  int deadline_ms = 60'000;
  std::function<void(const std::string&)> log;          // one line per request; empty: stderr
  // Assets (`--assets DIR`): scenes named relative to this directory and nothing else on disk;
  // empty: built-in and inline scenes only. Loaded assets are cached within these bounds.
  std::string assets_dir;
  AssetCacheLimits asset_cache;
};

// The built-in assets, embedded at build time (server/embed_assets.cmake).
std::string_view viewer_html();
// GET /openapi.json: server/openapi.json with every option's schema filled in from the jobs'
// option tables (server/api_documents.cpp).
std::string_view openapi_json();

class HttpServer {
 public:
  // Generates the built-in scenes; the kernels are built and warmed after bind(), in the
  // background, while the server already answers (/health says "starting", renders wait).
  HttpServer(ClRuntime& runtime, ServerOptions options);
  ~HttpServer();
  HttpServer(const HttpServer&) = delete;
  HttpServer& operator=(const HttpServer&) = delete;

  // Binds host:port (port 0: an ephemeral port) and starts warming; returns the port, or -1 when
  // the address cannot be bound (a port in use is never shared).
  int bind();
  int port() const { return port_; }
  // Serves until stop(); returns after every in-flight request has been answered.
  bool listen_after_bind();
  // Safe from any thread (e.g. a signal-waiting thread).
  void stop();
  bool is_running() const;
  // Every slot has the default scene and variant warm (renders no longer wait for start-up), or
  // failed to warm while at least one did.
  bool ready() const { return ready_slots_.load() > 0 && ready_slots_.load() + failed_slots_.load() == options_.threads; }
  // Blocks until ready() or the warm-up failed; false on failure or after timeout.
  bool wait_ready(std::chrono::milliseconds timeout);

  long long requests_served() const { return served_.load(); }

 private:
  struct Slot;
  struct SlotLease;
  struct HttpError;

  void install_routes();
  void handle_render(const nlohmann::json& request, httplib::Response& res);
  void handle_compare(const nlohmann::json& request, httplib::Response& res);
  void handle_reference(const nlohmann::json& request, httplib::Response& res);
  // reference_method and reference_msaa taken out of a compare or reference request.
  ReferenceSettings take_reference_settings(nlohmann::json& rest, bool& explicit_msaa) const;
  // The frame's pixels and the 8x reference's samples within this server's limits (413).
  void check_reference_limits(const RenderOptions& frame, const ReferenceSettings& settings, bool explicit_msaa) const;
  nlohmann::json parse_body(const httplib::Request& req) const;
  // A built-in scene by options.scene (and tint), or `inline_scene` when it is not null (limits
  // checked, parsed, validated; options.scene becomes its name). `key` is the slot Renderer's key,
  // empty for an inline scene.
  std::shared_ptr<const Scene> resolve_scene(const nlohmann::json& inline_scene, RenderOptions& options,
                                             std::string& key) const;
  // 413 for a figure over its per-request limit, naming that figure's field.
  void refuse_over_budget(size_t device_bytes, const std::string& device_field, size_t host_bytes,
                          const std::string& host_field, const std::string& what) const;
  // For figures split by what drives them (a render's, a compare's): the limit exceeded names the
  // largest share of its own figure, as budget_field translates it for the client ("texels" for a
  // built-in scene's share).
  void refuse_over_budget(const MemoryShares& device_bytes, const MemoryShares& host_bytes, bool builtin_scene,
                          const std::string& what) const;
  // 413 when the scene alone (scene_render_memory: at 1x1, whatever the size asked) is over the
  // budgets, naming the largest share of the figure over its limit as the above does; for an
  // inline generator scene the scene's share names its first sizing option given
  // (scene.options.faces, else scene.options.texture_scale_log2).
  void refuse_scene_over_budget(const Scene& scene, const RenderOptions& options, const nlohmann::json& inline_scene,
                                const std::string& key) const;
  nlohmann::json scenes_json() const;
  nlohmann::json assets_json() const;
  // An asset of the asset directory by options.scene and options.texture (400 without one).
  std::shared_ptr<const Scene> asset_scene(const RenderOptions& options) const;
  nlohmann::json make_methods_json() const;
  // A built-in scene ("paper", tinted or not), generated on first use; null for an unknown name.
  std::shared_ptr<const Scene> builtin_scene(const std::string& name, bool tint) const;
  nlohmann::json methods_json() const;
  nlohmann::json health_json() const;
  std::unique_ptr<SlotLease> acquire_slot(std::chrono::steady_clock::time_point arrived);
  void warm_up();  // the start-up thread
  void release_slot(Slot* slot);
  void log_line(const std::string& line) const;

  ClRuntime& runtime_;
  ServerOptions options_;
  std::unique_ptr<GuardedHttpServer> http_;
  std::unique_ptr<AssetDirectory> assets_;  // null without --assets
  int port_ = -1;
  std::chrono::steady_clock::time_point started_;

  // Built-in scenes, generated on first use: key "<name>" and "<name>+tint".
  mutable std::mutex scenes_mutex_;
  mutable std::map<std::string, std::shared_ptr<const Scene>> scenes_;
  mutable std::once_flag methods_once_;
  mutable nlohmann::json methods_cache_;

  std::vector<std::unique_ptr<Slot>> slots_;
  std::vector<Slot*> free_slots_;
  mutable std::mutex slots_mutex_;
  std::condition_variable slot_freed_;
  std::atomic<int> admitted_{0};  // rendering + waiting
  std::atomic<long long> served_{0};
  // Two compares of the same reference at once would both render it and write the same cache
  // file: one lock per hash stripe of the cache key, held while the reference is read or made.
  std::array<std::mutex, 16> reference_locks_;

  // Start-up: slots become free as they are warmed; then every method x filter, if asked.
  std::thread warm_thread_;
  std::atomic<bool> stopping_{false};
  std::atomic<int> ready_slots_{0};
  std::atomic<int> failed_slots_{0};  // slots whose warm-up failed (the rest serve)
  std::atomic<int> warmed_variants_{0};
  int total_variants_ = 0;
  std::string warm_error_;  // under slots_mutex_; not empty: the warm-up failed
};

}  // namespace seamcl::server
