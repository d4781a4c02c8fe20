#include <seamcl/jobs/compare_job.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <future>

#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include <seamcl/memory/compare_memory.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/io/image_io.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/pipeline/stage_stop.h>

namespace seamcl {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// The compare's own keys; the rest of a request is the frame's render options.
const OptionTable& compare_own_options() {
  static const OptionTable table = [] {
    OptionSpec methods = make_option("methods", OptionType::List, "Comma list of seam methods");
    methods.choices = method_names();
    methods.default_value = json::array({"discard", "clamp"});
    OptionSpec msaa = make_option("msaa", OptionType::List, "Comma list of MSAA rates");
    msaa.integers = {1, 2, 4, 8, 16};
    msaa.default_value = json::array({1, 2, 4, 8});
    OptionSpec repeat = make_option("repeat", OptionType::Integer, "Timed renders per method and rate; ms reports median, min, max");
    repeat.minimum = 1;
    repeat.maximum = 1000;
    repeat.default_value = 3;
    OptionSpec reference = make_option("reference", OptionType::List,
                         "References to measure against: paper (traverse at 8x, Mitchell), box (the same, box "
                         "downsample), analytic (the texture function at every 8x subsample, Mitchell), seamless (a "
                         "planar grid of equal faces as one texture, at the measured rate); the first is error's");
    reference.choices = reference_kind_names();
    reference.default_value = json::array({"paper"});
    OptionSpec reference_method = make_option("reference_method", OptionType::Choice, "Method of the 8x reference render");
    reference_method.choices = method_names();
    reference_method.noun = "method";
    reference_method.absent = "traverse, or discard where traverse is not built in";
    OptionSpec reference_msaa = make_option("reference_msaa", OptionType::Integer, "Samples per pixel of the 8x reference render");
    reference_msaa.integers = {1, 2, 4, 8, 16};
    reference_msaa.absent = "1 for traverse, 16 for discard";
    OptionSpec constant_color = make_option("constant_color", OptionType::String,
                              "Paint every face one linear colour r,g,b (each 0..1): seams then carry no texture error");
    constant_color.absent = "the scene's textures";
    constant_color.pattern = "^ *[0-9.eE+-]+ *, *[0-9.eE+-]+ *, *[0-9.eE+-]+ *$";
    return OptionTable{methods, msaa, repeat, reference, reference_method, reference_msaa, constant_color};
  }();
  return table;
}

glm::vec3 parse_color(const std::string& text) {
  const std::vector<std::string> parts = split_list(text, "constant_color");
  if (parts.size() != 3) throw InputError("constant_color", "must be r,g,b, got '" + text + "'");
  glm::vec3 c;
  for (int i = 0; i < 3; ++i) {
    const std::string& part = parts[static_cast<size_t>(i)];
    char* end = nullptr;
    const float v = std::strtof(part.c_str(), &end);
    if (end != part.c_str() + part.size() || !(v >= 0.0f && v <= 1.0f))
      throw InputError("constant_color", "each component must be a number in [0, 1], got '" + text + "'");
    c[i] = v;
  }
  return c;
}

}  // namespace

const OptionTable& compare_option_table() {
  static const OptionTable table = [] {
    OptionTable out;
    for (const OptionSpec& spec : render_option_table())
      if (spec.key != "method" && spec.key != "msaa") out.push_back(spec);
    for (const OptionSpec& spec : compare_own_options()) out.push_back(spec);
    return out;
  }();
  return table;
}

