// seamcl bench: an orbit of N frames, every method x MSAA rate rendered on each frame (frame-major,
// so machine noise falls on all methods alike), timed from OpenCL profiling events and measured
// against each frame's reference (host/eval/reference.h, cached) on every K-th frame. Also NaN/Inf
// pixels per frame, temporal stability near seams, memory per method, and the discard-traverse
// difference curves of the paper's Figure 5 (left).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/batch/bench_merge.h>
#include <seamcl/batch/scaling_sweep.h>
#include <seamcl/batch/shard.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/memory/bench_memory.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/options/render_options.h>
#include <seamcl/batch/bench_merge.h>
#include <seamcl/batch/scaling_sweep.h>
#include <seamcl/batch/shard.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "commands.h"
#include "measure_args.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;

struct BenchArgs : MeasureArgs {
  int frames = 60;
  int reference_frames = 1;
  bool no_errors = false;
  std::string shard = "1/1";  // part K of N of the orbit's frames (host/batch/shard.h)
  bool check_only = false;    // validate the options and the scene, render nothing
  std::string seam_mask = "band";  // parse_seam_mask_kind: band (the committed results') or footprint (compare's)
  std::optional<std::string> sweep;  // scaling sweeps instead of the orbit (host/batch/scaling_sweep.h); empty is refused
  int sweep_repeats = 5;
};

json base_request(const BenchArgs& a) {
  json request = measure_request(a);
  request["frame"] = 0;
  request["frames"] = a.frames;  // parse_render_options checks the range and names "frames"
  return request;
}

size_t count_nonfinite(const std::vector<glm::vec4>& pixels) {
  size_t n = 0;
  for (const glm::vec4& p : pixels) {
    if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b)) ++n;
  }
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
  std::vector<StageTimes> ms;            // per frame
  std::vector<size_t> nan_per_frame;     // non-finite pixels of each frame's image
  Pool errors;
  json error_per_frame = json::array();
  std::vector<glm::vec4> previous;       // last frame's image, for temporal stability
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

class Progress {
 public:
  Progress(size_t total, bool quiet) : total_(total), tty_(!quiet && isatty(STDERR_FILENO) == 1), quiet_(quiet) {}
  void step(int frame, int frames, const std::string& what) {
    ++done_;
    if (!tty_) return;
    const int width = 30;
    const int filled = static_cast<int>(static_cast<double>(width) * static_cast<double>(done_) /
                                        static_cast<double>(std::max<size_t>(total_, 1)));
    std::fprintf(stderr, "\r[%s%s] %3d%% frame %d/%d %-24s", std::string(static_cast<size_t>(filled), '#').c_str(),
                 std::string(static_cast<size_t>(width - filled), '.').c_str(),
                 static_cast<int>(100.0 * static_cast<double>(done_) / static_cast<double>(std::max<size_t>(total_, 1))),
                 frame + 1, frames, what.c_str());
    std::fflush(stderr);
  }
  // One plain line (not on a terminal): a frame's entries and their times.
  void line(const std::string& text) {
    if (quiet_ || tty_) return;
    std::fprintf(stderr, "%s\n", text.c_str());
  }
  void finish() {
    if (tty_) std::fprintf(stderr, "\n");
  }

 private:
  size_t total_, done_ = 0;
  bool tty_, quiet_;
};

// --sweep: the scaling sweeps (one JSON, the chart's input: examples/scaling_chart.py).
int run_sweep(const BenchArgs& args, const CLI::App& command, const GlobalOptions& global) {
  const std::vector<SweepAxis> axes = parse_sweep(*args.sweep);
  if (std::none_of(axes.begin(), axes.end(), sweep_reads_base_size)) {
    refuse_ignored_options(command, {"--size"}, "with --sweep " + *args.sweep + " (its points have sizes of their own)");
  }
  SweepSettings settings;
  settings.base = parse_render_options(measure_request(args));
  settings.methods = split_list(args.methods, "methods");
  settings.repeats = args.sweep_repeats;
  settings.make_scene = [&](const GeneratorOptions& generator) {
    SceneSourceOptions source;
    source.generator = generator;
    return load_scene_source(settings.base.scene, settings.base.texture, source);
  };
  settings.progress = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };  // stdout stays JSON
  validate_sweep(axes, settings);
  ClRuntime runtime(global.device);
  // A sweep this machine cannot hold is refused before its first point renders (the run itself
  // would refuse only the group that cannot be held, after rendering those before it), and by
  // --check, as the orbit's is: making the points' scenes with their textures deferred renders
  // and bakes nothing.
  refuse_sweeps_beyond_machine(axes, settings, runtime.info());
  if (args.check_only) {
    std::printf("sweep options valid: %s\n", args.sweep->c_str());
    return 0;
  }
  settings.device_byte_limit = device_memory_bound(runtime.info());  // as limit_to_machine holds the orbit's Renderers
  const json out = run_scaling_sweeps(runtime, axes, settings);
  if (args.json_out) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  for (const json& sweep : out.at("sweeps")) {
    for (const json& r : sweep.at("ratios")) {
      std::printf("%-7s %-10s x %8.2f -> time x %7.3f%s\n", sweep.at("axis").get<std::string>().c_str(),
                  r.at("method").get<std::string>().c_str(), r.at("x_ratio").get<double>(), r.at("time_ratio").get<double>(),
                  r.at("met").is_null() ? "" : (r.at("met").get<bool>() ? " (target met)" : " (target missed)"));
    }
  }
  return 0;
}

