#include <seamcl/jobs/bench_job.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>

#include <seamcl/assets/scene_source.h>
#include <seamcl/core/input_error.h>
#include <seamcl/memory/bench_memory.h>
#include <seamcl/batch/bench_merge.h>
#include <seamcl/io/image_io.h>
#include <seamcl/jobs/compare_job.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>

namespace seamcl {
namespace {

using nlohmann::json;

// The bench's own keys; the rest of a request is the frame's render options.
const OptionTable& bench_own_options() {
  static const OptionTable table = [] {
    OptionTable out;
    for (const char* key : {"methods", "msaa", "reference_method", "reference_msaa"}) {
      OptionSpec spec = *find_option(compare_option_table(), key);
      if (spec.key == "methods") spec.default_value = json::array({"discard", "traverse"});
      out.push_back(spec);
    }
    OptionSpec reference_frames = make_option(
        "reference_frames", OptionType::Integer,
        "Measure errors on every K-th frame only (frames 0, K, 2K, ...): each needs an 8x reference");
    reference_frames.minimum = 1;
    reference_frames.maximum = kMaxFrames;
    reference_frames.default_value = 1;
    OptionSpec no_errors = make_option("no_errors", OptionType::Boolean,
                                       "Skip the references and errors (times, NaN counts, temporal only)");
    no_errors.default_value = false;
    OptionSpec shard = make_option("shard", OptionType::String,
                                   "Run part K (1-based) of N: a contiguous block of the orbit's frames; `seamcl merge` "
                                   "combines the parts' JSON into the unsharded run's");
    shard.pattern = "^[0-9]+/[0-9]+$";
    shard.default_value = "1/1";
    OptionSpec seam_mask = make_option("seam_mask", OptionType::Choice,
                                       "The seam pixels errors are pooled over (footprint: each rate's pixels whose "
                                       "filter footprint crosses a shared edge, as compare measures; band: within 2 px "
                                       "of a face boundary, one mask for every rate)");
    seam_mask.choices = seam_mask_kind_names();
    seam_mask.noun = "mask";
    seam_mask.default_value = "band";
    OptionSpec sweep = make_option("sweep", OptionType::String,
                                   "Scaling sweeps instead of the orbit: a comma list of " +
                                       joined_names(sweep_axis_names()) +
                                       ", or all (time against image pixels, paper's face count at equal pixels, "
                                       "MSAA rate, texels)");
    sweep.absent = "the orbit";
    OptionSpec sweep_repeats = make_option("sweep_repeats", OptionType::Integer,
                                           "Timed renders per method and sweep point (median)");
    sweep_repeats.minimum = 1;
    sweep_repeats.maximum = 100;
    sweep_repeats.default_value = 5;
    for (const OptionSpec& spec : {reference_frames, no_errors, shard, seam_mask, sweep, sweep_repeats})
      out.push_back(spec);
    return out;
  }();
  return table;
}

// The orbit's options, which a sweep never reads. (The reference cache is the front end's and is
// not refused: a wrapper may pass it to every bench, and without references it does nothing.)
const std::vector<std::string> kOrbitOnlyKeys = {"msaa",           "frames",         "no_errors", "reference_frames",
                                                 "reference_method", "reference_msaa", "shard",     "seam_mask"};

// A boolean given as false asks for the default: only a key that would change something is "given".
bool given(const json& request, const std::string& key) {
  return request.contains(key) && !(request.at(key).is_boolean() && !request.at(key).get<bool>());
}

void refuse_ignored(const json& request, const std::vector<std::string>& keys, const std::string& where) {
  for (const std::string& key : keys)
    if (given(request, key)) throw InputError(key, "is ignored " + where + ": leave it out");
}

size_t count_nonfinite(const std::vector<glm::vec4>& pixels) {
  size_t n = 0;
  for (const glm::vec4& p : pixels)
    if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b)) ++n;
  return n;
}

