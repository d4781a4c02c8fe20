// seamcl compare: the compare job (host/jobs/compare_job.h) from the command line: its flags from
// the job's option table, the reference cache's settings, images written where --images says, a
// table or the job's JSON printed.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/jobs/compare_job.h>
#include <seamcl/memory/render_memory.h>
#include "commands.h"
#include "option_flags.h"
#include "reference_cache_flags.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;

struct CompareArgs {
  std::unique_ptr<OptionFlags> options;
  ReferenceCacheFlags cache;
  std::optional<std::string> images;  // a directory; empty is refused, not taken for none
  bool no_progress = false;
  bool json_out = false;
};

// `first_reference`: the name of the reference `error` is measured against.
void print_compare_table(const json& out, const std::string& first_reference) {
  std::printf("%s %s; seam mask: pixels whose texture footprint crosses a face edge\n",
              out["scene"].get<std::string>().c_str(), out["size"].get<std::string>().c_str());
  for (const auto& [msaa, mask] : out["seam_mask"]["by_msaa"].items()) {
    std::printf("  msaa %s: %zu seam pixels (%.1f%%)\n", msaa.c_str(), mask["pixels"].get<size_t>(),
                100.0 * mask["coverage"].get<double>());
  }
  std::printf("%-9s %-10s %4s %9s %10s %10s %10s %10s %10s %6s\n", "reference", "method", "msaa", "ms", "mean",
              "seam_mean", "seam_p99", "off_mean", "off_p99", "nan");
  for (const json& r : out["results"]) {
    const json by_reference = r.contains("errors") ? r["errors"] : json{{first_reference, r["error"]}};
    for (const auto& [name, e] : by_reference.items()) {
      std::printf("%-9s %-10s %4d %9.2f %10.3e %10.3e %10.3e %10.3e %10.3e %6zu\n", name.c_str(),
                  r["method"].get<std::string>().c_str(), r["msaa"].get<int>(), r["ms"]["median"].get<double>(),
                  e["mean"].get<double>(), e["seam_mean"].get<double>(), e["seam_p99"].get<double>(),
                  e["off_seam_mean"].get<double>(), e["off_seam_p99"].get<double>(), e["nan_pixels"].get<size_t>());
    }
  }
  if (out.contains("displacement")) {
    const json& d = out["displacement"];
    std::printf("displacement %s, T %d: max gap %.3g, crack pixels %s (msaa %d)\n", d["method"].get<std::string>().c_str(),
                d["tessellation"].get<int>(), d["max_gap"].get<double>(),
                d["crack_pixels"].is_null() ? "n/a (open mesh)" : std::to_string(d["crack_pixels"].get<size_t>()).c_str(),
                out["results"].front()["msaa"].get<int>());
  }
}

int run_compare(CompareArgs& args, const GlobalOptions& global) {
  // Validate everything before any work.
  const std::string images_dir = given_value(args.images, "images", "leave out --images to write no images");
  CompareJob job(args.options->request());
  args.cache.apply(job.reference_settings());
  // A --device that matches none: refused before any work.
  ClRuntime& runtime = cli::command_runtime(global.device);
  SceneSourceOptions source;
  source.generator = job.generator_options();
  source.displacement_map = job.frame().displacement_map;
  const Scene scene = load_scene_source(job.frame().scene, job.frame().texture, source);
  // A compare this machine cannot hold is refused before it allocates, as render refuses one.
  const JobPlan plan = job.plan(scene);
  refuse_beyond_machine(plan, runtime.info());
  if (!images_dir.empty()) make_output_directory(images_dir, "images");

  JobControl control;
  if (!args.no_progress) control.progress = [](const std::string& line) { std::fprintf(stderr, "compare: %s\n", line.c_str()); };
  control.should_stop = stop_on_interrupt();
  control.device_byte_limit = device_memory_bound(runtime.info());
  const CompareRun run = job.run(runtime, scene, control);
  json out = job.result_json(run, scene, runtime.device_description(), true);
  if (!images_dir.empty()) {
    const std::vector<json> paths = write_compare_images(run, job.frame(), images_dir);
    for (size_t i = 0; i < paths.size(); ++i) out["results"][i]["images"] = paths[i];
    out["images"] = images_dir;
  }
  if (args.json_out) {
    out["estimate"] = plan.estimate_json(runtime.info().host_unified_memory);
    out["memory"] = {{"peak_rss_bytes", process_memory().peak_rss_bytes}};
    std::cout << out.dump(2) << "\n";
  } else {
    print_compare_table(out, to_string(job.reference_kinds().front()));
  }
  return 0;
}

}  // namespace

Command add_compare_command(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Render one frame with each method x MSAA rate and measure the error against the references");
  args->options = std::make_unique<OptionFlags>(cmd, compare_option_table());
  args->cache.add_to(cmd);
  cmd->add_option("--images", args->images,
                  "Write each image, an error heat map (log scale 1e-4..1), the reference and the seam mask (PNG) here");
  cmd->add_flag("--no-progress", args->no_progress, "Do not print progress lines on stderr");
  cmd->add_flag("--json", args->json_out, "Print one JSON object");
  return Command{cmd, [args](const GlobalOptions& global) { return run_compare(*args, global); }};
}

}  // namespace seamcl::cli
