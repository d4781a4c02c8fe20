// seamcl displacement-metrics: every displacement method at every tessellation level, measured on
// one scene (host/eval/displacement_metrics.h): the exact gap between vertices two patches share,
// crack pixels over an orbit (closed meshes: a flag shell inside shows through every crack), time
// per frame and the extra data each method keeps. One JSON for examples/displacement_chart.py.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/io/image_io.h>
#include <seamcl/options/displacement_method.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include "commands.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

struct DisplacementArgs {
  std::string scene = "displaced";
  std::optional<std::string> displacement_map;  // a .ptx for an .obj scene; empty is refused, not taken for none
  std::string methods;
  std::string tessellation = "4,16,64";
  int level = 0;
  std::string size = "480x540";
  int msaa = 4;
  int frames = 60;
  int repeat = 5;
  std::optional<std::string> images;  // a directory; empty is refused, not taken for none
  bool json_out = false;
  bool no_progress = false;
};

std::vector<DisplacementMethod> parse_methods(const std::string& text) {
  std::vector<DisplacementMethod> out;
  for (const std::string& name : split_list(text, "methods")) {
    const auto method = parse_displacement_method(name);
    if (!method) {
      throw InputError("methods", "unknown displacement method '" + name + "' (known: " +
                                      join_names(displacement_method_names()) + ")");
    }
    out.push_back(*method);
  }
  return out;
}

int run(const DisplacementArgs& args, const GlobalOptions& global) {
  // Validate everything before any work.
  const std::string images_dir = given_value(args.images, "images", "leave out --images to write no images");
  const std::string displacement_map =
      given_value(args.displacement_map, "displacement_map", "leave out --displacement-map to use the scene's own maps");
  const std::vector<DisplacementMethod> methods = parse_methods(args.methods);
  const std::vector<int> levels = parse_int_list(args.tessellation, "tessellation");
  for (int t : levels) {
    if (t < 1 || t > SEAMCL_MAX_TESSELLATION) {
      throw InputError("tessellation", "each must be in 1.." + std::to_string(SEAMCL_MAX_TESSELLATION) + ", got " +
                                           std::to_string(t));
    }
  }
  if (args.frames < 0 || args.frames > 3600) throw InputError("frames", "must be in 0..3600 (0: the scene's camera only)");
  if (args.repeat < 1 || args.repeat > 100) throw InputError("repeat", "must be in 1..100");
  const RenderOptions base = parse_render_options({{"scene", args.scene},
                                                   {"size", args.size},
                                                   {"msaa", args.msaa},
                                                   {"displacement_method", to_string(methods.front())},
                                                   {"displacement_level", args.level}});
  ClRuntime runtime(global.device);  // a --device that matches none: refused before any work
  Scene scene = load_scene_source(base.scene);
  if (!displacement_map.empty()) attach_ptex_displacement(scene, displacement_map);
  if (args.frames > 0 && !scene.orbit) {
    throw InputError("frames", "scene '" + scene.name + "' has no orbit; pass --frames 0 to measure its camera only");
  }
  if (!scene.displacement) {
    throw InputError("scene", "'" + scene.name + "' has no displacement maps (the built-in 'displaced' scene has; an "
                                                 ".obj takes them with --displacement-map FILE.ptx)");
  }
  check_tessellation_levels(scene, levels);  // the triangle bound of every level, before any render
  const bool closed = is_closed_mesh(scene);
  if (!images_dir.empty()) make_output_directory(images_dir, "images");
  auto progress = [&](const std::string& line) {
    if (!args.no_progress) std::fprintf(stderr, "displacement-metrics: %s\n", line.c_str());
  };

  json results = json::array();
  const size_t total = methods.size() * levels.size();
  size_t done = 0;
  for (int t : levels) {
    for (DisplacementMethod method : methods) {
      RenderOptions options = base;
      options.displacement = method;
      options.tessellation = t;
      progress("[" + std::to_string(++done) + "/" + std::to_string(total) + "] " + to_string(method) + " T " +
               std::to_string(t));
      const DisplacementReport report = measure_displacement(runtime, scene, scene.camera, options, args.frames, args.repeat,
                                                                     device_memory_bound(runtime.info()));
      json item = report.to_json();
      if (!images_dir.empty()) {
        // Frame 0 of the orbit with the flag shell inside (closed meshes): cracks show as magenta.
        const Camera camera = scene.orbit ? orbit_camera(scene, 0, std::max(args.frames, 1)) : scene.camera;
        Renderer renderer(runtime);
        limit_to_machine(renderer, runtime.info());
        const Scene shown = closed ? with_flag_shell(scene) : scene;
        renderer.load_scene(shown, options.texels);
        const RenderResult image = renderer.render(camera, options);
        const fs::path path = fs::path(images_dir) / (to_string(method) + "_T" + std::to_string(t) + ".png");
        write_image(path.string(), image.width, image.height, image.pixels);
        item["image"] = path.string();
      }
      results.push_back(item);
    }
  }

  if (args.json_out) {
    json out = {{"scene", scene.name},
                {"size", args.size},
                {"msaa", args.msaa},
                {"level", args.level},
                {"crack_frames", closed ? args.frames : 0},
                {"closed_mesh", closed},
                {"repeat", args.repeat},
                {"device", runtime.device_description()},
                {"results", results}};
    if (!displacement_map.empty()) out["displacement_map"] = displacement_map;
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  std::printf("%s %s msaa %d, crack pixels over %d orbit frames%s\n", scene.name.c_str(), args.size.c_str(), args.msaa,
              args.frames, closed ? "" : " (open mesh: not counted)");
  std::printf("| method | T | max gap | differing pairs | crack pixels | samples | extra bytes | tessellate ms | frame ms |\n"
              "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  for (const json& r : results) {
    const std::string cracks = r["crack_pixels"].is_null() ? "n/a" : std::to_string(r["crack_pixels"].get<size_t>());
    std::printf("| %s | %d | %.4g | %zu | %s | %zu | %zu | %.2f | %.2f |\n", r["method"].get<std::string>().c_str(),
                r["tessellation"].get<int>(), r["max_gap"].get<double>(), r["differing_pairs"].get<size_t>(),
                cracks.c_str(), r["samples"].get<size_t>(), r["extra_bytes"].get<size_t>(),
                r["tessellate_ms"].get<double>(), r["frame_ms"].get<double>());
  }
  return 0;
}

}  // namespace