// Pixels of several frames pooled, so the statistics over them are exact (not means of means).
struct Pool {
  std::vector<float> distance;
  std::vector<uint8_t> mask;
  size_t nan_pixels = 0, seam_nan_pixels = 0;
  int frames = 0;
  void add(const ImageErrors& e, const std::vector<uint8_t>& m) {
    distance.insert(distance.end(), e.distance.begin(), e.distance.end());
    mask.insert(mask.end(), m.begin(), m.end());
    nan_pixels += e.nan_pixels;
    seam_nan_pixels += e.seam_nan_pixels;
    ++frames;
  }
  ImageErrors stats() const {
    // As compare_images: seam over the value 1, off the seams over 0 (a footprint mask's boundary
    // pixels, 2, are neither).
    ImageErrors e;
    e.all = error_stats(distance);
    const std::vector<uint8_t> seam = seam_pixels_only(mask), off = off_seam_pixels_only(mask);
    e.seam = error_stats(distance, &seam);
    e.off_seam = error_stats(distance, &off);
    e.nan_pixels = nan_pixels;
    e.seam_nan_pixels = seam_nan_pixels;
    return e;
  }
};

struct Accum {
  MethodEntry entry;
  Renderer* renderer = nullptr;
  std::vector<StageTimes> ms;         // per frame
  std::vector<size_t> nan_per_frame;  // non-finite pixels of each frame's image
  Pool errors;
  json error_per_frame = json::array();
  std::vector<glm::vec4> previous;  // last frame's image, for temporal stability
  std::vector<double> temporal_seam, temporal_all;
  json temporal_per_frame = json::array();  // per pair (k-1, k): {frame: k, mean, seam_mean or null}
  RenderResult current;
  size_t texture_bytes = 0, padding_bytes = 0, adjacency_bytes = 0;
};

struct DifferenceAccum {
  size_t a = 0, b = 0;  // indices into the entries
  int msaa = 0;
  Pool pool;
};

// Figure 5 (left): discard against traverse at each rate both have.
std::vector<DifferenceAccum> discard_traverse_pairs(const std::vector<MethodEntry>& entries) {
  std::vector<DifferenceAccum> pairs;
  for (size_t i = 0; i < entries.size(); ++i) {
    if (entries[i].options.method != Method::Discard) continue;
    for (size_t j = 0; j < entries.size(); ++j) {
      if (entries[j].options.method == Method::Traverse && entries[j].options.msaa == entries[i].options.msaa) {
        pairs.push_back({i, j, entries[i].options.msaa, {}});
        break;
      }
    }
  }
  return pairs;
}

json result_of(const Accum& a, bool with_errors) {
  const RenderOptions& o = a.entry.options;
  std::vector<double> total, setup, binning, raster, shade, readback;
  for (const StageTimes& t : a.ms) {
    total.push_back(t.total);
    setup.push_back(t.setup);
    binning.push_back(t.binning);
    raster.push_back(t.raster);
    shade.push_back(t.shade);
    readback.push_back(t.readback);
  }
  json ms = bench_timing_stats(total);
  ms["stages"] = {{"setup", median_of(setup)}, {"binning", median_of(binning)}, {"raster", median_of(raster)},
                  {"shade", median_of(shade)}, {"readback", median_of(readback)}};
  size_t nan_total = 0;
  for (size_t n : a.nan_per_frame) nan_total += n;
  json item = {{"method", a.entry.method_name},
               {"msaa", o.msaa},
               {"aniso", o.aniso},
               {"filter", to_string(o.filter)},
               {"ms", ms},
               {"ms_per_frame", total},
               {"ms_stages_per_frame",
                {{"setup", setup}, {"binning", binning}, {"raster", raster}, {"shade", shade}, {"readback", readback}}},
               {"nan_pixels", nan_total},
               {"nan_pixels_per_frame", a.nan_per_frame},
               {"temporal",
                {{"seam_mean", finite_or_zero(mean_in_order(a.temporal_seam))},
                 {"mean", finite_or_zero(mean_in_order(a.temporal_all))},
                 {"pairs", a.temporal_all.size()},
                 {"seam_pairs", a.temporal_seam.size()}}},
               {"temporal_per_frame", a.temporal_per_frame},
               {"texture_bytes", a.texture_bytes},
               {"padding_bytes", a.padding_bytes},
               {"adjacency_bytes", a.adjacency_bytes}};
  if (with_errors) {
    const ImageErrors e = a.errors.stats();
    item["error"] = errors_json(e);
    item["error"]["frames"] = a.errors.frames;
    item["curve"] = curve_json(e.all);
    item["seam_curve"] = curve_json(e.seam);
    item["error_per_frame"] = a.error_per_frame;
  }
  return item;
}

}  // namespace

