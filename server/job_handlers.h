// The routes that run the library's jobs: POST /v1/render (and GET with a query), POST
// /v1/inspect, POST /v1/overlays, POST /v1/compare and POST /v1/reference. Each takes the service's own keys out of the request (the
// answer's format, an inline scene), hands the rest to the job (host/jobs/), resolves the scene,
// holds the request to this server's limits and budgets, runs the job on an admitted render slot
// and answers what it made.
#pragma once
#include <array>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>

#include <nlohmann/json.hpp>

#include <httplib.h>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/eval/reference.h>
#include <seamcl/jobs/job.h>
#include <seamcl/jobs/job_progress.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>
#include <seamcl/options/render_options.h>

#include "http_server.h"
#include "render_slots.h"
#include "memory_bound.h"
#include "request_budget.h"
#include "scene_resolution.h"

namespace seamcl::server {

// A job id a client gives (X-Seamcl-Job on POST /v1/compare, job on GET /v1/progress): 1 to 64
// letters, digits, '-', '_' or '.'; anything else is a 400 naming `field`.
std::string checked_job_id(const std::string& text, const std::string& field);

class JobHandlers {
 public:
  // Every reference outlives the handlers (the HttpServer owns them all).
  JobHandlers(ClRuntime& runtime, const ServerOptions& options, const SceneResolver& scenes, RenderSlots& slots,
              MemoryBound& memory);

  void render(const nlohmann::json& request, httplib::Response& res);
  // POST /v1/inspect: a render request plus the pixel (x, y, window); the inspect job's JSON.
  void inspect(const nlohmann::json& request, httplib::Response& res);
  // POST /v1/overlays: a render request; the overlay job's JSON (seam mask and face edges).
  void overlays(const nlohmann::json& request, httplib::Response& res);
  // job_id: empty, or the client's name for this compare, under which GET /v1/progress shows it.
  void compare(const nlohmann::json& request, httplib::Response& res, const std::string& job_id = "");
  void reference(const nlohmann::json& request, httplib::Response& res);
  // GET /v1/progress?job=ID: what the job named ID has reported (JobProgressBoard::get).
  void progress(const std::string& job_id, httplib::Response& res) const;

 private:
  struct FrameJobRun {
    double queue_ms = 0, build_ms = 0;
    RenderOptions options;  // the request's, its scene resolved (options.scene: the scene's name)
  };
  // A job on one frame of `options` (a render, an inspection): the scene resolved, the request
  // held to the limits and budgets (`make_plan`: the job's plan for the scene and the bytes the
  // request holds besides), a render slot and a Renderer with the scene, the kernels warmed up,
  // then `work` on them; the times spent waiting for the slot and for the kernels.
  FrameJobRun run_frame_job(std::chrono::steady_clock::time_point start, const nlohmann::json& inline_scene,
                              RenderOptions options, const std::function<JobPlan(const Scene&, size_t)>& make_plan,
                              const std::function<void(Renderer&, const Scene&, const JobControl&)>& work);
  // reference_method and reference_msaa taken out of a reference request.
  ReferenceSettings take_reference_settings(nlohmann::json& rest, bool& explicit_msaa) const;
  // The frame's pixels and the 8x reference's samples within this server's limits (413).
  void check_reference_limits(const RenderOptions& frame, const ReferenceSettings& settings, bool explicit_msaa) const;
  // Held while a reference is read from the cache or made and written to it.
  std::mutex& reference_lock(const std::string& cache_key);
  // What `slot` keeps, counted against the memory bound again after a request changed it.
  void count_kept(RenderSlot& slot);
  // The slot's least recently used Renderer freed: false when it keeps none.
  bool evict_one(RenderSlot& slot);
  // `bytes` reserved under the memory bound for a request on `slot`, evicting what the slot keeps
  // (least recently used first) until they fit; 503 "memory" when they do not.
  std::unique_ptr<MemoryReservation> reserve(RenderSlot& slot, size_t bytes, const std::string& what);

  ClRuntime& runtime_;
  const ServerOptions& options_;
  const SceneResolver& scenes_;
  RenderSlots& slots_;
  MemoryBound& memory_;
  RequestBudget budget_;
  // Two requests for the same reference at once would both render it and write the same cache
  // file: one lock per hash stripe of the cache key.
  std::array<std::mutex, 16> reference_locks_;
  JobProgressBoard progress_;
};

}  // namespace seamcl::server
