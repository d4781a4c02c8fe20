#include <seamcl/jobs/displacement_metrics_job.h>

#include <algorithm>
#include <filesystem>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/io/image_io.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/displacement_packing.h"
#include "pipeline/tessellation_factors.h"

namespace seamcl {
namespace {

using nlohmann::json;

constexpr int kMaxCrackFrames = 3600;

// What with_back_faces_flagged makes for `patches` patches at T, before any vertex exists:
// (T+1)^2 vertices and 2 T^2 faces (1x1 textures) a patch.
SceneSizes back_faces_flagged_sizes(size_t patches, int tessellation) {
  const auto t = static_cast<size_t>(std::max(tessellation, 1));
  SceneSizes sizes;
  sizes.vertices = patches * (t + 1) * (t + 1);
  sizes.faces.assign(2 * patches * t * t, {1, 1});
  return sizes;
}

}  // namespace

const OptionTable& displacement_metrics_option_table() {
  static const OptionTable table = [] {
    OptionSpec scene = *find_option(render_option_table(), "scene");
    scene.help = "A scene with displacement maps: built-in, a scene file, or an .obj with its maps attached";
    scene.default_value = "displaced";
    OptionSpec methods = make_option("methods", OptionType::List, "Comma list of displacement methods");
    methods.choices = displacement_method_names();
    methods.default_value = displacement_method_names();
    OptionSpec levels = make_option("tessellation", OptionType::List, "Comma list of tessellation levels T");
    for (int t = 1; t <= SEAMCL_MAX_TESSELLATION; ++t) levels.integers.push_back(t);
    levels.default_value = json::array({4, 16, 64});
    OptionSpec level = make_option("level", OptionType::Integer, "The maps' level sampled");
    level.minimum = 0;
    level.maximum = kMaxDisplacementLevel;
    level.default_value = 0;
    OptionSpec size = *find_option(render_option_table(), "size");
    OptionSpec msaa = *find_option(render_option_table(), "msaa");
    msaa.help = "Samples per pixel (crack pixels count a pixel when any sample sees through a crack)";
    msaa.default_value = 4;
    OptionSpec frames = make_option("frames", OptionType::Integer,
                                    "Orbit frames to count crack pixels over; 0: the scene's camera only");
    frames.minimum = 0;
    frames.maximum = kMaxCrackFrames;
    frames.default_value = 60;
    OptionSpec repeat = make_option("repeat", OptionType::Integer, "Timed renders per entry; the median is reported");
    repeat.minimum = 1;
    repeat.maximum = 100;
    repeat.default_value = 5;
    OptionSpec pixels = *find_option(render_option_table(), "tessellation_pixels");
    pixels.help = "Screen-space adaptive factors from the scene's camera, this many pixels a segment, each T the "
                  "largest factor; absent: uniform";
    return OptionTable{scene, methods, levels, level, size, msaa, frames, repeat, pixels};
  }();
  return table;
}

DisplacementMetricsJob::DisplacementMetricsJob(const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  std::vector<std::string> known;
  for (const OptionSpec& spec : displacement_metrics_option_table()) known.push_back(spec.key);
  refuse_unknown_keys(request, known);
  auto value_of = [&](const std::string& key) {
    const OptionSpec& spec = *find_option(displacement_metrics_option_table(), key);
    return request.contains(key) ? checked_option(spec, request.at(key)) : spec.default_value;
  };
  for (const json& name : value_of("methods")) methods_.push_back(*parse_displacement_method(name.get<std::string>()));
  for (const json& t : value_of("tessellation")) levels_.push_back(t.get<int>());
  frames_ = value_of("frames").get<int>();
  repeat_ = value_of("repeat").get<int>();
  json frame = {{"scene", value_of("scene")},
                {"size", value_of("size")},
                {"msaa", value_of("msaa")},
                {"displacement_method", to_string(methods_.front())},
                {"displacement_level", value_of("level")}};
  if (request.contains("tessellation_pixels")) frame["tessellation_pixels"] = value_of("tessellation_pixels");
  frame_ = parse_render_options(frame);
}

JobPlan DisplacementMetricsJob::plan(const Scene& scene) const {
  if (frames_ > 0 && !scene.orbit)
    throw InputError("frames", "scene '" + scene.name + "' has no orbit; pass --frames 0 to measure its camera only");
  if (!scene.displacement) {
    throw InputError("scene", "'" + scene.name + "' has no displacement maps (the built-in 'displaced' scene has; an "
                                                 ".obj takes them with --displacement-map FILE.ptx)");
  }
  check_tessellation_levels(scene, levels_);  // the triangle bound of every level, before any render
  RenderOptions densest = frame_;
  densest.tessellation = *std::max_element(levels_.begin(), levels_.end());
  // The timed renders hold the scene tessellated; a closed mesh's crack renders, after them, its
  // displaced micro-quads twice as plain faces: the run needs the larger.
  const std::string field = frame_buffers_field(densest.msaa);
  const RenderMemory timed = render_memory(scene, densest);
  if (!is_closed_mesh(scene)) return JobPlan{"this displacement-metrics run", timed.device_shares(field), timed.host_shares(), {}};
  const RenderMemory cracks =
      render_memory(back_faces_flagged_sizes(scene.faces.size(), densest.tessellation), crack_render_options(densest));
  return JobPlan{"this displacement-metrics run", larger(timed.device_shares(field), cracks.device_shares(field)),
                 larger(timed.host_shares(), cracks.host_shares()), {}};
}

json DisplacementMetricsJob::run(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                                 const std::string& images_dir) const {
  (void)plan(scene);  // the scene's checks, for a caller that did not plan
  const bool closed = is_closed_mesh(scene);
  json results = json::array();
  const size_t total = methods_.size() * levels_.size();
  for (int t : levels_) {
    for (DisplacementMethod method : methods_) {
      throw_if_stopped(control.should_stop, "before " + to_string(method) + " T " + std::to_string(t));
      RenderOptions options = frame_;
      options.displacement = method;
      options.tessellation = t;
      control.report(step_of(results.size() + 1, total) + to_string(method) +
                     " T " + std::to_string(t));
      json item = measure_displacement(runtime, scene, scene.camera, options, frames_, repeat_, control.device_byte_limit)
                      .to_json();
      if (!images_dir.empty()) {
        // Frame 0 of the orbit; a closed mesh's as the crack renders count it: back faces (seen
        // only through cracks) in the flag's magenta, front faces tinted per patch.
        const Camera camera = scene.orbit ? orbit_camera(scene, 0, std::max(frames_, 1)) : scene.camera;
        Renderer renderer(runtime);
        renderer.set_device_byte_limit(control.device_byte_limit);
        RenderResult image;
        if (closed) {
          const RenderOptions crack_options = crack_render_options(options);
          const PackedDisplacement packed = pack_displacement(scene, displacement_settings(scene, options, scene.camera));
          renderer.load_scene(with_back_faces_flagged(scene, tessellate_displacement(runtime, scene, options),
                                                      packed.params.tessellation, packed.adaptive()),
                              crack_options.texels);
          image = renderer.render(camera, crack_options);
        } else {
          renderer.load_scene(scene, options.texels);
          image = renderer.render(camera, options);
        }
        const std::filesystem::path path =
            std::filesystem::path(images_dir) / (to_string(method) + "_T" + std::to_string(t) + ".png");
        write_image(path.string(), image.width, image.height, image.pixels);
        item["image"] = path.string();
      }
      results.push_back(item);
    }
  }
  return {{"scene", scene.name},
          {"size", std::to_string(frame_.width) + "x" + std::to_string(frame_.height)},
          {"msaa", frame_.msaa},
          {"level", frame_.displacement_level},
          {"tessellation_pixels", frame_.tessellation_pixels ? json(*frame_.tessellation_pixels) : json()},
          {"crack_frames", closed ? frames_ : 0},
          {"closed_mesh", closed},
          {"repeat", repeat_},
          {"device", runtime.device_description()},
          {"results", results}};
}

}  // namespace seamcl