const OptionTable& bench_option_table() {
  static const OptionTable table = [] {
    OptionTable out;
    for (const OptionSpec& spec : render_option_table()) {
      if (spec.key == "method" || spec.key == "msaa" || spec.key == "frame") continue;
      OptionSpec copy = spec;
      if (copy.key == "frames") copy.help = "Frames of the camera orbit; frame k uses orbit frame k of N";
      out.push_back(copy);
    }
    for (const OptionSpec& spec : bench_own_options()) out.push_back(spec);
    return out;
  }();
  return table;
}

BenchJob::BenchJob(const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  if (request.contains("method"))
    throw InputError("method", "bench takes \"methods\", a list (\"discard,traverse\" or [\"discard\", \"traverse\"])");
  if (request.contains("frame")) throw InputError("frame", "bench renders every frame of the orbit: leave it out");
  json frame_request = json::object();
  json own = json::object();
  for (const auto& [key, value] : request.items()) {
    if (find_option(bench_own_options(), key))
      own[key] = value;
    else
      frame_request[key] = value;  // render options; an unknown key is refused by their parser
  }
  auto value_of = [&](const char* key) {
    const OptionSpec& spec = *find_option(bench_own_options(), key);
    return own.contains(key) ? checked_option(spec, own.at(key)) : spec.default_value;
  };
  methods_ = strings_of(value_of("methods"));
  if (own.contains("reference_method")) reference_.method = value_of("reference_method").get<std::string>();
  if (own.contains("reference_msaa")) reference_.msaa = value_of("reference_msaa").get<int>();
  sweep_repeats_ = value_of("sweep_repeats").get<int>();

  if (own.contains("sweep")) {
    sweep_text_ = value_of("sweep").get<std::string>();
    refuse_ignored(request, kOrbitOnlyKeys, "with sweep (a sweep renders no orbit)");
    sweep_axes_ = parse_sweep(sweep_text_);
    if (std::none_of(sweep_axes_.begin(), sweep_axes_.end(), sweep_reads_base_size))
      refuse_ignored(request, {"size"}, "with sweep " + sweep_text_ + " (its points have sizes of their own)");
    frame_ = parse_render_options(frame_request);
    validate_sweep(sweep_axes_, sweep_settings());
    return;
  }
  refuse_ignored(request, {"sweep_repeats"}, "without sweep");
  with_errors_ = !value_of("no_errors").get<bool>();
  if (!with_errors_)
    refuse_ignored(request, {"reference_frames", "reference_method", "reference_msaa"},
                   "with no_errors (no reference is rendered)");
  frame_request["frame"] = 0;
  frame_ = parse_render_options(frame_request);
  std::vector<int> rates;
  for (const json& rate : value_of("msaa")) rates.push_back(rate.get<int>());
  entries_ = method_entries(frame_request, methods_, rates);
  reference_frames_ = value_of("reference_frames").get<int>();
  if (with_errors_) (void)reference_render_options(frame_, reference_);  // size and settings checked now
  shard_ = parse_shard(value_of("shard").get<std::string>());
  range_ = shard_frames(shard_, frame_.frames);
  mask_kind_ = *parse_seam_mask_kind(value_of("seam_mask").get<std::string>());
}

GeneratorOptions BenchJob::generator_options() const {
  GeneratorOptions options;
  options.tint = frame_.tint;
  options.defer_textures = true;  // each Renderer packs face by face: no float copy of the textures
  return options;
}

