// seamcl compare: renders one frame with every method x MSAA rate, measures each against the
// paper's reference (host/eval/reference.h) and prints the errors (host/eval/metrics.h) with the timings.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/memory/compare_memory.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/io/image_io.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "commands.h"
#include "measure_args.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

struct CompareArgs : MeasureArgs {
  std::optional<int> frame, frames;
  std::optional<std::string> constant_color;  // "r,g,b" linear: paint every face this colour; empty is refused
  std::optional<std::string> images;  // a directory; empty is refused, not taken for none
  int repeat = 3;
  std::vector<std::string> references;  // --reference, repeatable, each a name or a comma list
  bool no_progress = false;
};

glm::vec3 parse_color(const std::string& text) {
  const std::vector<std::string> parts = split_list(text, "constant_color");
  if (parts.size() != 3) throw InputError("constant_color", "must be r,g,b, got '" + text + "'");
  glm::vec3 c;
  for (int i = 0; i < 3; ++i) {
    size_t used = 0;
    float v = -1.0f;
    try {
      v = std::stof(parts[static_cast<size_t>(i)], &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != parts[static_cast<size_t>(i)].size() || !(v >= 0.0f && v <= 1.0f)) {
      throw InputError("constant_color", "each component must be a number in [0, 1], got '" + text + "'");
    }
    c[i] = v;
  }
  return c;
}

json base_request(const CompareArgs& a) {
  json request = measure_request(a);
  if (a.frame) request["frame"] = *a.frame;
  if (a.frames) request["frames"] = *a.frames;
  return request;
}

// The names of --reference (repeatable, each a name or a comma list); paper when none is given.
std::vector<ReferenceKind> reference_kinds(const std::vector<std::string>& given) {
  std::vector<std::string> names;
  for (const std::string& text : given)
    for (const std::string& name : split_list(text, "reference")) names.push_back(name);
  if (names.empty()) names.push_back("paper");
  return parse_reference_kinds(names);
}

int run_compare(const CompareArgs& args, const GlobalOptions& global) {
  // Validate everything before any work.
  const std::string images_dir = given_value(args.images, "images", "leave out --images to write no images");
  const json base = base_request(args);
  const RenderOptions frame = parse_render_options(base);
  const std::vector<std::string> methods = split_list(args.methods, "methods");
  const std::vector<int> rates = parse_int_list(args.msaa, "msaa");
  const std::vector<MethodEntry> entries = method_entries(base, methods, rates);
  if (args.repeat < 1 || args.repeat > 1000) throw InputError("repeat", "must be in 1..1000");
  // Ignored otherwise: without --frame the scene's own camera renders.
  if (args.frames && !args.frame) throw InputError("frames", "--frames is ignored without --frame: leave it out");
  const std::vector<ReferenceKind> kinds = reference_kinds(args.references);
  ReferenceSettings ref_settings = reference_settings(args);
  (void)reference_render_options(frame, ref_settings);  // size and reference settings checked now
  GeneratorOptions generator_options;
  generator_options.tint = frame.tint;
  if (args.constant_color) generator_options.constant_color = parse_color(*args.constant_color);

  SceneSourceOptions source;
  source.generator = generator_options;
  source.generator.defer_textures = true;  // each Renderer packs face by face: no float copy of the textures
  ClRuntime runtime(global.device);  // a --device that matches none: refused before any work
  const Scene scene = load_scene_source(frame.scene, frame.texture, source);
  const Camera camera = frame.frame ? orbit_camera(scene, *frame.frame, frame.frames) : scene.camera;
  // A compare this machine cannot hold is refused before it allocates, as render refuses one.
  const bool seamless = std::find(kinds.begin(), kinds.end(), ReferenceKind::Seamless) != kinds.end();
  const CompareMemory memory = compare_memory(scene_sizes(scene), frame, entries, ref_settings, kinds,
                                              seamless ? std::optional(seamless_scene_sizes(scene)) : std::nullopt);
  refuse_beyond_machine(memory.device_shares, memory.host_shares, runtime.info(), "this compare");
  if (ref_settings.use_cache) ref_settings.scene_hash = scene_content_hash(scene);  // once for every reference kind
  if (!images_dir.empty()) make_output_directory(images_dir, "images");
  auto progress = [&](const std::string& line) {
    if (!args.no_progress) std::fprintf(stderr, "compare: %s\n", line.c_str());
  };

  Renderer renderer(runtime);
  limit_to_machine(renderer, runtime.info());
  renderer.load_scene(scene, frame.texels);
  const ComparisonTargets targets =
      prepare_targets(runtime, renderer, camera, frame, entries, ref_settings, kinds, progress);
  if (!images_dir.empty()) {
    for (const ReferenceImage& reference : targets.high_res) {
      const std::string name = reference.kind == ReferenceKind::Paper ? "reference" : "reference_" + to_string(reference.kind);
      write_image((fs::path(images_dir) / (name + ".png")).string(), reference.width, reference.height,
                  reference.pixels);
    }
    for (const auto& [msaa, reference] : targets.seamless_by_rate) {
      write_image((fs::path(images_dir) / ("reference_seamless_msaa" + std::to_string(msaa) + ".png")).string(),
                  reference.width, reference.height, reference.pixels);
    }
    for (const auto& [msaa, mask] : targets.masks) {
      std::vector<glm::vec4> mask_image(mask.size());
      // Seams white, mesh boundary rims grey, the rest black.
      for (size_t i = 0; i < mask.size(); ++i)
        mask_image[i] = mask[i] == SEAMCL_MASK_SEAM       ? glm::vec4(1)
                        : mask[i] == SEAMCL_MASK_BOUNDARY ? glm::vec4(0.2f, 0.2f, 0.2f, 1.0f)
                                                          : glm::vec4(0, 0, 0, 1);
      write_image((fs::path(images_dir) / ("seam_mask_msaa" + std::to_string(msaa) + ".png")).string(), frame.width,
                  frame.height, mask_image);
    }
  }

  json results = json::array();
  const TargetsFor targets_for = [&](const MethodEntry& entry) { return targets.for_entry(entry); };
  for (const EntryResult& measured :
       compare_methods(renderer, scene, camera, entries, targets_for, args.repeat, {}, progress)) {
    json item = compare_result_json(measured);
    if (!images_dir.empty()) {
      const RenderResult& result = measured.last;
      const std::string stem = measured.entry.method_name + "_msaa" + std::to_string(measured.entry.options.msaa);
      const fs::path image = fs::path(images_dir) / (stem + ".png");
      const fs::path heat = fs::path(images_dir) / (stem + "_error.png");
      write_image(image.string(), result.width, result.height, result.pixels);
      write_image(heat.string(), result.width, result.height, error_heatmap(measured.errors->distance));
      item["images"] = {{"image", image.string()}, {"error", heat.string()}};
    }
    results.push_back(item);
  }

  // Watertightness of the displaced surface at this camera (docs/displacement.md), at the first rate.
  json displacement;
  if (frame.displacement) {
    progress("displacement: gap and crack pixels of " + to_string(*frame.displacement));
    displacement = measure_displacement(runtime, scene, camera, entries.front().options, 0, 0, renderer.device_byte_limit())
                       .to_json();
  }

  const json summary = targets.summary_json(entries.front().options.msaa, true);
  const std::string size = std::to_string(frame.width) + "x" + std::to_string(frame.height);
  if (args.json_out) {
    json out = {{"scene", scene.name}, {"size", size}, {"device", runtime.device_description()}};
    out.update(summary);
    out["options"] = to_json(frame);
    out["results"] = results;
    if (frame.frame) {
      out["frame"] = *frame.frame;
      out["frames"] = frame.frames;
    }
    if (!images_dir.empty()) out["images"] = images_dir;
    if (!displacement.is_null()) out["displacement"] = displacement;
    const bool unified = runtime.info().host_unified_memory;
    out["estimate"] = estimate_json(memory.device_shares, memory.host_shares, memory.process_shares(unified), unified);
    out["memory"] = {{"peak_rss_bytes", process_memory().peak_rss_bytes}};
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("%s %s; seam mask: pixels whose texture footprint crosses a face edge\n", scene.name.c_str(), size.c_str());
    for (const auto& [msaa, mask] : summary["seam_mask"]["by_msaa"].items()) {
      std::printf("  msaa %s: %zu seam pixels (%.1f%%)\n", msaa.c_str(), mask["pixels"].get<size_t>(),
                  100.0 * mask["coverage"].get<double>());
    }
    std::printf("%-9s %-10s %4s %9s %10s %10s %10s %10s %10s %6s\n", "reference", "method", "msaa", "ms", "mean",
                "seam_mean", "seam_p99", "off_mean", "off_p99", "nan");
    for (const json& r : results) {
      json by_reference = r.contains("errors") ? r["errors"] : json{{to_string(kinds.front()), r["error"]}};
      for (const auto& [name, e] : by_reference.items()) {
        std::printf("%-9s %-10s %4d %9.2f %10.3e %10.3e %10.3e %10.3e %10.3e %6zu\n", name.c_str(),
                    r["method"].get<std::string>().c_str(), r["msaa"].get<int>(), r["ms"]["median"].get<double>(),
                    e["mean"].get<double>(), e["seam_mean"].get<double>(), e["seam_p99"].get<double>(),
                    e["off_seam_mean"].get<double>(), e["off_seam_p99"].get<double>(), e["nan_pixels"].get<size_t>());
      }
    }
    if (!displacement.is_null()) {
      std::printf("displacement %s, T %d: max gap %.3g, crack pixels %s (msaa %d)\n",
                  displacement["method"].get<std::string>().c_str(), displacement["tessellation"].get<int>(),
                  displacement["max_gap"].get<double>(),
                  displacement["crack_pixels"].is_null() ? "n/a (open mesh)"
                                                         : std::to_string(displacement["crack_pixels"].get<size_t>()).c_str(),
                  entries.front().options.msaa);
    }
  }
  return 0;
}

}  // namespace

