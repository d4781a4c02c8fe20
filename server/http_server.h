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
// deadlines); renders are counted by server/render_slots.h: at most `threads` render at once and
// at most `queue` wait for a slot; any render beyond that is answered 503 with Retry-After at
// once, and /health and refusals never wait behind renders.
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

namespace seamcl::server {

class GuardedHttpServer;
class JobHandlers;
class MemoryBound;
class RenderSlots;
class SceneResolver;

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
  // The process-wide memory bound (server/memory_bound.h): admitted requests' plans plus the kept
  // Renderers; 0: half the physical memory.
  size_t memory_bound_bytes = 0;
  bool warm_all_methods = true;    // after start, build every method x filter (rgba8) in the background
  // Connections (server/connection.h): open at once, read deadline of one request, keep-alive wait.
  int max_connections = 256;
  int max_connections_per_client = 64;  // open at once from one address; 0: no cap (behind a proxy)
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
  // Every slot has the default scene and variant warm and, with warm_all_methods, every method x
  // filter is built (no render waits for a build), or the warm-up failed while at least one slot
  // was warm.
  bool ready() const;
  // Blocks until ready() or the warm-up failed; false on failure or after timeout.
  bool wait_ready(std::chrono::milliseconds timeout);

  long long requests_served() const { return served_.load(); }
  int open_connections() const;

 private:
  void install_routes();
  nlohmann::json methods_json() const;
  nlohmann::json health_json() const;
  void warm_up();  // the start-up thread
  void log_line(const std::string& line) const;

  ClRuntime& runtime_;
  ServerOptions options_;
  std::unique_ptr<GuardedHttpServer> http_;
  std::unique_ptr<SceneResolver> scenes_;
  std::unique_ptr<RenderSlots> slots_;
  std::unique_ptr<MemoryBound> memory_;
  std::unique_ptr<JobHandlers> jobs_;
  int port_ = -1;
  std::chrono::steady_clock::time_point started_;

  mutable std::once_flag methods_once_;
  mutable nlohmann::json methods_cache_;
  std::atomic<long long> served_{0};

  // Start-up: slots become free as they are warmed; then every method x filter, if asked.
  std::thread warm_thread_;
  std::atomic<bool> stopping_{false};
  std::atomic<int> warmed_variants_{0};
  std::atomic<bool> variants_done_{false};  // the background variants are built (or their build failed)
  int total_variants_ = 0;
};

}  // namespace seamcl::server