SweepSettings BenchJob::sweep_settings() const {
  SweepSettings settings;
  settings.base = frame_;
  settings.methods = methods_;
  settings.repeats = sweep_repeats_;
  settings.make_scene = [base = frame_](const GeneratorOptions& generator) {
    SceneSourceOptions source;
    source.generator = generator;
    source.displacement_map = base.displacement_map;
    return load_scene_source(base.scene, base.texture, source);
  };
  return settings;
}

int BenchJob::error_frame_count() const {
  int count = 0;
  for (int k = range_.first; k < range_.end; ++k) count += with_errors_ && k % reference_frames_ == 0 ? 1 : 0;
  return count;
}

JobPlan BenchJob::plan(const Scene& scene) const {
  if (is_sweep()) throw std::logic_error("BenchJob::plan: a sweep is refused group by group (refuse_beyond_machine)");
  const BenchMemory memory =
      bench_memory(scene_sizes(scene), frame_, entries_, reference_,
                   {with_errors_, error_frame_count(), discard_traverse_pairs(entries_).size(), range_.size()});
  return JobPlan{"this bench", memory.device, memory.host, {}};
}

void BenchJob::refuse_beyond_machine(const Scene& scene, const DeviceInfo& device) const {
  if (is_sweep()) {
    refuse_sweeps_beyond_machine(sweep_axes_, sweep_settings(), device);
    return;
  }
  const JobPlan planned = plan(scene);
  seamcl::refuse_beyond_machine(planned.device, planned.host, device, planned.what);
}

std::string frame_images_folder(int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06d", frame);
  return name;
}

void BenchJob::refuse_images(const std::string& field) const {
  if (is_sweep()) throw InputError(field, "writes the orbit's error frames: a sweep has none (leave out sweep)");
  if (!with_errors_) throw InputError(field, "writes the orbit's error frames: no_errors leaves none");
}

json BenchJob::run(ClRuntime& runtime, const Scene& scene, const JobControl& control, const std::string& images_dir) {
  if (!images_dir.empty()) refuse_images("images");
  if (!is_sweep()) return run_orbit(runtime, scene, control, images_dir);
  SweepSettings settings = sweep_settings();
  // The sweeps report once per point and take no stop hook: the point's report is where a stop is
  // asked for.
  settings.progress = [&control](const std::string& line) {
    control.report(line);
    throw_if_stopped(control.should_stop, "between sweep points");
  };
  settings.device_byte_limit = control.device_byte_limit;
  throw_if_stopped(control.should_stop, "before the sweeps");
  return run_scaling_sweeps(runtime, sweep_axes_, settings);
}

