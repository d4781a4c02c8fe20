// seamcl cube-metrics: every cube-map seam method at every cube size, measured against the
// scene's environment function (analytic, or an image loaded from a scene file; host/eval/cube_metrics.h): seam step per lod at the 12 edges, first-order
// jump, error of an envmap frame against the environment integrated over each pixel (all pixels
// and those whose footprint crosses a cube edge), time per frame and cube-map memory.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/cube_metrics.h>
#include <seamcl/io/image_io.h>
#include <seamcl/pipeline/packed_cube.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/cube_map.h>
#include <seamcl/scene/scene_json.h>
#include "commands.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;

struct CubeArgs {
  std::string scene = "envmap";
  std::string cube_methods;
  std::string cube_sizes = "16,64,256";
  std::string size = "160x180";
  std::string filter = "aniso";
  int msaa = 1;
  int frame = 0, frames = 1;
  int repeat = 5;
  int reference_scale = 8;
  std::optional<std::string> images;  // a directory; empty is refused, not taken for none
  bool json_out = false;
};

std::vector<int> parse_sizes(const std::string& text) {
  std::vector<int> out;
  for (const std::string& part : split_list(text, "cube_sizes")) {
    int n = 0;
    try {
      size_t used = 0;
      n = std::stoi(part, &used);
      if (used != part.size()) n = 0;
    } catch (const std::exception&) {
      n = 0;
    }
    if (n < 1 || n > kMaxCubeSize || (n & (n - 1)) != 0) {
      throw InputError("cube_sizes", "each must be a power of two in 1.." + std::to_string(kMaxCubeSize) + ", got '" +
                                         part + "'");
    }
    out.push_back(n);
  }
  return out;
}

std::string fixed(double v, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", digits, v);
  return buffer;
}

std::string scientific(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.2e", v);
  return buffer;
}

