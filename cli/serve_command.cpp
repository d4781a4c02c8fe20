// seamcl serve: the HTTP render service (server/http_server.h). Builds and warms the kernels and
// generates the built-in scenes before it listens; SIGINT/SIGTERM stop it after the requests in
// flight have been answered.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <thread>

#include <pthread.h>

#include <seamcl/cl/cl_runtime.h>
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
};

int run_serve(const ServeArgs& args, const GlobalOptions& global) {
  if (args.port < 0 || args.port > 65535) throw InputError("port", "must be in 0..65535");
  if (args.threads < 1 || args.threads > 64) throw InputError("threads", "must be in 1..64");
  if (args.queue < 0 || args.queue > 1024) throw InputError("queue", "must be in 0..1024");

  // Block the stop signals in every thread (the pool threads inherit the mask); one thread
  // waits for them and stops the server.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);  // a client that hangs up must not end the process

  const auto start = std::chrono::steady_clock::now();
  ClRuntime runtime(global.device);
  server::ServerOptions options;
  options.host = args.host;
  options.port = args.port;
  options.threads = args.threads;
  options.queue = args.queue;
  options.warm_all_methods = !args.quick_start;
  server::HttpServer http(runtime, options);
  if (http.bind() < 0) {
    std::fprintf(stderr, "seamcl: cannot listen on %s:%d\n", args.host.c_str(), args.port);
    return 1;
  }
  const double ready_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(stderr, "seamcl serve: http://%s:%d/ on %s, %d threads, queue %d (ready in %.0f ms)\n",
               args.host.c_str(), http.port(), runtime.device_description().c_str(), args.threads, args.queue, ready_ms);

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
  return Command{serve, [args](const GlobalOptions& global) { return run_serve(*args, global); }};
}

}  // namespace seamcl::cli
