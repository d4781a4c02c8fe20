#include "job_handlers.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <seamcl/core/cancelled.h>
#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include <seamcl/memory/compare_memory.h>
#include <seamcl/io/image_encoding.h>
#include <seamcl/jobs/compare_job.h>
#include <seamcl/jobs/inspect_job.h>
#include <seamcl/jobs/overlay_job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/pipeline/stage_stop.h>
#include <seamcl/scene/scene.h>

#include "connection.h"
#include "request_hygiene.h"

namespace seamcl::server {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

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

// The answer's image encoding, taken out of a request: png unless `format` names another.
ImageEncoding take_image_encoding(json& rest) {
  if (!rest.contains("format")) return ImageEncoding::Png;
  const json& value = rest.at("format");
  const auto parsed = value.is_string() ? parse_image_encoding(value.get<std::string>()) : std::nullopt;
  if (!parsed) {
    std::string names;
    for (const std::string& name : image_encoding_names()) names += (names.empty() ? "\"" : ", \"") + name + "\"";
    throw InputError("format", "must be one of " + names + ", got " + echo(json_text(value)));
  }
  rest.erase("format");
  return *parsed;
}

// The image as the answer's body, with its size in headers: an f32 body carries no header of its
// own, and a client reads the size before it reads the pixels.
void set_image(httplib::Response& res, ImageEncoding encoding, int width, int height, const std::vector<glm::vec4>& pixels) {
  res.set_header("X-Seamcl-Width", std::to_string(width));
  res.set_header("X-Seamcl-Height", std::to_string(height));
  res.set_content(encode_image(encoding, width, height, pixels), media_type(encoding));
}

}  // namespace

JobHandlers::JobHandlers(ClRuntime& runtime, const ServerOptions& options, const SceneResolver& scenes, RenderSlots& slots,
                         MemoryBound& memory)
    : runtime_(runtime),
      options_(options),
      scenes_(scenes),
      slots_(slots),
      memory_(memory),
      budget_(options.max_request_device_bytes, options.max_request_host_bytes) {}

std::mutex& JobHandlers::reference_lock(const std::string& cache_key) {
  return reference_locks_[std::hash<std::string>{}(cache_key) % reference_locks_.size()];
}

void JobHandlers::count_kept(RenderSlot& slot) {
  std::map<std::string, size_t> now;
  for (const auto& [key, renderer] : slot.renderers)
    if (renderer) now[key] = renderer->device_bytes();
  if (slot.scratch) now[""] = slot.scratch->device_bytes();
  long long delta = 0;
  for (const auto& [key, bytes] : now) delta += static_cast<long long>(bytes);
  for (const auto& [key, bytes] : slot.counted_bytes) delta -= static_cast<long long>(bytes);
  memory_.add_kept(delta);
  slot.counted_bytes = std::move(now);
}

bool JobHandlers::evict_one(RenderSlot& slot) {
  std::string oldest;
  long long oldest_use = 0;
  bool found = false;
  for (const auto& [key, bytes] : slot.counted_bytes) {
    if (bytes == 0) continue;
    const long long use = slot.last_used.contains(key) ? slot.last_used.at(key) : 0;
    if (!found || use < oldest_use) {
      oldest = key;
      oldest_use = use;
      found = true;
    }
  }
  if (!found) return false;
  if (oldest.empty()) {
    slot.scratch.reset();
  } else {
    slot.renderers.erase(oldest);
  }
  slot.last_used.erase(oldest);
  count_kept(slot);
  return true;
}

std::unique_ptr<MemoryReservation> JobHandlers::reserve(RenderSlot& slot, size_t bytes, const std::string& what) {
  if (bytes > memory_.bound()) {
    throw HttpError{413, "memory", what + " needs about " + std::to_string(bytes >> 20) + " MiB, over this server's memory bound of " +
                                       std::to_string(memory_.bound() >> 20) + " MiB"};
  }
  while (!memory_.try_reserve(bytes)) {
    if (!evict_one(slot)) {
      throw HttpError{503, "memory", "the server's memory bound (" + std::to_string(memory_.bound() >> 20) +
                                         " MiB) is taken by the requests in flight; retry later", 1};
    }
  }
  return std::make_unique<MemoryReservation>(memory_, bytes);
}