CompareJob::CompareJob(const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  if (request.contains("method"))
    throw InputError("method", "compare takes \"methods\", a list (\"discard,traverse\" or [\"discard\", \"traverse\"])");
  json frame_request = json::object();
  json own = json::object();
  for (const auto& [key, value] : request.items()) {
    if (find_option(compare_own_options(), key))
      own[key] = value;
    else
      frame_request[key] = value;  // render options; an unknown key is refused by their parser
  }
  // Each own option checked, or its default.
  auto value_of = [&](const char* key) {
    const OptionSpec& spec = *find_option(compare_own_options(), key);
    return own.contains(key) ? checked_option(spec, own.at(key)) : spec.default_value;
  };
  if (frame_request.contains("frames") && !frame_request.contains("frame"))
    throw InputError("frames", "is ignored without frame (the scene's own camera renders): leave it out");
  frame_ = parse_render_options(frame_request);
  for (const json& rate : value_of("msaa")) rates_.push_back(rate.get<int>());
  methods_ = strings_of(value_of("methods"));
  entries_ = method_entries(frame_request, methods_, rates_);
  repeat_ = value_of("repeat").get<int>();
  kinds_ = parse_reference_kinds(strings_of(value_of("reference")));
  if (own.contains("reference_method")) reference_.method = value_of("reference_method").get<std::string>();
  if (own.contains("reference_msaa")) reference_.msaa = value_of("reference_msaa").get<int>();
  if (own.contains("constant_color")) constant_color_ = parse_color(value_of("constant_color").get<std::string>());
  (void)reference_render_options(frame_, reference_);  // the reference's size and settings, checked now
}

GeneratorOptions CompareJob::generator_options() const {
  GeneratorOptions options;
  options.tint = frame_.tint;
  options.constant_color = constant_color_;
  options.defer_textures = true;  // each Renderer packs face by face: no float copy of the textures
  return options;
}

Camera CompareJob::camera(const Scene& scene) const {
  return frame_.frame ? orbit_camera(scene, *frame_.frame, frame_.frames) : scene.camera;
}

JobPlan CompareJob::plan(const Scene& scene) const {
  const bool seamless = std::find(kinds_.begin(), kinds_.end(), ReferenceKind::Seamless) != kinds_.end();
  const CompareMemory memory = compare_memory(scene_sizes(scene), frame_, entries_, reference_, kinds_,
                                              seamless ? std::optional(seamless_scene_sizes(scene)) : std::nullopt);
  return JobPlan{"this compare", memory.device_shares, memory.host_shares, memory.process_shares(true)};
}

CompareRun CompareJob::run(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                           const ReferenceLock& lock_reference) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  const Camera view = camera(scene);
  // The variants this compare renders with build while the scene is hashed and packed, in the
  // order prepare_targets and compare_methods first use them: the seam masks, the reference (when
  // no cache can hold it), the entries.
  std::vector<ProgramNeed> needs;
  for (const MethodEntry& entry : entries_) {
    RenderOptions mask = entry.options;
    mask.method = Method::Black;  // footprint_seam_mask's render
    needs.push_back({mask, true});
  }
  const auto asks_for = [&](ReferenceKind kind) { return std::find(kinds_.begin(), kinds_.end(), kind) != kinds_.end(); };
  // Analytic is never cached and is reduced on the host; paper and box are rendered unless the
  // cache holds them, and reduced on the device (the downsample program).
  const bool reduces_on_device =
      !reference_.use_cache && (asks_for(ReferenceKind::Paper) || asks_for(ReferenceKind::Box));
  const bool renders_reference = asks_for(ReferenceKind::Analytic) || reduces_on_device;
  if (renders_reference) needs.push_back({reference_render_options(frame_, reference_), false, reduces_on_device});
  for (const MethodEntry& entry : entries_) needs.push_back({entry.options, false});
  // A run that ends (cancelled, or failed) leaves out the builds not yet begun: the future's
  // destructor then waits for the one under way only.
  std::atomic<bool> builds_done{false};
  const std::future<void> programs = build_programs_ahead(runtime, scene, needs, &builds_done);
  struct EndBuilds {
    std::atomic<bool>& done;
    ~EndBuilds() { done = true; }
  } end_builds{builds_done};
  // The renders ask the same between their stages (a seam mask, the 8x reference, each entry's
  // frames), for this run only (host/pipeline/stage_stop.h).
  const StageStopScope stage_stop(control.should_stop);
  // Hashed once for the lock's key and every reference kind's cache key. Hashing and packing each
  // bake every face, so a cancel is heard after each of them.
  if (reference_.use_cache && reference_.scene_hash.empty()) reference_.scene_hash = scene_content_hash(scene);
  throw_if_stopped(control.should_stop, "after hashing the scene");
  Renderer renderer(runtime);
  renderer.set_device_byte_limit(control.device_byte_limit);
  renderer.load_scene(scene, frame_.texels);
  throw_if_stopped(control.should_stop, "after packing the scene");
  CompareRun run;
  const int total = static_cast<int>(entries_.size());
  control.step(0, total);
  run.timing.setup_ms = ms_since(start);
  const Clock::time_point targets_start = Clock::now();
  {
    std::unique_lock<std::mutex> lock;
    if (lock_reference) lock = lock_reference(reference_cache_key(scene, view, frame_, reference_));
    run.targets = prepare_targets(runtime, renderer, view, frame_, entries_, reference_, kinds_, control.progress);
  }
  run.timing.targets_ms = ms_since(targets_start);
  throw_if_stopped(control.should_stop, "before the entries");
  const TargetsFor targets_for = [&](const MethodEntry& entry) { return run.targets.for_entry(entry); };
  const Clock::time_point entries_start = Clock::now();
  // Each entry's line comes before it: the entries before it are done.
  int started = 0;
  const Progress entry_progress = [&](const std::string& line) {
    control.report(line);
    control.step(started++, total);
  };
  run.measured = compare_methods(renderer, scene, view, entries_, targets_for, repeat_, control.should_stop, entry_progress);
  control.step(total, total);
  run.timing.entries_ms = ms_since(entries_start);
  // Watertightness of the displaced surface at this camera (docs/displacement.md), at the first rate.
  if (frame_.displacement) {
    control.report("displacement: gap and crack pixels of " + to_string(*frame_.displacement));
    run.displacement =
        measure_displacement(runtime, scene, view, entries_.front().options, 0, 0, renderer.device_byte_limit()).to_json();
  }
  run.timing.total_ms = ms_since(start);
  return run;
}