// The orbit's options, which a sweep never reads. (The reference cache's options are not refused:
// a wrapper may pass them to every bench, and without references they do nothing.)
const std::vector<std::string> kOrbitOnlyOptions = {"--msaa", "--frames", "--no-errors", "--reference-frames",
                                                     "--reference-method", "--reference-msaa", "--shard", "--seam-mask"};

int run_bench(const BenchArgs& args, const CLI::App& command, const GlobalOptions& global) {
  if (args.sweep) {
    if (args.sweep->empty()) throw InputError("sweep", "must not be empty (leave out --sweep to run the orbit)");
    refuse_ignored_options(command, kOrbitOnlyOptions, "with --sweep (a sweep renders no orbit)");
    (void)reference_settings(args);  // the cache options, unused here, are still checked (an empty --cache is a mistake)
    return run_sweep(args, command, global);
  }
  refuse_ignored_options(command, {"--sweep-repeats"}, "without --sweep");
  if (args.no_errors) {
    refuse_ignored_options(command, {"--reference-frames", "--reference-method", "--reference-msaa"},
                           "with --no-errors (no reference is rendered)");
  }
  // Validate everything before any work.
  const json base = base_request(args);
  const RenderOptions frame = parse_render_options(base);
  const std::vector<std::string> methods = split_list(args.methods, "methods");
  const std::vector<int> rates = parse_int_list(args.msaa, "msaa");
  std::vector<MethodEntry> entries = method_entries(base, methods, rates);
  if (args.reference_frames < 1) throw InputError("reference_frames", "must be at least 1");
  const bool with_errors = !args.no_errors;
  ReferenceSettings ref_settings = reference_settings(args);
  if (with_errors) (void)reference_render_options(frame, ref_settings);  // size and settings checked now
  const Shard shard = parse_shard(args.shard);
  const FrameRange range = shard_frames(shard, frame.frames);
  const std::optional<SeamMaskKind> mask_kind = parse_seam_mask_kind(args.seam_mask);
  if (!mask_kind) {
    throw InputError("seam_mask", "unknown mask '" + args.seam_mask + "' (known: " + join_names(seam_mask_kind_names()) + ")");
  }

  GeneratorOptions generator_options;
  generator_options.tint = frame.tint;
  SceneSourceOptions source;
  source.generator = generator_options;
  source.generator.defer_textures = true;  // each Renderer packs face by face: no float copy of the textures
  const Scene scene = load_scene_source(frame.scene, frame.texture, source);
  int error_frames = 0;
  for (int k = range.first; k < range.end; ++k) error_frames += with_errors && k % args.reference_frames == 0 ? 1 : 0;
  const auto wall_start = std::chrono::steady_clock::now();
  ClRuntime runtime(global.device);
  std::vector<DifferenceAccum> diffs = discard_traverse_pairs(entries);
  // A bench this machine cannot hold is refused before it allocates, as render and compare refuse
  // theirs. An estimate, so --check makes it too: a batch's pre-check (scripts/farm) must not pass
  // a part that would then be refused.
  const BenchMemory memory =
      bench_memory(scene_sizes(scene), frame, entries, ref_settings, {with_errors, error_frames, diffs.size(), range.size()});
  refuse_beyond_machine(memory.device, memory.host, runtime.info(), "this bench");
  if (args.check_only) {
    std::printf("bench options valid: %s, part %s: frames %d..%d of %d\n", scene.name.c_str(), to_string(shard).c_str(),
                range.first, range.end - 1, frame.frames);
    return 0;
  }
  // Once, not per reference frame: hashing bakes every face.
  if (with_errors && ref_settings.use_cache) ref_settings.scene_hash = scene_content_hash(scene);

  // One renderer for the face maps and references, one per method (a method's packing, e.g. the
  // guard bands, then stays uploaded instead of being rebuilt on every switch).
  Renderer base_renderer(runtime);
  limit_to_machine(base_renderer, runtime.info());
  base_renderer.load_scene(scene, frame.texels);
  std::map<std::string, std::unique_ptr<Renderer>> renderers;
  std::vector<Accum> acc(entries.size());
  for (size_t i = 0; i < entries.size(); ++i) {
    std::unique_ptr<Renderer>& r = renderers[entries[i].method_name];
    if (!r) {
      r = std::make_unique<Renderer>(runtime);
      limit_to_machine(*r, runtime.info());
      r->load_scene(scene, frame.texels);
    }
    acc[i].entry = entries[i];
    acc[i].renderer = r.get();
    r->warm_up(entries[i].options);
  }

  const int frames = frame.frames;
  const bool lead_in = range.first > 0;
  Progress progress(static_cast<size_t>(range.size() + (lead_in ? 1 : 0)) * entries.size() +
                        static_cast<size_t>(error_frames),
                    false);
  std::string reference_method;
  int reference_msaa = 0, references_cached = 0, references_rendered = 0;
  double reference_ms = 0;
  std::vector<int> error_frame_list;
  std::vector<size_t> seam_pixels_per_frame;

  // A part that starts later renders the frame before its first (untimed, unmeasured), so the
  // temporal pair across its first frame is measured as an unsharded run measures it.
  if (lead_in) {
    const int k = range.first - 1;
    const Camera camera = orbit_camera(scene, k, frames);
    for (Accum& a : acc) {
      MethodEntry entry = a.entry;
      entry.options.frame = k;
      a.previous = a.renderer->render(camera, entry.options).pixels;
      progress.step(k, frames, "lead-in " + entry.method_name + " x" + std::to_string(entry.options.msaa));
    }
  }
  for (int k = range.first; k < range.end; ++k) {
    RenderOptions frame_options = frame;
    frame_options.frame = k;
    const Camera camera = orbit_camera(scene, k, frames);
    // The mask per rate: one band (0/1) for every rate, or each rate's footprint mask (0/1/2).
    std::map<int, std::vector<uint8_t>> masks;
    if (*mask_kind == SeamMaskKind::Band) {
      const std::vector<uint8_t> band = seam_mask(render_face_map(base_renderer, camera, frame_options));
      for (const MethodEntry& e : entries) masks[e.options.msaa] = band;
    } else {
      for (const MethodEntry& e : entries) {
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
    std::optional<ReferenceImage> reference;
    if (with_errors && k % args.reference_frames == 0) {
      reference = reference_image(base_renderer, camera, frame_options, ref_settings);
      reference_method = reference->method;
      reference_msaa = reference->msaa;
      reference->from_cache ? ++references_cached : ++references_rendered;
      reference_ms += reference->render_ms;
      error_frame_list.push_back(k);
      progress.step(k, frames, reference->from_cache ? "reference (cached)" : "reference");
    }
    std::string line = "bench: frame " + std::to_string(k + 1) + "/" + std::to_string(frames) +
                       (reference ? (reference->from_cache ? " [reference cached]" : " [reference rendered]") : "") +
                       " ms:";
    // Interleaved: every entry once per frame, starting one further along each frame so that no
    // entry always runs first (or right after a reference render).
    for (size_t n = 0; n < entries.size(); ++n) {
      const size_t i = (n + static_cast<size_t>(k)) % entries.size();
      Accum& a = acc[i];
      MethodEntry entry = a.entry;
      entry.options.frame = k;
      const std::vector<uint8_t>& mask = masks.at(entry.options.msaa);
      EntryResult r = measure_entry(*a.renderer, camera, entry, 1, reference ? &reference->pixels : nullptr, &mask);
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
      progress.step(k, frames, entry.method_name + " x" + std::to_string(entry.options.msaa));
    }
    for (size_t i = 0; i < entries.size(); ++i) {
      Accum& a = acc[i];
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
    for (DifferenceAccum& d : diffs) {
      const std::vector<uint8_t>& mask = masks.at(d.msaa);
      d.pool.add(compare_images(acc[d.a].current.pixels, acc[d.b].current.pixels, &mask), mask);
    }
    for (Accum& a : acc) a.previous = std::move(a.current.pixels);
    progress.line(line);
  }
  progress.finish();

  json results = json::array();
  for (const Accum& a : acc) {
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
    ms["stages"] = {{"setup", median_of(setup)},     {"binning", median_of(binning)}, {"raster", median_of(raster)},
                    {"shade", median_of(shade)},     {"readback", median_of(readback)}};
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
    results.push_back(item);
  }
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
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  const std::string size = std::to_string(frame.width) + "x" + std::to_string(frame.height);
  if (args.json_out) {
    json out = {{"scene", scene.name},
                {"size", size},
                {"device", runtime.device_description()},
                {"frames", frames},
                {"shard", {{"index", shard.index}, {"count", shard.count}, {"first_frame", range.first}, {"end_frame", range.end}}},
                {"reference_frames", args.reference_frames},
                {"errors", with_errors},
                {"error_frames", error_frame_list},
                {"order", "frame-major: every entry once per frame, start rotated by one each frame"},
                {"seam_mask", to_string(*mask_kind)},
                {"seam_radius", kSeamRadius},
                {"seam_pixels_per_frame", seam_pixels_per_frame},
                {"options", to_json(frame)},
                {"wall_s", wall_s},
                {"results", results},
                {"differences", differences}};
    if (with_errors) {
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
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("%s %s, %d frames (orbit), errors %s; %.1f s\n", scene.name.c_str(), size.c_str(), frames,
                with_errors ? ("on every " + std::to_string(args.reference_frames) + ". frame vs " + reference_method +
                               " 8x reference").c_str()
                            : "off",
                wall_s);
    if (!shard.whole()) {
      std::printf("part %s: frames %d..%d (seamcl merge combines the parts' --json output)\n", to_string(shard).c_str(),
                  range.first, range.end - 1);
    }
    std::printf("%-10s %4s %9s %9s %9s %7s %5s %10s %10s %10s %12s\n", "method", "msaa", "ms_med", "ms_min", "ms_max",
                "spread", "nan", "mean", "seam_mean", "temporal", "tex_bytes");
    for (const json& r : results) {
      const bool e = r.contains("error");
      std::printf("%-10s %4d %9.3f %9.3f %9.3f %7.3f %5zu %10.3e %10.3e %10.3e %12zu\n",
                  r["method"].get<std::string>().c_str(), r["msaa"].get<int>(), r["ms"]["median"].get<double>(),
                  r["ms"]["min"].get<double>(), r["ms"]["max"].get<double>(), r["ms"]["spread"].get<double>(),
                  r["nan_pixels"].get<size_t>(), e ? r["error"]["mean"].get<double>() : 0.0,
                  e ? r["error"]["seam_mean"].get<double>() : 0.0, r["temporal"]["seam_mean"].get<double>(),
                  r["texture_bytes"].get<size_t>());
    }
    for (const json& d : differences) {
      std::printf("||%s - %s|| at %dx: mean %.3e, seam_mean %.3e, p99 %.3e\n", d["a"].get<std::string>().c_str(),
                  d["b"].get<std::string>().c_str(), d["msaa"].get<int>(), d["mean"].get<double>(),
                  d["seam_mean"].get<double>(), d["p99"].get<double>());
    }
  }
  return 0;
}

}  // namespace

Command add_bench_command(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Time every method x MSAA rate side by side over an orbit of frames, with errors against the reference");
  add_measure_options(cmd, *args, "discard,traverse");
  cmd->add_option("--frames", args->frames, "Frames of the camera orbit; frame k uses orbit frame k of N [60]");
  cmd->add_flag("--no-errors", args->no_errors, "Skip the references and errors (times, NaN counts, temporal only)");
  cmd->add_option("--reference-frames", args->reference_frames,
                  "Measure errors on every K-th frame only (frames 0, K, 2K, ...): each needs an 8x reference [1]");
  cmd->add_option("--shard", args->shard,
                  "Run part K (1-based) of N: a contiguous block of the orbit's frames; `seamcl merge` combines "
                  "the parts' JSON into the unsharded run's [1/1]");
  cmd->add_option("--seam-mask", args->seam_mask,
                  "The seam pixels errors are pooled over: " + join_names(seam_mask_kind_names()) +
                      " (footprint: each rate's pixels whose filter footprint crosses a shared edge, as compare "
                      "measures; band: within 2 px of a face boundary, one mask for every rate) [band]");
  cmd->add_flag("--check", args->check_only,
                "Validate the options (and the scene), refuse a bench this machine cannot hold, and exit without rendering");
  cmd->add_option("--sweep", args->sweep,
                  "Scaling sweeps instead of the orbit: a comma list of " + join_names(sweep_axis_names()) +
                      ", or all (time against image pixels, paper's face count at equal pixels, MSAA rate, texels)");
  cmd->add_option("--sweep-repeats", args->sweep_repeats, "Timed renders per method and sweep point (median) [5]");
  return Command{cmd, [args, cmd](const GlobalOptions& global) { return run_bench(*args, *cmd, global); }};
}

}  // namespace seamcl::cli