void JobHandlers::render(const json& request, httplib::Response& res) {
  const Clock::time_point start = Clock::now();
  if (!request.is_object()) throw HttpError{400, "body", "must be a JSON object"};

  // The service's own keys (format, an inline scene); the rest is the render job's request, but
  // the command line's timing keys: one answer is one image.
  json rest = request;
  const ImageEncoding format = take_image_encoding(rest);
  const json inline_scene = take_inline_scene(rest);
  for (const char* key : {"repeat", "crack_orbit"})
    if (rest.contains(key)) throw HttpError{400, key, "is the command line's (seamcl render); a request renders one image"};
  // A path the render job would write: a client must never name a file on the server's disk.
  if (rest.contains("export_mesh"))
    throw HttpError{400, "export_mesh", "is the command line's (seamcl render --export-mesh): the server writes no file a request names"};
  const RenderJob job(rest);
  RenderRun run;
  const FrameJobRun times = run_frame_job(
      start, inline_scene, job.options(), [&](const Scene& scene, size_t held) { return job.plan(scene, held); },
      [&](Renderer& renderer, const Scene& scene, const JobControl& control) {
        run = job.run(runtime_, renderer, scene, control);
      });
  const double queue_ms = times.queue_ms, build_ms = times.build_ms;
  const RenderOptions& options = times.options;
  const RenderResult& result = run.last;
  const Clock::time_point encode_start = Clock::now();
  set_image(res, format, result.width, result.height, result.pixels);
  const double encode_ms = ms_since(encode_start);

  res.set_header("X-Seamcl-Render-Ms", std::to_string(result.ms.total));
  res.set_header("X-Seamcl-Stage-Ms", json_text(RenderJob::stage_ms_json(result.ms)));
  res.set_header("X-Seamcl-Queue-Ms", std::to_string(queue_ms));
  res.set_header("X-Seamcl-Build-Ms", std::to_string(build_ms));
  res.set_header("X-Seamcl-Encode-Ms", std::to_string(encode_ms));
  res.set_header("X-Seamcl-Server-Ms", std::to_string(ms_since(start)));
  res.set_header("X-Seamcl-Options", json_text(to_json(options)));
  res.set_header("X-Seamcl-Fragments", std::to_string(result.stats.fragments));
}

JobHandlers::FrameJobRun JobHandlers::run_frame_job(
    Clock::time_point start, const json& inline_scene, RenderOptions options,
    const std::function<JobPlan(const Scene&, size_t)>& make_plan,
    const std::function<void(Renderer&, const Scene&, const JobControl&)>& work) {
  std::string key;
  const std::shared_ptr<const Scene> scene = scenes_.resolve(inline_scene, options, key);
  const bool inline_request = key.empty();  // an inline scene or an asset: held for this request only
  // Limits after every syntax check (a malformed request is a 400 whatever its size) and before
  // anything is packed or put on the device (an inline scene's own size is bounded by the face
  // and texel limits checked before it is parsed).
  if (static_cast<long long>(options.width) * options.height * options.msaa > options_.max_samples) {
    throw HttpError{413, "size",
                    "width x height x msaa = " + std::to_string(static_cast<long long>(options.width) * options.height * options.msaa) +
                        " exceeds this server's limit of " + std::to_string(options_.max_samples) + " samples"};
  }
  budget_.refuse_scene_over(*scene, options, inline_scene, key);
  // The request's own copy of an inline scene or asset is held on top of the Renderer's.
  const JobPlan plan = make_plan(*scene, inline_request ? scene_host_bytes(scene_sizes(*scene)) : 0);
  budget_.refuse_over(plan.device, plan.host, !inline_request, plan.what);

  // Wait for a render slot (or 503), render, and give the slot back before encoding.
  const Clock::time_point queued = Clock::now();
  FrameJobRun times;
  times.options = options;
  const std::unique_ptr<SlotLease> lease = slots_.acquire(start);
  times.queue_ms = ms_since(queued);
  // Queued for a client that has since hung up: nobody would read the image.
  if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
  RenderSlot& slot = lease->slot();
  // Admitted under the memory bound: what this slot keeps goes first, least recently used.
  const size_t planned = plan.unified.total() > 0 ? plan.unified.total() : plan.device.total() + plan.host.total();
  // Counted again however the request ends (after its reservation is given back); the kept
  // caches then give back what is over.
  struct Recount {
    JobHandlers& jobs;
    RenderSlot& slot;
    ~Recount() {
      jobs.count_kept(slot);
      while (jobs.memory_.kept_over() && jobs.evict_one(slot)) {
      }
    }
  } recount{*this, slot};
  const std::unique_ptr<MemoryReservation> reserved = reserve(slot, planned, plan.what);
  slot.last_used[key] = ++slot.uses;
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
    // A render whose client has gone stops at the next stage boundary, like a compare.
    control.should_stop = [] { return GuardedHttpServer::client_gone(); };
    try {
      // What it needs before its frame, made here and timed: kernel variants the warm-up has
      // not built yet and an environment's cube map. A render that waits for them says so
      // (X-Seamcl-Build-Ms), never a silent stall.
      {
        const StageStopScope stop_between_stages(control.should_stop);
        const Clock::time_point build_start = Clock::now();
        renderer->warm_up(options);
        times.build_ms = ms_since(build_start);
      }
      work(*renderer, *scene, control);
    } catch (const Cancelled& e) {
      throw HttpError{503, "client", std::string("the client has gone; render ") + e.what(), 0};
    }
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
  return times;
}