Command add_displacement_command(CLI::App& app) {
  auto args = std::make_shared<DisplacementArgs>();
  args->methods = join_names(displacement_method_names(), ",");
  CLI::App* command = app.add_subcommand(
      "displacement-metrics",
      "Measure every displacement method at every tessellation level: exact gap, crack pixels over an orbit, time, extra bytes");
  command->add_option("--scene", args->scene, "A scene with displacement maps: built-in, a scene file, or an .obj with --displacement-map [displaced]");
  command->add_option("--displacement-map", args->displacement_map, "A .ptx of displacement for an .obj --scene (face i takes face i)");
  command->add_option("--methods", args->methods, "Comma list of displacement methods [" + args->methods + "]");
  command->add_option("--tessellation", args->tessellation, "Comma list of tessellation levels T, each 1..64 [4,16,64]");
  command->add_option("--level", args->level, "The maps' level sampled, 0..16 [0]");
  command->add_option("--size", args->size, "Image size WIDTHxHEIGHT [480x540]");
  command->add_option("--msaa", args->msaa, "Samples per pixel (crack pixels count a pixel when any sample sees the flag) [4]");
  command->add_option("--frames", args->frames, "Orbit frames to count crack pixels over; 0: the scene's camera only [60]");
  command->add_option("--repeat", args->repeat, "Timed renders per entry; the median is reported [5]");
  command->add_option("--images", args->images, "Write frame 0 of each entry as PNG (flag shell inside: cracks magenta)");
  command->add_flag("--json", args->json_out, "Print one JSON object");
  command->add_flag("--no-progress", args->no_progress, "Do not print progress lines on stderr");
  return {command, [args](const GlobalOptions& global) { return run(*args, global); }};
}

}  // namespace seamcl::cli
