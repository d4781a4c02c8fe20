#include <seamcl/jobs/cube_metrics_job.h>

#include <algorithm>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/cube_metrics.h>
#include <seamcl/io/image_io.h>
#include <seamcl/pipeline/packed_cube.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/cube_map.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {
namespace {

using nlohmann::json;

// The frame's render options this job reads, with the defaults of a small envmap frame.
const std::vector<std::pair<std::string, json>> kFrameDefaults = {
    {"scene", "envmap"}, {"size", "160x180"}, {"filter", "aniso"}, {"msaa", 1}, {"frame", 0}, {"frames", 1}};


}  // namespace

const OptionTable& cube_metrics_option_table() {
  static const OptionTable table = [] {
    OptionTable out;
    for (const auto& [key, value] : kFrameDefaults) {
      OptionSpec spec = *find_option(render_option_table(), key);
      spec.default_value = value;
      spec.absent.clear();
      out.push_back(spec);
    }
    out.front().help = "A scene with an environment, built-in or a scene file (its environment may be an image)";
    OptionSpec methods = make_option("cube_methods", OptionType::List, "Comma list of cube methods");
    methods.choices = cube_method_names();
    methods.default_value = cube_method_names();
    OptionSpec sizes = make_option("cube_sizes", OptionType::List, "Comma list of cube face sizes, powers of two");
    for (int n = 1; n <= kMaxCubeSize; n *= 2) sizes.integers.push_back(n);
    sizes.default_value = json::array({16, 64, 256});
    OptionSpec repeat = make_option("repeat", OptionType::Integer, "Timed renders per entry; the median is reported");
    repeat.minimum = 1;
    repeat.maximum = 100;
    repeat.default_value = 5;
    OptionSpec scale = make_option("reference_scale", OptionType::Integer, "Supersampling of the analytic reference per axis");
    scale.minimum = 1;
    scale.maximum = 16;
    scale.default_value = 8;
    for (const OptionSpec& spec : {methods, sizes, repeat, scale}) out.push_back(spec);
    return out;
  }();
  return table;
}

CubeMetricsJob::CubeMetricsJob(const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  std::vector<std::string> known;
  for (const OptionSpec& spec : cube_metrics_option_table()) known.push_back(spec.key);
  refuse_unknown_keys(request, known);
  auto value_of = [&](const std::string& key) {
    const OptionSpec& spec = *find_option(cube_metrics_option_table(), key);
    return request.contains(key) ? checked_option(spec, request.at(key)) : spec.default_value;
  };
  json frame_request = json::object();
  for (const auto& [key, value] : kFrameDefaults) frame_request[key] = value_of(key);
  frame_ = parse_render_options(frame_request);
  for (const json& name : value_of("cube_methods")) methods_.push_back(*parse_cube_method(name.get<std::string>()));
  for (const json& n : value_of("cube_sizes")) sizes_.push_back(n.get<int>());
  repeat_ = value_of("repeat").get<int>();
  reference_scale_ = value_of("reference_scale").get<int>();
}

JobPlan CubeMetricsJob::plan(const Scene& scene) const {
  if (!scene.environment) throw InputError("scene", "'" + frame_.scene + "' has no environment (try envmap)");
  RenderOptions reference = frame_;
  reference.width *= reference_scale_;
  reference.height *= reference_scale_;
  reference.msaa = 1;
  const RenderMemory measured = render_memory(scene, frame_), supersampled = render_memory(scene, reference);
  MemoryShares device = larger(measured.device_shares(frame_buffers_field(frame_.msaa)), supersampled.device_shares("size"));
  MemoryShares host = larger(measured.host_shares(), supersampled.host_shares());
  size_t largest_cube = 0;
  for (CubeMethod method : methods_) {
    largest_cube = std::max(largest_cube, cube_bytes(method, *std::max_element(sizes_.begin(), sizes_.end())));
  }
  device.add("scene", largest_cube);
  host.add("scene", largest_cube);
  return JobPlan{"this cube-metrics run", device, host, {}};
}