json CompareJob::result_json(const CompareRun& run, const Scene& scene, const std::string& device,
                             bool with_cache_path) const {
  json results = json::array();
  for (const EntryResult& measured : run.measured) results.push_back(compare_result_json(measured));
  json out = {{"scene", scene.name},
              {"size", std::to_string(frame_.width) + "x" + std::to_string(frame_.height)},
              {"device", device},
              {"repeat", repeat_}};
  out.update(run.targets.summary_json(entries_.front().options.msaa, with_cache_path));
  out["options"] = to_json(frame_);
  out["results"] = results;
  if (frame_.frame) {
    out["frame"] = *frame_.frame;
    out["frames"] = frame_.frames;
  }
  if (!run.displacement.is_null()) out["displacement"] = run.displacement;
  out["timing"] = {{"setup_ms", run.timing.setup_ms},
                   {"targets_ms", run.timing.targets_ms},
                   {"entries_ms", run.timing.entries_ms},
                   {"total_ms", run.timing.total_ms}};
  return out;
}

std::vector<json> write_compare_images(const CompareRun& run, const RenderOptions& frame, const std::string& directory) {
  const fs::path dir(directory);
  for (const ReferenceImage& reference : run.targets.high_res) {
    const std::string name = reference.kind == ReferenceKind::Paper ? "reference" : "reference_" + to_string(reference.kind);
    write_image((dir / (name + ".png")).string(), reference.width, reference.height, reference.pixels);
  }
  for (const auto& [msaa, reference] : run.targets.seamless_by_rate) {
    write_image((dir / ("reference_seamless_msaa" + std::to_string(msaa) + ".png")).string(), reference.width,
                reference.height, reference.pixels);
  }
  for (const auto& [msaa, mask] : run.targets.masks)
    write_image((dir / ("seam_mask_msaa" + std::to_string(msaa) + ".png")).string(), frame.width, frame.height,
                seam_mask_image(mask));
  std::vector<json> paths;
  for (const EntryResult& measured : run.measured) {
    const RenderResult& result = measured.last;
    const std::string stem = measured.entry.method_name + "_msaa" + std::to_string(measured.entry.options.msaa);
    const fs::path image = dir / (stem + ".png");
    const fs::path heat = dir / (stem + "_error.png");
    write_image(image.string(), result.width, result.height, result.pixels);
    write_image(heat.string(), result.width, result.height, error_heatmap(measured.errors->distance));
    paths.push_back({{"image", image.string()}, {"error", heat.string()}});
  }
  return paths;
}

}  // namespace seamcl