Command add_compare_command(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Render one frame with each method x MSAA rate and measure the error against the paper's reference");
  add_measure_options(cmd, *args, "discard,clamp");
  cmd->add_option("--frame", args->frame, "Orbit frame K (0-based) of --frames");
  cmd->add_option("--frames", args->frames, "Frames in the orbit [60]");
  cmd->add_option("--constant-color", args->constant_color,
                  "Paint every face one linear colour r,g,b (each 0..1): seams then carry no texture error");
  cmd->add_option("--images", args->images,
                  "Write each image, an error heat map (log scale 1e-4..1), the reference and the seam mask (PNG) here");
  cmd->add_option("--repeat", args->repeat, "Timed renders per method and rate; ms reports median, min, max [3]");
  cmd->add_option("--reference", args->references,
                  "Reference(s) to measure against, repeatable or a comma list: paper (traverse at 8x, Mitchell), box "
                  "(the same, box downsample), analytic (the texture function at every 8x subsample, Mitchell), "
                  "seamless (a planar grid of equal faces as one texture, at the measured rate); the first is `error`'s "
                  "[paper]");
  cmd->add_flag("--no-progress", args->no_progress, "Do not print progress lines on stderr");
  return Command{cmd, [args](const GlobalOptions& global) { return run_compare(*args, global); }};
}

}  // namespace seamcl::cli