// POST /v1/inspect: the inspect job (host/jobs/inspect_job.h) on one frame, admitted as a render,
// answered as its JSON.
void JobHandlers::inspect(const json& request, httplib::Response& res) {
  const Clock::time_point start = Clock::now();
  if (!request.is_object()) throw HttpError{400, "body", "must be a JSON object"};
  json rest = request;
  const json inline_scene = take_inline_scene(rest);
  if (rest.contains("format")) throw HttpError{400, "format", "inspect answers JSON; format is for /v1/render"};
  for (const char* key : {"repeat", "crack_orbit", "export_mesh"})
    if (rest.contains(key)) throw HttpError{400, key, "is for renders; an inspection renders one frame"};
  const InspectJob job(rest);
  json answer;
  const FrameJobRun times = run_frame_job(
      start, inline_scene, job.options(), [&](const Scene& scene, size_t held) { return job.plan(scene, held); },
      [&](Renderer& renderer, const Scene& scene, const JobControl& control) {
        answer = job.run(renderer, scene, control);
      });
  res.set_header("X-Seamcl-Queue-Ms", std::to_string(times.queue_ms));
  res.set_header("X-Seamcl-Build-Ms", std::to_string(times.build_ms));
  res.set_header("X-Seamcl-Server-Ms", std::to_string(ms_since(start)));
  res.set_content(json_text(answer), "application/json");
}

// POST /v1/overlays: the overlay job (host/jobs/overlay_job.h) on one frame, admitted as a render,
// answered as its JSON.
void JobHandlers::overlays(const json& request, httplib::Response& res) {
  const Clock::time_point start = Clock::now();
  if (!request.is_object()) throw HttpError{400, "body", "must be a JSON object"};
  json rest = request;
  const json inline_scene = take_inline_scene(rest);
  if (rest.contains("format")) throw HttpError{400, "format", "overlays answer JSON; format is for /v1/render"};
  const OverlayJob job(rest);
  json answer;
  const FrameJobRun times = run_frame_job(
      start, inline_scene, job.options(), [&](const Scene& scene, size_t held) { return job.plan(scene, held); },
      [&](Renderer& renderer, const Scene& scene, const JobControl& control) {
        answer = job.run(runtime_, renderer, scene, control);
      });
  res.set_header("X-Seamcl-Queue-Ms", std::to_string(times.queue_ms));
  res.set_header("X-Seamcl-Build-Ms", std::to_string(times.build_ms));
  res.set_header("X-Seamcl-Server-Ms", std::to_string(ms_since(start)));
  res.set_content(json_text(answer), "application/json");
}

