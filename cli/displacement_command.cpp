// seamcl displacement-metrics: the displacement-metrics job (host/jobs/displacement_metrics_job.h)
// from the command line: its flags from the job's option table, --displacement-map (a local file)
// attached to the scene, images written where --images says, a Markdown table or the job's JSON.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/jobs/displacement_metrics_job.h>
#include <seamcl/memory/render_memory.h>
#include "commands.h"
#include "option_flags.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;

struct DisplacementArgs {
  std::unique_ptr<OptionFlags> options;
  std::optional<std::string> displacement_map;  // a .ptx for an .obj scene; empty is refused, not taken for none
  std::optional<std::string> images;            // a directory; empty is refused, not taken for none
  bool json_out = false;
  bool no_progress = false;
};

void print_displacement_table(const json& out) {
  std::printf("%s %s msaa %d, crack pixels over %d orbit frames%s\n", out["scene"].get<std::string>().c_str(),
              out["size"].get<std::string>().c_str(), out["msaa"].get<int>(), out["frames"].get<int>(),
              out["closed_mesh"].get<bool>() ? "" : " (open mesh: not counted)");
  std::printf("| method | T | max gap | differing pairs | normal gap | crack pixels | samples | extra bytes | tessellate ms | frame ms |\n"
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  for (const json& r : out["results"]) {
    const std::string cracks = r["crack_pixels"].is_null() ? "n/a" : std::to_string(r["crack_pixels"].get<size_t>());
    std::printf("| %s | %d | %.4g | %zu | %.4g | %s | %zu | %zu | %.2f | %.2f |\n", r["method"].get<std::string>().c_str(),
                r["tessellation"].get<int>(), r["max_gap"].get<double>(), r["differing_pairs"].get<size_t>(),
                r["max_normal_gap"].get<double>(), cracks.c_str(), r["samples"].get<size_t>(), r["extra_bytes"].get<size_t>(),
                r["tessellate_ms"].get<double>(), r["frame_ms"].get<double>());
  }
}

int run(const DisplacementArgs& args, const GlobalOptions& global) {
  // Validate everything before any work.
  const std::string images_dir = given_value(args.images, "images", "leave out --images to write no images");
  const std::string displacement_map =
      given_value(args.displacement_map, "displacement_map", "leave out --displacement-map to use the scene's own maps");
  const json request = args.options->request();
  const DisplacementMetricsJob job(request);
  // A --device that matches none: refused before any work.
  ClRuntime& runtime = cli::command_runtime(global.device);
  Scene scene = load_scene_source(job.frame().scene);
  if (!displacement_map.empty()) attach_ptex_displacement(scene, displacement_map);
  const JobPlan plan = job.plan(scene);
  refuse_beyond_machine(plan.device, plan.host, runtime.info(), plan.what);
  if (!images_dir.empty()) make_output_directory(images_dir, "images");
  JobControl control;
  if (!args.no_progress)
    control.progress = [](const std::string& line) { std::fprintf(stderr, "displacement-metrics: %s\n", line.c_str()); };
  control.should_stop = stop_on_interrupt();
  control.device_byte_limit = device_memory_bound(runtime.info());
  json out = job.run(runtime, scene, control, images_dir);
  if (!displacement_map.empty()) out["displacement_map"] = displacement_map;
  if (args.json_out) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  // The frames asked for, where crack_frames is 0 on an open mesh.
  out["frames"] = request.value("frames", find_option(displacement_metrics_option_table(), "frames")->default_value.get<int>());
  print_displacement_table(out);
  return 0;
}

}  // namespace

Command add_displacement_command(CLI::App& app) {
  auto args = std::make_shared<DisplacementArgs>();
  CLI::App* command = app.add_subcommand(
      "displacement-metrics",
      "Measure every displacement method at every tessellation level: exact gap, crack pixels over an orbit, time, extra bytes");
  args->options = std::make_unique<OptionFlags>(command, displacement_metrics_option_table());
  command->add_option("--displacement-map", args->displacement_map, "A .ptx of displacement for an .obj --scene (face i takes face i)");
  command->add_option("--images", args->images, "Write frame 0 of each entry as PNG (closed meshes: back faces, seen through cracks, magenta)");
  command->add_flag("--json", args->json_out, "Print one JSON object");
  command->add_flag("--no-progress", args->no_progress, "Do not print progress lines on stderr");
  return {command, [args](const GlobalOptions& global) { return run(*args, global); }};
}

}  // namespace seamcl::cli