json CubeMetricsJob::run(ClRuntime& runtime, const Scene& source, const JobControl& control,
                         const std::string& images_dir) const {
  if (!source.environment) throw InputError("scene", "'" + frame_.scene + "' has no environment (try envmap)");
  Scene scene = source;  // its cube size changes per entry
  const Camera camera = scene.orbit ? orbit_camera(scene, *frame_.frame, frame_.frames) : scene.camera;
  Renderer renderer(runtime);
  renderer.set_device_byte_limit(control.device_byte_limit);
  renderer.load_scene(scene);
  // The reference does not depend on the cube: it is the environment itself.
  control.report("reference at " + std::to_string(reference_scale_) + "x");
  const CubeReference reference = cube_reference(renderer, camera, frame_, reference_scale_);
  if (!images_dir.empty()) {
    write_image(images_dir + "/reference.png", reference.width, reference.height, reference.pixels);
    std::vector<glm::vec4> mask(reference.cube_edge.size());
    for (size_t i = 0; i < mask.size(); ++i) mask[i] = glm::vec4(glm::vec3(reference.cube_edge[i] ? 1.0f : 0.0f), 1.0f);
    write_image(images_dir + "/cube_edge_mask.png", reference.width, reference.height, mask);
  }
  json results = json::array();
  const size_t total = sizes_.size() * methods_.size();
  for (int n : sizes_) {
    scene.environment->cube_size = n;
    renderer.load_scene(scene);
    for (CubeMethod method : methods_) {
      throw_if_stopped(control.should_stop, "before " + to_string(method) + " at " + std::to_string(n));
      control.report(step_of(results.size() + 1, total) + to_string(method) +
                     " at " + std::to_string(n));
      RenderOptions options = frame_;
      options.cube_method = method;
      renderer.warm_up(options);
      std::vector<double> ms;
      RenderResult image;
      for (int r = 0; r < repeat_; ++r) {
        image = renderer.render(camera, options);
        ms.push_back(image.ms.total);
      }
      std::sort(ms.begin(), ms.end());
      const ImageErrors errors = compare_images(image.pixels, reference.pixels, &reference.cube_edge);
      const EdgeMeasures edges = measure_cube_edges(runtime, *scene.environment, method, n);
      if (!images_dir.empty()) {
        write_image(images_dir + "/" + to_string(method) + "-" + std::to_string(n) + ".png", image.width, image.height,
                    image.pixels);
      }
      results.push_back({{"cube_size", n},
                         {"cube_method", to_string(method)},
                         {"bake", to_string(cube_bake(method))},
                         {"edges_averaged", cube_preparation(method).average_edges},
                         {"border", cube_preparation(method).border},
                         {"seam_step", edges.seam_step_mean},
                         {"seam_step_max", edges.seam_step_max},
                         {"seam_step_half_lod", edges.seam_step_half_lod},
                         {"first_order_jump", edges.first_order_jump},
                         {"environment_first_order_jump", edges.environment_first_order_jump},
                         {"first_order_band", edges.first_order_band},
                         {"environment_band_slope", edges.environment_band_slope},
                         {"ms", {{"median", ms[ms.size() / 2]}, {"min", ms.front()}, {"max", ms.back()}}},
                         {"cube_bytes", edges.cube_bytes},
                         {"bake_ms", edges.bake_ms},
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
  return {{"scene", frame_.scene},
          {"size", std::to_string(frame_.width) + "x" + std::to_string(frame_.height)},
          {"filter", to_string(frame_.filter)},
          {"msaa", frame_.msaa},
          {"reference_scale", reference_scale_},
          {"edge_pixels", reference.edge_pixels},
          {"device", runtime.device_description()},
          {"results", results}};
}

}  // namespace seamcl
