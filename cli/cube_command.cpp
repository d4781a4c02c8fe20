// seamcl cube-metrics: the cube-metrics job (host/jobs/cube_metrics_job.h) from the command line:
// its flags from the job's option table, images written where --images says, a Markdown table or
// the job's JSON printed.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/jobs/cube_metrics_job.h>
#include <seamcl/memory/render_memory.h>
#include "commands.h"
#include "option_flags.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;

struct CubeArgs {
  std::unique_ptr<OptionFlags> options;
  std::optional<std::string> images;  // a directory; empty is refused, not taken for none
  bool json_out = false;
};

std::string formatted(const char* format, double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, format, v);
  return buffer;
}

void print_cube_table(const json& out) {
  const auto scientific = [](const json& v) { return formatted("%.2e", v.get<double>()); };
  std::cout << "| n | method | error mean | edge error mean | edge error p99 | first-order jump | ms | cube MiB | seam step per lod 0..log2(n) |\n"
            << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const json& r : out["results"]) {
    std::string steps;
    for (const json& s : r["seam_step"]) steps += (steps.empty() ? "" : " ") + scientific(s);
    std::cout << "| " << r["cube_size"].get<int>() << " | " << r["cube_method"].get<std::string>() << " | "
              << scientific(r["error"]["mean"]) << " | " << scientific(r["edge_error"]["mean"]) << " | "
              << scientific(r["edge_error"]["p99"]) << " | " << scientific(r["first_order_jump"]) << " | "
              << formatted("%.2f", r["ms"]["median"].get<double>()) << " | "
              << formatted("%.3f", r["cube_bytes"].get<double>() / 1048576.0) << " | " << steps << " |\n";
  }
}

int run(const CubeArgs& args, const GlobalOptions& global) {
  const std::string images_dir = given_value(args.images, "images", "leave out --images to write no images");
  const CubeMetricsJob job(args.options->request());
  // A --device that matches none: refused before any work.
  ClRuntime& runtime = cli::command_runtime(global.device);
  // Through host/assets, so that a scene file's environment may be an image file.
  const Scene scene = load_scene_source(job.frame().scene);
  const JobPlan plan = job.plan(scene);
  refuse_beyond_machine(plan.device, plan.host, runtime.info(), plan.what);
  if (!images_dir.empty()) make_output_directory(images_dir, "images");
  JobControl control;
  control.should_stop = stop_on_interrupt();
  control.device_byte_limit = device_memory_bound(runtime.info());
  const json out = job.run(runtime, scene, control, images_dir);
  if (args.json_out) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  print_cube_table(out);
  std::cout << "\nedge pixels (footprint crosses a cube edge): " << out["edge_pixels"].get<size_t>() << " of "
            << job.frame().width * job.frame().height << "\n";
  return 0;
}

}  // namespace

Command add_cube_command(CLI::App& app) {
  auto args = std::make_shared<CubeArgs>();
  CLI::App* command = app.add_subcommand(
      "cube-metrics", "Measure every cube-map seam method against the analytic environment, per cube size");
  args->options = std::make_unique<OptionFlags>(command, cube_metrics_option_table());
  command->add_option("--images", args->images, "Write each image, the reference and the cube-edge mask as PNG");
  command->add_flag("--json", args->json_out, "Print one JSON object");
  return {command, [args](const GlobalOptions& global) { return run(*args, global); }};
}

}  // namespace seamcl::cli
