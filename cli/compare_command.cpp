// seamcl compare: renders one frame with every method x MSAA rate, measures each against the
// paper's reference (host/eval/reference.h) and prints the errors (host/eval/metrics.h) with the timings.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/io/image_io.h>
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
  std::string constant_color;  // "r,g,b" linear: paint every face this colour
  std::string images_dir;
  int repeat = 3;
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

int run_compare(const CompareArgs& args, const GlobalOptions& global) {
  // Validate everything before any work.
  const json base = base_request(args);
  const RenderOptions frame = parse_render_options(base);
  const std::vector<std::string> methods = split_list(args.methods, "methods");
  const std::vector<int> rates = parse_int_list(args.msaa, "msaa");
  const std::vector<MethodEntry> entries = method_entries(base, methods, rates);
  if (args.repeat < 1 || args.repeat > 1000) throw InputError("repeat", "must be in 1..1000");
  const ReferenceSettings ref_settings = reference_settings(args);
  (void)reference_render_options(frame, ref_settings);  // size and reference settings checked now
  GeneratorOptions generator_options;
  generator_options.tint = frame.tint;
  if (!args.constant_color.empty()) generator_options.constant_color = parse_color(args.constant_color);

  SceneSourceOptions source;
  source.generator = generator_options;
  const Scene scene = load_scene_source(frame.scene, frame.texture, source);
  const Camera camera = frame.frame ? orbit_camera(scene, *frame.frame, frame.frames) : scene.camera;
  if (!args.images_dir.empty()) fs::create_directories(args.images_dir);

  ClRuntime runtime(global.device);
  Renderer renderer(runtime);
  renderer.load_scene(scene, frame.texels);

  // The seam mask of this frame at its own size, from a 1-sample render.
  const FaceMap faces = render_face_map(renderer, camera, frame);
  const std::vector<uint8_t> mask = seam_mask(faces);
  const size_t seam_pixels = static_cast<size_t>(std::count(mask.begin(), mask.end(), uint8_t{1}));

  const ReferenceImage reference = reference_image(renderer, camera, frame, ref_settings);
  if (!args.images_dir.empty()) {
    write_image((fs::path(args.images_dir) / "reference.png").string(), reference.width, reference.height,
                reference.pixels);
  }

  json results = json::array();
  for (const EntryResult& measured :
       compare_methods(renderer, scene, camera, entries, &reference.pixels, &mask, args.repeat)) {
    json item = compare_result_json(measured);
    if (!args.images_dir.empty()) {
      const RenderResult& result = measured.last;
      const std::string stem = measured.entry.method_name + "_msaa" + std::to_string(measured.entry.options.msaa);
      const fs::path image = fs::path(args.images_dir) / (stem + ".png");
      const fs::path heat = fs::path(args.images_dir) / (stem + "_error.png");
      write_image(image.string(), result.width, result.height, result.pixels);
      write_image(heat.string(), result.width, result.height, error_heatmap(measured.errors->distance));
      item["images"] = {{"image", image.string()}, {"error", heat.string()}};
    }
    results.push_back(item);
  }

  if (!args.images_dir.empty()) {
    std::vector<glm::vec4> mask_image(mask.size());
    for (size_t i = 0; i < mask.size(); ++i) mask_image[i] = mask[i] ? glm::vec4(1) : glm::vec4(0, 0, 0, 1);
    write_image((fs::path(args.images_dir) / "seam_mask.png").string(), frame.width, frame.height, mask_image);
  }

  const std::string size = std::to_string(frame.width) + "x" + std::to_string(frame.height);
  if (args.json_out) {
    json out = {{"scene", scene.name},
                {"size", size},
                {"device", runtime.device_description()},
                {"reference_method", reference.method},
                {"reference", reference_json(reference, true)},
                {"seam_pixels", seam_pixels},
                {"seam_radius", kSeamRadius},
                {"options", to_json(frame)},
                {"results", results}};
    if (frame.frame) {
      out["frame"] = *frame.frame;
      out["frames"] = frame.frames;
    }
    if (!args.images_dir.empty()) out["images"] = args.images_dir;
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("%s %s, reference: %s at %dx, %d spp, Mitchell B=C=1/3 (%s); %zu seam pixels\n", scene.name.c_str(),
                size.c_str(), reference.method.c_str(), kReferenceScale, reference.msaa,
                reference.from_cache ? "cached" : "rendered", seam_pixels);
    std::printf("%-10s %4s %9s %10s %10s %10s %10s %10s %6s\n", "method", "msaa", "ms", "mean", "p99", "max",
                "seam_mean", "seam_p99", "nan");
    for (const json& r : results) {
      const json& e = r["error"];
      std::printf("%-10s %4d %9.2f %10.3e %10.3e %10.3e %10.3e %10.3e %6zu\n", r["method"].get<std::string>().c_str(),
                  r["msaa"].get<int>(), r["ms"]["median"].get<double>(), e["mean"].get<double>(),
                  e["p99"].get<double>(), e["max"].get<double>(), e["seam_mean"].get<double>(),
                  e["seam_p99"].get<double>(), e["nan_pixels"].get<size_t>());
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
  cmd->add_option("--images", args->images_dir,
                  "Write each image, an error heat map (log scale 1e-4..1), the reference and the seam mask (PNG) here");
  cmd->add_option("--repeat", args->repeat, "Timed renders per method and rate; ms reports median, min, max [3]");
  return Command{cmd, [args](const GlobalOptions& global) { return run_compare(*args, global); }};
}

}  // namespace seamcl::cli
