// seamcl: the command-line front end. Each subcommand gathers its flags, hands them to the
// library (the same option parser the HTTP service uses) and prints a result.
// Exit codes: 0 success, 2 bad usage or input (one line naming the field), 1 other failures.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/io/image_io.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/version.h>
#include "commands.h"

namespace {

using nlohmann::json;
using namespace seamcl;

struct RenderArgs {
  std::optional<std::string> scene, texture, method, filter, zero_coverage, texels, size, shading, cube_method;
  std::optional<int> msaa, aniso, guard_band, frame, frames;
  std::optional<std::string> displacement_method;
  std::optional<int> tessellation, displacement_level;
  std::optional<std::string> displacement_map;  // a .ptx of displacement for an .obj scene (CLI only)
  int crack_orbit = 0;           // count crack pixels over this many orbit frames (0: this frame)
  bool centroid = false;
  bool tint = false;
  std::optional<std::string> output;
  bool json_out = false;
  int repeat = 1;
};

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// The flags given on the command line as the JSON request the shared parser reads.
json render_request(const RenderArgs& a) {
  json request = json::object();
  if (a.scene) request["scene"] = *a.scene;
  if (a.texture) request["texture"] = *a.texture;
  if (a.method) request["method"] = *a.method;
  if (a.filter) request["filter"] = *a.filter;
  if (a.zero_coverage) request["zero_coverage"] = *a.zero_coverage;
  if (a.texels) request["texels"] = *a.texels;
  if (a.cube_method) request["cube_method"] = *a.cube_method;
  if (a.msaa) request["msaa"] = *a.msaa;
  if (a.aniso) request["aniso"] = *a.aniso;
  if (a.guard_band) request["guard_band"] = *a.guard_band;
  if (a.size) request["size"] = *a.size;
  if (a.shading) request["shading"] = *a.shading;
  if (a.centroid) request["centroid"] = true;
  if (a.frame) request["frame"] = *a.frame;
  if (a.frames) request["frames"] = *a.frames;
  if (a.tint) request["tint"] = true;
  if (a.displacement_method) request["displacement_method"] = *a.displacement_method;
  if (a.tessellation) request["tessellation"] = *a.tessellation;
  if (a.displacement_level) request["displacement_level"] = *a.displacement_level;
  return request;
}

int run_render(const RenderArgs& args, const std::string& device) {
  // Validate everything before any work, so bad input changes nothing.
  const std::string output = cli::given_value(args.output, "output", "leave out -o to render and time only");
  const std::string displacement_map = cli::given_value(args.displacement_map, "displacement_map",
                                                        "leave out --displacement-map to use the scene's own maps");
  const RenderOptions options = parse_render_options(render_request(args));
  if (!output.empty()) {
    image_format_for_path(output, "output");
    cli::check_output_parent(output, "output");
  }
  if (args.repeat < 1 || args.repeat > 1000) throw InputError("repeat", "must be in 1..1000");
  if (args.crack_orbit < 0 || args.crack_orbit > 3600) throw InputError("crack_orbit", "must be in 0..3600");
  // Options that would otherwise be ignored without a word.
  if (args.crack_orbit > 0 && (!options.displacement || !args.json_out))
    throw InputError("crack_orbit", "counts the cracks of a displaced render in --json's displacement block: give "
                                    "--displacement-method and --json too");
  if (args.frames && !args.frame) throw InputError("frames", "--frames is ignored without --frame: leave it out");
  if (!displacement_map.empty() && !options.displacement)
    throw InputError("displacement_map", "displaces only a render with --displacement-method");

  ClRuntime runtime(device);  // a --device that matches none is bad input too: refused before any work
  const auto scene_start = std::chrono::steady_clock::now();
  SceneSourceOptions source;
  source.generator.tint = options.tint;
  source.generator.defer_textures = true;  // baked face by face while packing: no float copy of them all
  Scene scene = load_scene_source(options.scene, options.texture, source);
  if (!displacement_map.empty()) attach_ptex_displacement(scene, displacement_map);
  const Camera camera = options.frame ? orbit_camera(scene, *options.frame, options.frames) : scene.camera;
  const double scene_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - scene_start).count();

