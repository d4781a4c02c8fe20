// seamcl: the command-line front end. Each subcommand gathers its flags, hands them to the
// library (the same option parser the HTTP service uses) and prints a result.
// Exit codes: 0 success, 2 bad usage or input (one line naming the field), 1 other failures.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <future>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include <seamcl/io/image_io.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/version.h>
#include "commands.h"
#include "option_flags.h"

namespace {

using nlohmann::json;
using namespace seamcl;

struct RenderArgs {
  std::unique_ptr<cli::OptionFlags> options;
  std::optional<std::string> output;
  bool json_out = false;
};

int run_render(const RenderArgs& args, const std::string& device) {
  // Validate everything before any work, so bad input changes nothing.
  const std::string output = cli::given_value(args.output, "output", "leave out -o to render and time only");
  const RenderJob job(args.options->request());
  const RenderOptions& options = job.options();
  if (!output.empty()) {
    image_format_for_path(output, "output");
    cli::check_output_parent(output, "output");
  }
  if (args.options->given("crack_orbit") && !args.json_out)
    throw InputError("crack_orbit", "counts the cracks of a displaced render in --json's displacement block: give --json too");

  // A --device that matches none is bad input too: refused before any work.
  ClRuntime& runtime = cli::command_runtime(device);
  const auto scene_start = std::chrono::steady_clock::now();
  SceneSourceOptions source;
  source.generator = job.generator_options();
  source.displacement_map = options.displacement_map;
  Scene scene = load_scene_source(options.scene, options.texture, source);
  const double scene_ms = ms_since(scene_start);

  // A render this machine cannot hold is refused before it allocates.
  const JobPlan plan = job.plan(scene);
  refuse_beyond_machine(plan, runtime.info());
  // The render's kernels build while the scene packs.
  const std::future<void> programs = build_programs_ahead(runtime, scene, {{options, false}});
  Renderer renderer(runtime);
  limit_to_machine(renderer, runtime.info());
  // Handed over, not copied: image faces' float chains exist once (scene() reads them back).
  renderer.load_scene(std::move(scene), options.texels);
  JobControl control;
  control.should_stop = cli::stop_on_interrupt();
  control.device_byte_limit = renderer.device_byte_limit();
  const RenderRun run = job.run(runtime, renderer, renderer.scene(), control, args.json_out);
  if (!output.empty()) write_image(output, run.last.width, run.last.height, run.last.pixels);

  if (args.json_out) {
    json out = job.result_json(run, renderer, runtime.device_description());
    out["kernel_build_ms"] = runtime.program_build_ms();
    out["scene_ms"] = scene_ms;
    out["estimate"] = plan.estimate_json(runtime.info().host_unified_memory);
    if (!output.empty()) out["output"] = output;
    out["memory"] = to_json(measure_memory(renderer));  // peak over everything above
    std::cout << out.dump(2) << "\n";
  } else {
    const StageTimes& ms = run.median;
    std::printf("%s: %dx%d msaa %d, %.2f ms (setup %.2f, binning %.2f, raster %.2f, shade %.2f), %u fragments%s%s\n",
                renderer.scene().name.c_str(), run.last.width, run.last.height, options.msaa, ms.total, ms.setup,
                ms.binning, ms.raster, ms.shade, run.last.stats.fragments, output.empty() ? "" : " -> ", output.c_str());
  }
  return 0;
}

int run_scenes(bool json_out) {
  if (json_out) {
    json list = json::array();
    for (const GeneratorInfo& g : scene_generators()) list.push_back({{"name", g.name}, {"description", g.description}});
    std::cout << list.dump(2) << "\n";
  } else {
    for (const GeneratorInfo& g : scene_generators()) std::printf("%-8s %s\n", g.name.c_str(), g.description.c_str());
  }
  return 0;
}

int run_devices(const std::string& device) {
  const std::vector<DeviceInfo> devices = list_devices();
  if (devices.empty()) {
    std::printf("no OpenCL devices\n");
    return 1;
  }
  std::string chosen;
  try {
    chosen = ClRuntime(device).info().name;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "seamcl: %s\n", e.what());
  }
  for (const DeviceInfo& d : devices) {
    std::printf("%s %s [%s] %s, %d compute units (%s)\n", d.name == chosen ? "*" : " ", d.name.c_str(), d.type.c_str(),
                d.version.c_str(), d.compute_units, d.platform.c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  seamcl::set_allocator_thresholds();  // freed textures leave the process, faces' chains are reused (render_memory.h)
  CLI::App app{"seamcl: render per-face textured scenes with OpenCL and compare texture seam methods"};
  app.require_subcommand(0, 1);
  std::optional<std::string> given_device;
  app.add_option("--device", given_device, "OpenCL device: a substring of 'platform device' (default $SEAMCL_DEVICE, else the first GPU, else the first CPU)");
  bool show_version = false;
  app.add_flag("--version", show_version, "Print the version and the OpenCL device, then exit");

  RenderArgs render_args;
  CLI::App* render = app.add_subcommand("render", "Render one frame of a scene to PNG (sRGB 8-bit) or EXR (linear)");
  render_args.options = std::make_unique<cli::OptionFlags>(render, render_job_option_table());
  render->add_option("-o,--output", render_args.output, "Output image, .png or .exr (none: render and time only)");
  render->add_flag("--json", render_args.json_out,
                   "Print one JSON object: device, options, ms per stage, triangles, fragments, plan, memory");

  bool scenes_json = false;
  CLI::App* scenes = app.add_subcommand("scenes", "List the built-in scenes");
  scenes->add_flag("--json", scenes_json, "Print a JSON array");
  CLI::App* devices = app.add_subcommand("devices", "List OpenCL devices (* marks the one seamcl would use)");

  // Subcommands defined in their own files (cli/commands.h), one line each.
  std::vector<seamcl::cli::Command> extra_commands;
  extra_commands.push_back(seamcl::cli::add_serve_command(app));
  extra_commands.push_back(seamcl::cli::add_compare_command(app));
  extra_commands.push_back(seamcl::cli::add_bench_command(app));
  extra_commands.push_back(seamcl::cli::add_merge_command(app));
  extra_commands.push_back(seamcl::cli::add_cube_command(app));
  extra_commands.push_back(seamcl::cli::add_displacement_command(app));
  extra_commands.push_back(seamcl::cli::add_ptx_command(app));
  extra_commands.push_back(seamcl::cli::add_warmup_command(app));

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "seamcl: %s\n", e.what());
    return 2;
  }

  try {
    const std::string device = cli::given_value(given_device, "device",
                                                "leave out --device for $SEAMCL_DEVICE, else the first GPU, else the first CPU");
    if (show_version) {
      std::printf("seamcl %s\n", SEAMCL_VERSION);
      std::printf("device: %s\n", ClRuntime(device).device_description().c_str());
      return 0;
    }
    if (render->parsed()) return run_render(render_args, device);
    if (scenes->parsed()) return run_scenes(scenes_json);
    if (devices->parsed()) return run_devices(device);
    for (const seamcl::cli::Command& command : extra_commands) {
      if (command.subcommand->parsed()) return command.run(seamcl::cli::GlobalOptions{device});
    }
    std::fputs(app.help().c_str(), stdout);
    return 2;
  } catch (const InputError& e) {
    std::fprintf(stderr, "seamcl: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "seamcl: %s\n", describe_cl_exception(e).c_str());
    return 1;
  }
}
