#include "http_server.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <utility>

#include <httplib.h>

#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/over_budget.h>
#include <seamcl/eval/reference.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>

#include "api_documents.h"
#include "connection.h"
#include "job_handlers.h"
#include "memory_bound.h"
#include "render_slots.h"
#include "request_hygiene.h"
#include "scene_resolution.h"

namespace seamcl::server {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

// The reference cache of POST /v1/compare: the server's own directory, not a user's ~/.cache.
std::string server_cache_dir(const std::string& configured) {
  if (!configured.empty()) return configured;
  if (const char* dir = std::getenv("SEAMCL_CACHE_DIR"); dir && *dir) return dir;
  return (std::filesystem::temp_directory_path() / "seamcl-serve-cache").string();
}

ConnectionLimits connection_limits(const ServerOptions& options) {
  ConnectionLimits limits;
  limits.max_connections = options.max_connections;
  limits.request_read_timeout = std::chrono::milliseconds(options.request_read_timeout_ms);
  limits.idle_timeout = std::chrono::milliseconds(options.idle_timeout_ms);
  // A chunked body's framing is counted too: room for the body at twice its limit, plus headers.
  limits.max_request_bytes = 2 * options.max_body_bytes + (64 << 10);
  limits.max_body_bytes = options.max_body_bytes;
  limits.max_connections_per_client = options.max_connections_per_client;
  return limits;
}

}  // namespace

HttpServer::HttpServer(ClRuntime& runtime, ServerOptions options)
    : runtime_(runtime), options_(std::move(options)), http_(std::make_unique<GuardedHttpServer>(connection_limits(options_))) {
  if (options_.threads < 1) throw InputError("threads", "must be at least 1");
  if (options_.queue < 0) throw InputError("queue", "must be at least 0");
  if (options_.max_connections < 1) throw InputError("max_connections", "must be at least 1");
  if (options_.max_connections_per_client < 0) throw InputError("max_connections_per_client", "must be at least 0 (0: no cap)");
  if (options_.request_read_timeout_ms < 1) throw InputError("request_read_timeout_ms", "must be at least 1");
  if (options_.deadline_ms < 0) throw InputError("deadline", "must be at least 0 (0: none)");
  options_.cache_dir = server_cache_dir(options_.cache_dir);
  check_reference_cache_dir(options_.cache_dir, "cache_dir");
  scenes_ = std::make_unique<SceneResolver>(options_);

  // The built-in scenes are generated on first use (SceneResolver), the default one by the
  // warm-up, so the port is bound without waiting for them. One slot per thread: their Renderers
  // are made and warmed after bind() (warm_up()); a slot becomes free once warm, so early
  // renders wait for it rather than build kernels themselves.
  slots_ = std::make_unique<RenderSlots>(options_.threads, options_.queue, options_.deadline_ms);
  memory_ = std::make_unique<MemoryBound>(options_.memory_bound_bytes > 0 ? options_.memory_bound_bytes : MemoryBound::default_bound());
  jobs_ = std::make_unique<JobHandlers>(runtime_, options_, *scenes_, *slots_, *memory_);
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
  if (port_ >= 0) http_->widen_backlog();
  if (port_ >= 0 && !warm_thread_.joinable()) {
    started_ = Clock::now();
    warm_thread_ = std::thread([this] { warm_up(); });
  }
  return port_;
}