json BenchJob::run_orbit(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                         const std::string& images_dir) {
  const auto wall_start = std::chrono::steady_clock::now();
  ReferenceSettings reference = reference_;
  // Once, not per reference frame: hashing bakes every face.
  if (with_errors_ && reference.use_cache && reference.scene_hash.empty()) reference.scene_hash = scene_content_hash(scene);

  // One renderer for the face maps and references, one per method (a method's packing, e.g. the
  // guard bands, then stays uploaded instead of being rebuilt on every switch).
  Renderer base_renderer(runtime);
  base_renderer.set_device_byte_limit(control.device_byte_limit);
  base_renderer.load_scene(scene, frame_.texels);
  std::map<std::string, std::unique_ptr<Renderer>> renderers;
  std::vector<Accum> acc(entries_.size());
  for (size_t i = 0; i < entries_.size(); ++i) {
    std::unique_ptr<Renderer>& r = renderers[entries_[i].method_name];
    if (!r) {
      r = std::make_unique<Renderer>(runtime);
      r->set_device_byte_limit(control.device_byte_limit);
      r->load_scene(scene, frame_.texels);
    }
    acc[i].entry = entries_[i];
    acc[i].renderer = r.get();
    r->warm_up(entries_[i].options);
  }
  std::vector<DifferenceAccum> diffs = discard_traverse_pairs(entries_);

  const int frames = frame_.frames;
  std::string reference_method;
  int reference_msaa = 0, references_cached = 0, references_rendered = 0;
  double reference_ms = 0;
  std::vector<int> error_frame_list;
  std::vector<size_t> seam_pixels_per_frame;

  // A part that starts later renders the frame before its first (untimed, unmeasured), so the
  // temporal pair across its first frame is measured as an unsharded run measures it.
  if (range_.first > 0) {
    const int k = range_.first - 1;
    const Camera camera = orbit_camera(scene, k, frames);
    for (Accum& a : acc) {
      MethodEntry entry = a.entry;
      entry.options.frame = k;
      a.previous = a.renderer->render(camera, entry.options).pixels;
    }
  }
  for (int k = range_.first; k < range_.end; ++k) {
    throw_if_stopped(control.should_stop, "before frame " + std::to_string(k));
    RenderOptions frame_options = frame_;
    frame_options.frame = k;
    const Camera camera = orbit_camera(scene, k, frames);
    // The mask per rate: one band (0/1) for every rate, or each rate's footprint mask (0/1/2).
    std::map<int, std::vector<uint8_t>> masks;
    if (mask_kind_ == SeamMaskKind::Band) {
      const std::vector<uint8_t> band = seam_mask(render_face_map(base_renderer, camera, frame_options));
      for (const MethodEntry& e : entries_) masks[e.options.msaa] = band;
    } else {
      for (const MethodEntry& e : entries_) {
        if (masks.count(e.options.msaa)) continue;
        RenderOptions mask_options = frame_options;
        mask_options.msaa = e.options.msaa;
        masks[e.options.msaa] = footprint_seam_mask(base_renderer, camera, mask_options);
      }
    }
    std::map<int, std::vector<uint8_t>> seam_only;  // value 1 only, for error_stats
    for (const auto& [rate, mask] : masks) seam_only[rate] = seam_pixels_only(mask);
    const std::vector<uint8_t>& first_seam = seam_only.begin()->second;  // the lowest rate's
    seam_pixels_per_frame.push_back(static_cast<size_t>(std::count(first_seam.begin(), first_seam.end(), uint8_t{1})));
    std::optional<ReferenceImage> frame_reference;
    if (with_errors_ && k % reference_frames_ == 0) {
      frame_reference = reference_image(base_renderer, camera, frame_options, reference);
      reference_method = frame_reference->method;
      reference_msaa = frame_reference->msaa;
      frame_reference->from_cache ? ++references_cached : ++references_rendered;
      reference_ms += frame_reference->render_ms;
      error_frame_list.push_back(k);
    }
    std::string line = "frame " + std::to_string(k + 1) + "/" + std::to_string(frames) +
                       (frame_reference ? (frame_reference->from_cache ? " [reference cached]" : " [reference rendered]") : "") +
                       " ms:";
    // Interleaved: every entry once per frame, starting one further along each frame so that no
    // entry always runs first (or right after a reference render).
    for (size_t n = 0; n < entries_.size(); ++n) {
      const size_t i = (n + static_cast<size_t>(k)) % entries_.size();
      Accum& a = acc[i];
      MethodEntry entry = a.entry;
      entry.options.frame = k;
      const std::vector<uint8_t>& mask = masks.at(entry.options.msaa);
      EntryResult r =
          measure_entry(*a.renderer, camera, entry, 1, frame_reference ? &frame_reference->pixels : nullptr, &mask);
      a.ms.push_back(r.last.ms);
      a.nan_per_frame.push_back(count_nonfinite(r.last.pixels));
      a.texture_bytes = r.texture_bytes;
      a.padding_bytes = r.padding_bytes;
      a.adjacency_bytes = r.adjacency_bytes;
      if (r.errors) {
        a.error_per_frame.push_back({{"frame", k},
                                     {"mean", finite_or_zero(r.errors->all.mean)},
                                     {"p99", finite_or_zero(r.errors->all.p99)},
                                     {"seam_mean", finite_or_zero(r.errors->seam.mean)},
                                     {"nan_pixels", r.errors->nan_pixels}});
        a.errors.add(*r.errors, mask);
      }
      a.current = std::move(r.last);
    }
    for (Accum& a : acc) {
      line += " " + a.entry.method_name + "/" + std::to_string(a.entry.options.msaa) + "=" +
              std::to_string(a.current.ms.total).substr(0, 6);
      if (!a.previous.empty()) {
        const std::vector<float> change = pixel_distances(a.current.pixels, a.previous);
        const ErrorStats seam = error_stats(change, &seam_only.at(a.entry.options.msaa));
        if (seam.pixels > 0) a.temporal_seam.push_back(seam.mean);  // frames with no seam in view: skipped
        a.temporal_all.push_back(error_stats(change).mean);
        a.temporal_per_frame.push_back({{"frame", k},
                                        {"mean", a.temporal_all.back()},
                                        {"seam_mean", seam.pixels > 0 ? json(seam.mean) : json(nullptr)}});
      }
    }
    if (frame_reference && !images_dir.empty()) {
      const std::filesystem::path dir = std::filesystem::path(images_dir) / frame_images_folder(k);
      std::filesystem::create_directories(dir);
      write_image((dir / "reference.png").string(), frame_.width, frame_.height, frame_reference->pixels);
      for (const auto& [rate, mask] : masks)
        write_image((dir / ("seam_mask_msaa" + std::to_string(rate) + ".png")).string(), frame_.width, frame_.height,
                    seam_mask_image(mask));
      for (const Accum& a : acc) {
        const std::string stem = a.entry.method_name + "_msaa" + std::to_string(a.entry.options.msaa);
        write_image((dir / (stem + ".png")).string(), frame_.width, frame_.height, a.current.pixels);
      }
    }
    for (DifferenceAccum& d : diffs) {
      const std::vector<uint8_t>& mask = masks.at(d.msaa);
      d.pool.add(compare_images(acc[d.a].current.pixels, acc[d.b].current.pixels, &mask), mask);
    }
    for (Accum& a : acc) a.previous = std::move(a.current.pixels);
    control.report(line);
  }

  json results = json::array();
  for (const Accum& a : acc) results.push_back(result_of(a, with_errors_));
  json differences = json::array();
  for (const DifferenceAccum& d : diffs) {
    const ImageErrors e = d.pool.stats();
    json item = errors_json(e);
    item["a"] = acc[d.a].entry.method_name;
    item["b"] = acc[d.b].entry.method_name;
    item["msaa"] = d.msaa;
    item["frames"] = d.pool.frames;
    item["curve"] = curve_json(e.all);
    item["seam_curve"] = curve_json(e.seam);
    differences.push_back(item);
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  json out = {{"scene", scene.name},
              {"size", std::to_string(frame_.width) + "x" + std::to_string(frame_.height)},
              {"device", runtime.device_description()},
              {"frames", frames},
              {"shard", {{"index", shard_.index}, {"count", shard_.count}, {"first_frame", range_.first}, {"end_frame", range_.end}}},
              {"reference_frames", reference_frames_},
              {"errors", with_errors_},
              {"error_frames", error_frame_list},
              {"order", "frame-major: every entry once per frame, start rotated by one each frame"},
              {"seam_mask", to_string(mask_kind_)},
              {"seam_radius", kSeamRadius},
              {"seam_pixels_per_frame", seam_pixels_per_frame},
              {"options", to_json(frame_)},
              {"wall_s", wall_s},
              {"results", results},
              {"differences", differences}};
  if (!images_dir.empty()) out["images"] = images_dir;
  if (with_errors_) {
    out["reference"] = {{"method", reference_method},
                        {"msaa", reference_msaa},
                        {"scale", kReferenceScale},
                        {"filter", "mitchell"},
                        {"filter_width", kMitchellWidth},
                        {"B", kMitchellB},
                        {"C", kMitchellC},
                        {"cached", references_cached},
                        {"rendered", references_rendered},
                        {"ms", reference_ms}};
  }
  return out;
}

}  // namespace seamcl
