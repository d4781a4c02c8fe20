// seamcl serve: the HTTP render service (server/http_server.h). Generates the built-in scenes,
// listens at once and warms the kernels in the background; SIGINT/SIGTERM stop it after the
// requests in flight have been answered.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdint>
#include <ctime>
#include <optional>
#include <string>
#include <thread>

#include <pthread.h>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include "commands.h"
#include "http_server.h"

namespace seamcl::cli {

namespace {

struct ServeArgs {
  std::string host = "127.0.0.1";
  int port = 8080;
  int threads = 2;
  int queue = 8;
  bool quick_start = false;
  int max_connections = 256;
  int max_connections_per_client = 64;
  double read_timeout_s = 10;
  double deadline_s = 60;
  std::optional<std::string> cache_dir;  // empty is refused, not taken for the default
  long long cache_max_mib = 256;
  std::optional<std::string> assets_dir;  // empty is refused, not taken for none
  long long assets_cache_mib = 512;
  long long request_memory_mib = 1024;
  long long memory_bound_mib = 0;  // 0: half the physical memory
  bool print_openapi = false;
};

int run_serve(const ServeArgs& args, const GlobalOptions& global) {
  if (args.print_openapi) {
    // The document alone, before any device is opened: docs/http-api.md is generated from it.
    std::fwrite(server::openapi_json().data(), 1, server::openapi_json().size(), stdout);
    std::fputc('\n', stdout);
    return 0;
  }
  // An empty address would listen wherever the resolver puts "" (loopback here), not where meant.
  if (args.host.empty()) throw InputError("host", "must not be empty (leave out --host for 127.0.0.1)");
  const std::string cache_dir =
      given_value(args.cache_dir, "cache-dir", "leave out --cache-dir for $SEAMCL_CACHE_DIR, else <temp>/seamcl-serve-cache");
  const std::string assets_dir = given_value(args.assets_dir, "assets", "leave out --assets to serve no files");
  if (args.port < 0 || args.port > 65535) throw InputError("port", "must be in 0..65535");
  if (args.threads < 1 || args.threads > 64) throw InputError("threads", "must be in 1..64");
  if (args.queue < 0 || args.queue > 1024) throw InputError("queue", "must be in 0..1024");
  if (args.max_connections < 1 || args.max_connections > 4096) throw InputError("max-connections", "must be in 1..4096");
  if (args.max_connections_per_client < 0 || args.max_connections_per_client > 4096)
    throw InputError("max-connections-per-client", "must be in 0..4096 (0: no cap)");
  if (!(args.read_timeout_s >= 0.1 && args.read_timeout_s <= 600)) throw InputError("read-timeout", "must be in 0.1..600 seconds");
  if (!(args.deadline_s >= 0 && args.deadline_s <= 3600)) throw InputError("deadline", "must be in 0..3600 seconds (0: none)");
  // Bounded so that the byte counts made from them (MiB << 20) cannot overflow.
  if (args.cache_max_mib < 0 || args.cache_max_mib > (1LL << 40))
    throw InputError("cache-max-mib", "must be in 0..2^40 (0: no bound)");
  if (args.assets_cache_mib < 0 || args.assets_cache_mib > (1LL << 24))
    throw InputError("assets-cache-mib", "must be in 0..16777216 (0: cache nothing)");
  if (args.memory_bound_mib < 0 || args.memory_bound_mib > (1LL << 24)) throw InputError("memory-bound-mib", "must be in 0..16777216 (0: half the physical memory)");
  if (args.request_memory_mib < 1 || args.request_memory_mib > (1LL << 20)) {
    throw InputError("request-memory-mib", "must be in 1..1048576");
  }

  // Block the stop signals in every thread (the pool threads inherit the mask); one thread
  // waits for them and stops the server.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);  // a client that hangs up must not end the process

  const auto start = std::chrono::steady_clock::now();
  ClRuntime& runtime = cli::command_runtime(global.device);
  server::ServerOptions options;
  options.host = args.host;
  options.port = args.port;
  options.threads = args.threads;
  options.queue = args.queue;
  options.warm_all_methods = !args.quick_start;
  options.max_connections = args.max_connections;
  options.max_connections_per_client = args.max_connections_per_client;
  options.request_read_timeout_ms = static_cast<int>(args.read_timeout_s * 1000);
  options.deadline_ms = static_cast<int>(args.deadline_s * 1000);
  options.cache_dir = cache_dir;
  options.cache_max_bytes = static_cast<std::uintmax_t>(args.cache_max_mib) << 20;
  options.assets_dir = assets_dir;
  options.asset_cache.max_bytes = static_cast<size_t>(args.assets_cache_mib) << 20;
  options.max_request_device_bytes = static_cast<size_t>(args.request_memory_mib) << 20;
  options.max_request_host_bytes = static_cast<size_t>(args.request_memory_mib) << 20;
  options.memory_bound_bytes = static_cast<size_t>(args.memory_bound_mib) << 20;
  server::HttpServer http(runtime, options);
  if (http.bind() < 0) {
    std::fprintf(stderr, "seamcl: cannot listen on %s:%d: the port is in use or the address is not this machine's\n",
                 args.host.c_str(), args.port);
    return 1;
  }
  const double listen_ms = ms_since(start);
  std::fprintf(stderr,
               "seamcl serve: http://%s:%d/ on %s, %d threads, queue %d; listening after %.0f ms, warming the kernels "
               "(GET /health says \"ready\" when renders no longer wait)\n",
               args.host.c_str(), http.port(), runtime.device_description().c_str(), args.threads, args.queue, listen_ms);

  std::atomic<bool> done{false};
  std::thread signal_waiter([&] {
    const timespec tick{0, 200'000'000};
    while (!done.load()) {
      const int signal = sigtimedwait(&stop_signals, nullptr, &tick);
      if (signal == SIGINT || signal == SIGTERM) {
        std::fprintf(stderr, "seamcl serve: %s, finishing the requests in flight\n", signal == SIGINT ? "SIGINT" : "SIGTERM");
        http.stop();
        break;
      }
    }
  });
  const bool ok = http.listen_after_bind();
  done.store(true);
  signal_waiter.join();
  std::fprintf(stderr, "seamcl serve: stopped after %lld requests\n", http.requests_served());
  return ok ? 0 : 1;
}

}  // namespace

Command add_serve_command(CLI::App& app) {
  auto args = std::make_shared<ServeArgs>();
  CLI::App* serve = app.add_subcommand("serve", "Serve renders over HTTP (GET / for the viewer, /openapi.json for the API)");
  serve->add_option("--host", args->host, "Address to listen on [127.0.0.1]; anything else exposes the service");
  serve->add_option("--port", args->port, "Port [8080]; 0 picks a free one");
  serve->add_option("--threads", args->threads, "Renders at once, each with its own Renderer [2]");
  serve->add_option("--queue", args->queue, "Renders that may wait for a thread; more get 503 [8]");
  serve->add_flag("--quick-start", args->quick_start, "Warm only the default method, not every method x filter");
  serve->add_option("--max-connections", args->max_connections, "Connections served at once; more get 503 and are closed [256]");
  serve->add_option("--max-connections-per-client", args->max_connections_per_client,
                    "Connections one client address may hold at once; more get 503 and are closed; 0: no cap (behind a proxy) [64]");
  serve->add_option("--read-timeout", args->read_timeout_s,
                    "Seconds a request's line, headers and body may take to arrive, however they trickle [10]");
  serve->add_option("--cache-dir", args->cache_dir,
                    "Reference cache of POST /v1/compare [$SEAMCL_CACHE_DIR, else <temp>/seamcl-serve-cache]");
  serve->add_option("--cache-max-mib", args->cache_max_mib, "Reference cache bound, least recently used go first; 0: none [256]");
  serve->add_option("--assets", args->assets_dir,
                    "Directory of assets (.obj, .ptx, scene .json) that requests may name, relative to it; nothing else on disk is reachable [none]");
  serve->add_option("--assets-cache-mib", args->assets_cache_mib,
                    "Bound of the loaded assets kept between requests (least recently used go first); 0: keep none [512]");
  serve->add_option("--request-memory-mib", args->request_memory_mib,
                    "Device and host memory one request may need, estimated before anything is allocated; more: 413 [1024]");
  serve->add_option("--memory-bound-mib", args->memory_bound_mib,
                    "Memory the whole process may plan for: admitted requests plus the kept scenes (least recently used "
                    "go first); a request that does not fit gets 503; 0: half the physical memory [0]");
  serve->add_option("--deadline", args->deadline_s,
                    "Seconds a request may wait for a render slot before it is answered 503; 0: no limit [60]");
  serve->add_flag("--openapi", args->print_openapi,
                  "Print the OpenAPI document the service answers at GET /openapi.json and exit (no device is opened)");
  return Command{serve, [args](const GlobalOptions& global) { return run_serve(*args, global); }};
}

}  // namespace seamcl::cli