void HttpServer::warm_up() {
  const Clock::time_point start = Clock::now();
  const RenderOptions defaults;
  const std::string default_key = builtin_scene_key(defaults.scene, false);
  try {
    // Not cut short by stop(): requests already admitted wait for these slots and are answered.
    for (size_t i = 0; i < slots_->size(); ++i) {
      log_line("warming: slot " + std::to_string(i + 1) + "/" + std::to_string(slots_->size()) + ", scene " +
               defaults.scene + ", " + to_string(defaults.method) + " " + to_string(defaults.filter));
      auto renderer = std::make_unique<Renderer>(runtime_);
      renderer->load_scene(*scenes_->builtin_scene(defaults.scene, false), defaults.texels);
      renderer->warm_up(defaults);
      slots_->add_warm(i, default_key, std::move(renderer));
    }
    warmed_variants_.store(1);
    char line[160];
    std::snprintf(line, sizeof line, "ready: %d slots warm in %.0f ms", slots_->ready_slots(), ms_since(start));
    log_line(line);
    // The other variants on a Renderer of their own: the programs land in the shared ClRuntime
    // (and PoCL's cache), so the slots find them built; renders go on meanwhile.
    if (options_.warm_all_methods) {
      Renderer renderer(runtime_);
      renderer.load_scene(*scenes_->builtin_scene(defaults.scene, false), defaults.texels);
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
    variants_done_.store(true);
  } catch (const std::exception& e) {
    variants_done_.store(true);
    const std::string message = describe_cl_exception(e);
    log_line("error: warm-up failed: " + message);
    // With some slots warm the service goes on with those (and says so in /health).
    slots_->record_warm_up_failure(message);
  }
}

// Ready when a request can need no build: every slot warm and, when the server warms every
// method x filter, every one of them built (before that, a render of one still building waited
// behind the build while /ready said 200).
bool HttpServer::ready() const { return slots_->ready() && (!options_.warm_all_methods || variants_done_.load()); }

bool HttpServer::wait_ready(std::chrono::milliseconds timeout) {
  const Clock::time_point deadline = Clock::now() + timeout;
  if (!slots_->wait_ready(timeout)) return false;
  // The background variants have no condition of their own: polled, they take seconds.
  while (!ready()) {
    if (Clock::now() >= deadline || slots_->failed()) return ready();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

bool HttpServer::listen_after_bind() { return http_->listen_after_bind(); }

void HttpServer::stop() {
  stopping_.store(true);
  if (http_) {
    http_->stop();
    http_->begin_shutdown();
  }
  if (slots_) slots_->wake_all();
}

int HttpServer::open_connections() const { return http_->open_connections(); }

bool HttpServer::is_running() const { return http_ && http_->is_running(); }

void HttpServer::log_line(const std::string& line) const {
  if (options_.log) {
    options_.log(line);
  } else {
    std::fprintf(stderr, "%s\n", line.c_str());
  }
}

json HttpServer::health_json() const {
  std::string status = ready() ? "ready" : "starting";
  if (slots_->failed()) status = "failed";
  return {{"status", status},
          {"warming", {{"slots_ready", slots_->ready_slots()}, {"variants_ready", warmed_variants_.load()},
                       {"variants", total_variants_}}},
          {"open_connections", http_->open_connections()},
          {"device", runtime_.device_description()},
          {"uptime_s", std::chrono::duration<double>(Clock::now() - started_).count()},
          {"requests_served", served_.load()},
          {"renders_admitted", slots_->admitted()},
          {"memory", memory_->to_json()},
          {"threads", options_.threads},
          {"queue", options_.queue}};
}

json HttpServer::methods_json() const {
  // Made on first use (from the default scene's sizes), which the start need not wait for.
  std::call_once(methods_once_, [this] {
    methods_cache_ = methods_document(*scenes_->builtin_scene(RenderOptions{}.scene, false), options_);
  });
  return methods_cache_;
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
        if (e.field == "client") log_line("stopped: " + echo(req.path, 200) + ": " + e.message);
        if (e.retry_after_s > 0) res.set_header("Retry-After", std::to_string(e.retry_after_s));
        send_error(res, e.status, e.field, echo(e.field) + ": " + e.message);
      } catch (const OverBudget& e) {
        send_error(res, 413, e.field(), echo(e.field()) + ": " + input_error_message(e));
      } catch (const InputError& e) {
        send_error(res, 400, e.field(), echo(e.field()) + ": " + input_error_message(e));
      } catch (const std::bad_alloc&) {
        // Out of memory for this request: said so, and the connection closes after the answer.
        log_line("error: out of memory while serving " + echo(req.path, 200));
        res.set_header("Retry-After", "1");
        send_error(res, 503, "memory", "memory: the server ran out of memory for this request; retry later");
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
    return refuse_disallowed_method(req, res);
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
  // Statuses httplib sets itself get the JSON body too.
  http.set_error_handler(httplib::Server::HandlerWithResponse(answer_httplib_error));
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
             res.set_content(json_text(scenes_->scenes_json()), "application/json");
           }));
  http.Get("/v1/assets", guarded([this](const httplib::Request&, httplib::Response& res) {
             res.set_content(json_text(scenes_->assets_json()), "application/json");
           }));
  http.Get("/v1/methods", guarded([this](const httplib::Request&, httplib::Response& res) {
             res.set_content(json_text(methods_json()), "application/json");
           }));
  http.Get("/v1/render", guarded([this](const httplib::Request& req, httplib::Response& res) {
             jobs_->render(query_to_json(req.params), res);
           }));
  http.Post("/v1/render", guarded([this](const httplib::Request& req, httplib::Response& res) {
              jobs_->render(parse_json_body(req, options_.max_json_depth), res);
            }));
  http.Post("/v1/inspect", guarded([this](const httplib::Request& req, httplib::Response& res) {
              jobs_->inspect(parse_json_body(req, options_.max_json_depth), res);
            }));
  http.Post("/v1/overlays", guarded([this](const httplib::Request& req, httplib::Response& res) {
              jobs_->overlays(parse_json_body(req, options_.max_json_depth), res);
            }));
  http.Post("/v1/reference", guarded([this](const httplib::Request& req, httplib::Response& res) {
              jobs_->reference(parse_json_body(req, options_.max_json_depth), res);
            }));
  http.Post("/v1/compare", guarded([this](const httplib::Request& req, httplib::Response& res) {
              const std::string job = req.has_header("X-Seamcl-Job")
                                          ? checked_job_id(req.get_header_value("X-Seamcl-Job"), "X-Seamcl-Job")
                                          : std::string();
              jobs_->compare(parse_json_body(req, options_.max_json_depth), res, job);
            }));
  http.Get("/v1/progress", guarded([this](const httplib::Request& req, httplib::Response& res) {
             jobs_->progress(checked_job_id(req.get_param_value("job"), "job"), res);
           }));
  // Last, for every other path and method cpp-httplib routes: a known path is reached here only
  // with a body, which cpp-httplib has read by now.
  http.Get(".*", answer_not_routed);
  http.Post(".*", answer_not_routed);
  http.Put(".*", answer_not_routed);
  http.Delete(".*", answer_not_routed);
  http.Patch(".*", answer_not_routed);
  http.Options(".*", answer_not_routed);
}

}  // namespace seamcl::server