  // A render this machine cannot hold is refused before it allocates (a mesh's triangles drive it:
  // each takes about 700 bytes of setup records).
  const RenderMemory estimate = render_memory(scene, options);
  refuse_beyond_machine(estimate, options.msaa, runtime.info(), "this render");
  Renderer renderer(runtime);
  limit_to_machine(renderer, runtime.info());
  // Handed over, not copied: image faces' float chains exist once (scene() reads them back).
  renderer.load_scene(std::move(scene), options.texels);
  const Scene& loaded = renderer.scene();
  renderer.warm_up(options);
  // Each run's times, and only the last run's image: holding every frame kept `--repeat` images
  // alive at once (4 MB each at 480x540, 133 MB at 3840x2160).
  std::vector<StageTimes> times;
  RenderResult result;
  for (int i = 0; i < args.repeat; ++i) {
    result = renderer.render(camera, options);
    times.push_back(result.ms);
  }
  if (!output.empty()) write_image(output, result.width, result.height, result.pixels);

  auto stage_median = [&](double StageTimes::*stage) {
    std::vector<double> values;
    for (const StageTimes& t : times) values.push_back(t.*stage);
    return median(values);
  };
  const json ms = {{"total", stage_median(&StageTimes::total)},     {"setup", stage_median(&StageTimes::setup)},
                   {"binning", stage_median(&StageTimes::binning)}, {"raster", stage_median(&StageTimes::raster)},
                   {"shade", stage_median(&StageTimes::shade)},     {"readback", stage_median(&StageTimes::readback)}};
  if (args.json_out) {
    json out = {{"device", runtime.device_description()},
                {"options", to_json(options)},
                {"ms", ms},
                {"runs", args.repeat},
                {"kernel_build_ms", runtime.program_build_ms()},
                {"scene_ms", scene_ms},
                {"triangles", loaded.triangle_count()},
                {"visible_triangles", result.stats.visible_triangles},
                {"fragments", result.stats.fragments},
                {"texture_bytes", renderer.packed_scene().texture_bytes()},
                {"padding_bytes", renderer.packed_scene().padding_bytes()},
                {"adjacency_bytes", reads_adjacency(options.method) ? renderer.packed_scene().adjacency_bytes() : 0},
                {"bin_entries", result.stats.bin_entries}};
    if (options.displacement) {
      // The gap and crack pixels of this frame (docs/displacement.md), the times of the renders above.
      DisplacementReport report = measure_displacement(runtime, loaded, camera, options, args.crack_orbit, 0,
                                                       renderer.device_byte_limit());
      report.frame_ms = stage_median(&StageTimes::total);
      report.tessellate_ms = stage_median(&StageTimes::tessellate);
      out["displacement"] = report.to_json();
      out["triangles"] = report.triangles;
    }
    if (!output.empty()) out["output"] = output;
    out["memory"] = to_json(measure_memory(renderer));  // peak over everything above
    const std::string field = frame_buffers_field(options.msaa);
    const bool unified = runtime.info().host_unified_memory;
    out["estimate"] = estimate_json(estimate.device_shares(field), estimate.host_shares(),
                                    estimate.process_shares(field, unified), unified);
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("%s: %dx%d msaa %d, %.2f ms (setup %.2f, binning %.2f, raster %.2f, shade %.2f), %u fragments%s%s\n",
                loaded.name.c_str(), result.width, result.height, options.msaa, ms["total"].get<double>(),
                ms["setup"].get<double>(), ms["binning"].get<double>(), ms["raster"].get<double>(),
                ms["shade"].get<double>(), result.stats.fragments, output.empty() ? "" : " -> ",
                output.c_str());
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
  seamcl::return_large_blocks_at_once();  // freed textures leave the process (render_memory.h)
  CLI::App app{"seamcl: render per-face textured scenes with OpenCL and compare texture seam methods"};
  app.require_subcommand(0, 1);
  std::optional<std::string> given_device;
  app.add_option("--device", given_device, "OpenCL device: a substring of 'platform device' (default $SEAMCL_DEVICE, else the first GPU, else the first CPU)");
  bool show_version = false;
  app.add_flag("--version", show_version, "Print the version and the OpenCL device, then exit");

  RenderArgs render_args;
  CLI::App* render = app.add_subcommand("render", "Render one frame of a scene to PNG (sRGB 8-bit) or EXR (linear)");
  render->add_option("--scene", render_args.scene,
                     "Built-in scene name (see 'seamcl scenes'), a scene JSON file, an .obj mesh or a .ptx that holds its mesh [paper]");
  render->add_option("--texture", render_args.texture,
                     "A .ptx file of per-face textures for an .obj --scene (face i of the mesh takes face i of the file)");
  render->add_option("--method", render_args.method, "Seam method: " + cli::join_names(method_names()) + " [discard]");
  render->add_option("--filter", render_args.filter, "Texture filter: " + cli::join_names(filter_names()) + " [aniso]");
  render->add_option("--zero-coverage", render_args.zero_coverage,
                     "discard with every tap outside the face: clamp (a clamped lookup) or nan (the raw 0/0) [clamp]");
  render->add_option("--texels", render_args.texels, "Texel storage: " + cli::join_names(texel_format_names()) + " [rgba8]");
  render->add_option("--cube-method", render_args.cube_method,
                     "Cube-map seam method of scenes with an environment (envmap): " + cli::join_names(cube_method_names()) +
                         " [cube-seamless]");
  render->add_option("--msaa", render_args.msaa, "Samples per pixel: 1, 2, 4, 8 or 16 [1]");
  render->add_option("--aniso", render_args.aniso, "Maximum anisotropy, 1..16 [16]");
  render->add_option("--guard-band", render_args.guard_band, "guardband: band texels per side of every level, 1..16 [4]");
  render->add_option("--size", render_args.size, "Image size WIDTHxHEIGHT [480x540]");
  render->add_option("--frame", render_args.frame, "Orbit frame K (0-based) of --frames");
  render->add_option("--frames", render_args.frames, "Frames in the orbit [60]");
  render->add_option("--shading", render_args.shading, "Where to shade: pixel, centroid or sample [pixel]");
  render->add_flag("--centroid", render_args.centroid, "Shade at the centroid of the covered samples (same as --shading centroid)");
  render->add_flag("--tint", render_args.tint, "Built-in scenes: tint each face a different base colour");
  render->add_option("--displacement-method", render_args.displacement_method,
                     "Tessellate and displace with this seam method: " + cli::join_names(displacement_method_names()) + " [off]");
  render->add_option("--tessellation", render_args.tessellation, "Displacement: each patch a (T+1)^2 grid, T 1..64 [8]");
  render->add_option("--displacement-level", render_args.displacement_level, "Displacement: the maps' level sampled, 0..16 [0]");
  render->add_option("--displacement-map", render_args.displacement_map,
                     "Displacement: a 1-channel .ptx for an .obj scene, face i displacing face i");
  render->add_option("--crack-orbit", render_args.crack_orbit,
                     "Displacement: count crack pixels over N frames of the scene's orbit instead of this frame [0]");
  render->add_option("-o,--output", render_args.output, "Output image, .png or .exr (none: render and time only)");
  render->add_flag("--json", render_args.json_out, "Print one JSON object: device, options, ms per stage, triangles, fragments");
  render->add_option("--repeat", render_args.repeat, "Render N times and report the median time per stage [1]");

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