int run(const CubeArgs& args, const GlobalOptions& global) {
  const std::string images_dir = given_value(args.images, "images", "leave out --images to write no images");
  std::vector<CubeMethod> methods;
  for (const std::string& name : split_list(args.cube_methods, "cube_methods")) {
    const auto method = parse_cube_method(name);
    if (!method) throw InputError("cube_methods", "unknown cube method '" + name + "'");
    methods.push_back(*method);
  }
  const std::vector<int> sizes = parse_sizes(args.cube_sizes);
  const RenderOptions base = parse_render_options({{"scene", args.scene},
                                                   {"size", args.size},
                                                   {"filter", args.filter},
                                                   {"msaa", args.msaa},
                                                   {"frame", args.frame},
                                                   {"frames", args.frames}});
  if (args.repeat < 1 || args.repeat > 100) throw InputError("repeat", "must be in 1..100");
  if (args.reference_scale < 1 || args.reference_scale > 16) throw InputError("reference_scale", "must be in 1..16");
  // Through host/assets, so that a scene file's environment may be an image file.
  ClRuntime runtime(global.device);  // a --device that matches none: refused before any work
  Scene scene = load_scene_source(base.scene);
  if (!scene.environment) throw InputError("scene", "'" + base.scene + "' has no environment (try envmap)");
  const Camera camera = scene.orbit ? orbit_camera(scene, args.frame, args.frames) : scene.camera;
  if (!images_dir.empty()) make_output_directory(images_dir, "images");

  Renderer renderer(runtime);
  limit_to_machine(renderer, runtime.info());
  renderer.load_scene(scene);
  // The reference does not depend on the cube: it is the environment itself.
  const CubeReference reference = cube_reference(renderer, camera, base, args.reference_scale);
  if (!images_dir.empty()) {
    write_image(images_dir + "/reference.png", reference.width, reference.height, reference.pixels);
    std::vector<glm::vec4> mask(reference.cube_edge.size());
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = glm::vec4(glm::vec3(reference.cube_edge[i] ? 1.0f : 0.0f), 1.0f);
    write_image(images_dir + "/cube_edge_mask.png", reference.width, reference.height, mask);
  }

  json results = json::array();
  for (int n : sizes) {
    scene.environment->cube_size = n;
    renderer.load_scene(scene);
    for (CubeMethod method : methods) {
      RenderOptions options = base;
      options.cube_method = method;
      renderer.warm_up(options);
      std::vector<double> ms;
      RenderResult image;
      for (int r = 0; r < args.repeat; ++r) {
        image = renderer.render(camera, options);
        ms.push_back(image.ms.total);
      }
      std::sort(ms.begin(), ms.end());
      const ImageErrors errors = compare_images(image.pixels, reference.pixels, &reference.cube_edge);
      const EdgeMeasures edges = measure_cube_edges(runtime, *scene.environment, method, n);
      const size_t cube_bytes = static_cast<size_t>(kCubeFaces) * (4 * static_cast<size_t>(n) * n - 1) / 3 * 16;
      if (!images_dir.empty()) {
        write_image(images_dir + "/" + to_string(method) + "-" + std::to_string(n) + ".png", image.width,
                    image.height, image.pixels);
      }
      results.push_back({{"cube_size", n},
                         {"cube_method", to_string(method)},
                         {"bake", to_string(cube_bake(method))},
                         {"seam_step", edges.seam_step_mean},
                         {"seam_step_max", edges.seam_step_max},
                         {"first_order_jump", edges.first_order_jump},
                         {"environment_first_order_jump", edges.environment_first_order_jump},
                         {"ms", {{"median", ms[ms.size() / 2]}, {"min", ms.front()}, {"max", ms.back()}}},
                         {"cube_bytes", cube_bytes},
                         // The statistics skip NaN pixels; their counts say whether there were any.
                         {"error",
                          {{"mean", errors.all.mean},
                           {"p99", errors.all.p99},
                           {"max", errors.all.max},
                           {"nan_pixels", errors.nan_pixels}}},
                         {"edge_error",
                          {{"mean", errors.seam.mean},
                           {"p99", errors.seam.p99},
                           {"max", errors.seam.max},
                           {"pixels", errors.seam.pixels},
                           {"nan_pixels", errors.seam_nan_pixels}}}});
    }
  }
  if (args.json_out) {
    std::cout << json{{"scene", base.scene},
                      {"size", args.size},
                      {"filter", args.filter},
                      {"msaa", args.msaa},
                      {"reference_scale", args.reference_scale},
                      {"edge_pixels", reference.edge_pixels},
                      {"device", runtime.device_description()},
                      {"results", results}}
                     .dump(2)
              << "\n";
    return 0;
  }
  std::cout << "| n | method | error mean | edge error mean | edge error p99 | first-order jump | ms | cube MiB | seam step per lod 0..log2(n) |\n"
            << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const json& r : results) {
    std::string steps;
    for (const json& s : r["seam_step"]) steps += (steps.empty() ? "" : " ") + scientific(s.get<double>());
    std::cout << "| " << r["cube_size"].get<int>() << " | " << r["cube_method"].get<std::string>() << " | "
              << scientific(r["error"]["mean"]) << " | " << scientific(r["edge_error"]["mean"]) << " | "
              << scientific(r["edge_error"]["p99"]) << " | " << scientific(r["first_order_jump"]) << " | "
              << fixed(r["ms"]["median"], 2) << " | " << fixed(r["cube_bytes"].get<double>() / 1048576.0, 3) << " | "
              << steps << " |\n";
  }
  std::cout << "\nedge pixels (footprint crosses a cube edge): " << reference.edge_pixels << " of "
            << reference.pixels.size() << "\n";
  return 0;
}

}  // namespace

Command add_cube_command(CLI::App& app) {
  auto args = std::make_shared<CubeArgs>();
  args->cube_methods = join_names(cube_method_names(), ",");
  CLI::App* command = app.add_subcommand(
      "cube-metrics", "Measure every cube-map seam method against the analytic environment, per cube size");
  command->add_option("--scene", args->scene, "A scene with an environment, built-in or a scene file (its environment may be an image) [envmap]");
  command->add_option("--cube-methods", args->cube_methods, "Comma list of cube methods [" + args->cube_methods + "]");
  command->add_option("--cube-sizes", args->cube_sizes, "Comma list of cube face sizes, powers of two [16,64,256]");
  command->add_option("--size", args->size, "Image size WIDTHxHEIGHT [160x180]");
  command->add_option("--filter", args->filter, "Filter: bilinear, trilinear, aniso (ewa filters as aniso) [aniso]");
  command->add_option("--msaa", args->msaa, "Samples per pixel of the measured renders [1]");
  command->add_option("--frame", args->frame, "Orbit frame K of --frames [0]");
  command->add_option("--frames", args->frames, "Frames in the orbit [1]");
  command->add_option("--repeat", args->repeat, "Timed renders per entry; the median is reported [5]");
  command->add_option("--reference-scale", args->reference_scale,
                      "Supersampling of the analytic reference per axis [8]");
  command->add_option("--images", args->images, "Write each image, the reference and the cube-edge mask as PNG");
  command->add_flag("--json", args->json_out, "Print one JSON object");
  return {command, [args](const GlobalOptions& global) { return run(*args, global); }};
}

}  // namespace seamcl::cli