// POST /v1/compare: the compare job (host/jobs/compare_job.h) on one frame, admitted as one
// request, answered as the JSON of `seamcl compare --json` (without server paths: no cache_path,
// no images).
void JobHandlers::compare(const json& request, httplib::Response& res, const std::string& job_id) {
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
  const std::shared_ptr<const Scene> scene = scenes_.resolve(inline_scene, frame, key);
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
  budget_.refuse_scene_over(*scene, frame, inline_scene, key);
  const JobPlan plan = job.plan(*scene);
  budget_.refuse_over(plan.device, plan.host, !key.empty(), plan.what);
  // Work for a client that has gone, or past the deadline, stops at the next entry, repeat or render stage.
  const Clock::time_point deadline =
      options_.deadline_ms > 0 ? start + std::chrono::milliseconds(options_.deadline_ms) : Clock::time_point::max();
  JobControl control;
  control.should_stop = [deadline] { return GuardedHttpServer::client_gone() || Clock::now() > deadline; };
  control.device_byte_limit = options_.max_request_device_bytes;
  // A client that named the job (X-Seamcl-Job) polls GET /v1/progress for its lines and steps.
  struct Finish {
    JobProgressBoard& board;
    const std::string& id;
    ~Finish() {
      if (!id.empty()) board.finish(id);
    }
  } finish{progress_, job_id};
  if (!job_id.empty()) {
    progress_.start(job_id, control);
    control.report("waiting for a render slot");
  }

  // One admitted request for the whole compare, with a Renderer of its own (the job's): the 8x
  // reference's buffers are freed with it, and the slot's warm Renderers keep their scenes.
  const Clock::time_point queued = Clock::now();
  double queue_ms = 0;
  CompareRun run;
  {
    const std::unique_ptr<SlotLease> lease = slots_.acquire(start);
    queue_ms = ms_since(queued);
    if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
    const size_t planned = plan.unified.total() > 0 ? plan.unified.total() : plan.device.total() + plan.host.total();
    const std::unique_ptr<MemoryReservation> reserved = reserve(lease->slot(), planned, plan.what);
    control.report("building kernels and packing the scene");
    // Two compares of the same reference at once render it once: the second reads the first's.
    const ReferenceLock lock_reference = [this](const std::string& cache_key) {
      return std::unique_lock<std::mutex>(reference_lock(cache_key));
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

std::string checked_job_id(const std::string& text, const std::string& field) {
  const bool ok = !text.empty() && text.size() <= 64 && std::all_of(text.begin(), text.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' || c == '.';
  });
  if (!ok) throw HttpError{400, field, "must be 1 to 64 letters, digits, '-', '_' or '.', got '" + echo(text) + "'"};
  return text;
}

void JobHandlers::progress(const std::string& job_id, httplib::Response& res) const {
  const std::optional<json> state = progress_.get(job_id);
  if (!state) throw HttpError{404, "job", "no job '" + echo(job_id) + "' on this server (never started here, or long gone)"};
  res.set_content(json_text(*state), "application/json");
}

ReferenceSettings JobHandlers::take_reference_settings(json& rest, bool& explicit_msaa) const {
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

void JobHandlers::check_reference_limits(const RenderOptions& frame, const ReferenceSettings& settings, bool explicit_msaa) const {
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
void JobHandlers::reference(const json& request, httplib::Response& res) {
  const Clock::time_point start = Clock::now();
  if (!request.is_object()) throw HttpError{400, "body", "must be a JSON object"};
  json rest = request;
  for (const char* key : {"method", "methods", "msaa", "repeat"}) {
    if (rest.contains(key)) {
      throw HttpError{400, key, std::string("the reference is one image of the frame; ") + key + " is for /v1/render or /v1/compare"};
    }
  }
  const ImageEncoding format = take_image_encoding(rest);
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
  const std::shared_ptr<const Scene> scene = scenes_.resolve(inline_scene, frame, key);
  const Camera camera = frame.frame ? orbit_camera(*scene, *frame.frame, frame.frames) : scene->camera;
  check_reference_limits(frame, settings, explicit_reference_msaa);
  budget_.refuse_scene_over(*scene, frame, inline_scene, key);
  const CompareMemory memory = compare_memory(scene_sizes(*scene), frame, {}, settings);
  budget_.refuse_over(memory.device_shares, memory.host_shares, !key.empty(), "this reference");

  const Clock::time_point queued = Clock::now();
  double queue_ms = 0;
  ReferenceImage reference;
  {
    const std::unique_ptr<SlotLease> lease = slots_.acquire(start);
    queue_ms = ms_since(queued);
    if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
    const std::unique_ptr<MemoryReservation> reserved =
        reserve(lease->slot(), memory.device_shares.total() + memory.host_shares.total(), "this reference");
    Renderer renderer(runtime_);
    renderer.set_device_byte_limit(options_.max_request_device_bytes);
    renderer.load_scene(*scene, frame.texels);
    settings.scene_hash = scene_content_hash(*scene);  // once for the lock's key and the cache's
    const std::string cache_key = reference_cache_key(*scene, camera, frame, settings);
    std::lock_guard lock(reference_lock(cache_key));
    reference = reference_image(renderer, camera, frame, settings);
  }
  set_image(res, format, reference.width, reference.height, reference.pixels);
  res.set_header("X-Seamcl-Reference-Method", reference.method);
  res.set_header("X-Seamcl-Reference", reference_json(reference, false).dump());
  res.set_header("X-Seamcl-Queue-Ms", std::to_string(queue_ms));
  res.set_header("X-Seamcl-Server-Ms", std::to_string(ms_since(start)));
}

}  // namespace seamcl::server
