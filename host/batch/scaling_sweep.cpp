#include <seamcl/batch/scaling_sweep.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>

#include <seamcl/batch/bench_merge.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>

namespace seamcl {
namespace {

using nlohmann::json;

constexpr SweepAxis kAxes[] = {SweepAxis::Pixels, SweepAxis::Faces, SweepAxis::Msaa, SweepAxis::Texels};

std::string known_axes() {
  std::string known;
  for (const std::string& name : sweep_axis_names()) known += (known.empty() ? "" : ", ") + name;
  return known + ", all";
}

std::string x_label(SweepAxis axis) {
  switch (axis) {
    case SweepAxis::Pixels: return "pixels";
    case SweepAxis::Faces: return "faces";
    case SweepAxis::Msaa: return "msaa samples per pixel";
    case SweepAxis::Texels: return "texels (all levels)";
  }
  return "";
}

// The targets: 32x pixels in at most 34x time; 40x faces in at most 1.2x time.
struct Target {
  double x_ratio;
  double max_time_ratio;
};
std::optional<Target> target_of(SweepAxis axis) {
  if (axis == SweepAxis::Pixels) return Target{32.0, 34.0};
  if (axis == SweepAxis::Faces) return Target{40.0, 1.2};
  return std::nullopt;
}

struct MethodTimes {
  std::string method;
  std::vector<StageTimes> runs;
};

json stage_medians(const std::vector<StageTimes>& runs) {
  auto median_stage = [&](double StageTimes::*stage) {
    std::vector<double> v;
    for (const StageTimes& t : runs) v.push_back(t.*stage);
    return median_of(v);
  };
  return {{"setup", median_stage(&StageTimes::setup)},
          {"binning", median_stage(&StageTimes::binning)},
          {"raster", median_stage(&StageTimes::raster)},
          {"shade", median_stage(&StageTimes::shade)},
          {"readback", median_stage(&StageTimes::readback)}};
}

// A point's options for one of the settings' methods.
RenderOptions point_options(const SweepSettings& settings, const SweepPoint& point, const std::string& method) {
  RenderOptions options = settings.base;
  options.method = *parse_method(method);
  options.width = point.width;
  options.height = point.height;
  options.msaa = point.msaa;
  return options;
}

// The groups of consecutive points that share a scene (the same generator options): [begin, end).
std::vector<std::pair<size_t, size_t>> scene_groups(const std::vector<SweepPoint>& points) {
  const auto key_of = [](const SweepPoint& p) { return std::pair{p.faces, p.texture_scale_log2}; };
  std::vector<std::pair<size_t, size_t>> groups;
  for (size_t begin = 0; begin < points.size();) {
    size_t end = begin;
    while (end < points.size() && key_of(points[end]) == key_of(points[begin])) ++end;
    groups.emplace_back(begin, end);
    begin = end;
  }
  return groups;
}

Scene make_point_scene(const SweepSettings& settings, const SweepPoint& point) {
  GeneratorOptions generator;
  generator.tint = settings.base.tint;
  generator.defer_textures = true;
  generator.faces = point.faces;
  generator.texture_scale_log2 = point.texture_scale_log2;
  return settings.make_scene(generator);
}

// How the refusal names a group: its last point, the largest of it.
std::string describe_group(SweepAxis axis, const std::vector<SweepPoint>& points, const SceneSizes& scene) {
  const SweepPoint& p = points.back();
  return "the " + to_string(axis) + " sweep's point at " + std::to_string(p.width) + "x" + std::to_string(p.height) +
         " msaa " + std::to_string(p.msaa) + ", " + std::to_string(scene.faces.size()) + " faces" +
         (p.texture_scale_log2 ? ", textures x2^" + std::to_string(*p.texture_scale_log2) : "");
}

}  // namespace

SweepMemory refuse_sweep_group_beyond_machine(SweepAxis axis, const SceneSizes& scene, const std::vector<SweepPoint>& points,
                                             const SweepSettings& settings, const SweepMemory* first, const DeviceInfo& device) {
  // A Renderer keeps the largest of each buffer any request needed; the points grow along the
  // axis, so the peak is about the largest render's (the larger of the figures, not the sum).
  SweepMemory group;
  for (const SweepPoint& point : points) {
    for (const std::string& method : settings.methods) {
      const RenderMemory m = render_memory(scene, point_options(settings, point, method));
      group.device = larger(group.device, m.device_shares(frame_buffers_field(point.msaa)));
      group.host = larger(group.host, m.host_shares());
    }
  }
  SweepMemory held = group;
  if (first) {
    held.device.add(first->device);
    held.host.add(first->host);
  }
  refuse_beyond_machine(held.device, held.host, device, describe_group(axis, points, scene));
  return group;
}

void refuse_sweeps_beyond_machine(const std::vector<SweepAxis>& axes, const SweepSettings& settings, const DeviceInfo& device) {
  validate_sweep(axes, settings);
  for (SweepAxis axis : axes) {
    const std::vector<SweepPoint> points = sweep_points(axis, settings.base);
    std::optional<SweepMemory> first;
    for (const auto& [begin, end] : scene_groups(points)) {
      const SceneSizes sizes = scene_sizes(make_point_scene(settings, points[begin]));
      const std::vector<SweepPoint> group(points.begin() + static_cast<long>(begin), points.begin() + static_cast<long>(end));
      const SweepMemory memory = refuse_sweep_group_beyond_machine(axis, sizes, group, settings, first ? &*first : nullptr, device);
      if (begin == 0) first = memory;
    }
  }
}

std::optional<SweepAxis> parse_sweep_axis(std::string_view name) {
  for (SweepAxis axis : kAxes)
    if (to_string(axis) == name) return axis;
  return std::nullopt;
}

std::string to_string(SweepAxis axis) {
  switch (axis) {
    case SweepAxis::Pixels: return "pixels";
    case SweepAxis::Faces: return "faces";
    case SweepAxis::Msaa: return "msaa";
    case SweepAxis::Texels: return "texels";
  }
  return "";
}

std::vector<std::string> sweep_axis_names() {
  std::vector<std::string> names;
  for (SweepAxis axis : kAxes) names.push_back(to_string(axis));
  return names;
}

std::vector<SweepAxis> parse_sweep(const std::string& value) {
  if (value == "all") return {std::begin(kAxes), std::end(kAxes)};
  std::vector<SweepAxis> axes;
  for (const std::string& name : split_list(value, "sweep")) {
    const std::optional<SweepAxis> axis = parse_sweep_axis(name);
    if (!axis) throw InputError("sweep", "unknown sweep '" + name + "' (known: " + known_axes() + ")");
    if (std::find(axes.begin(), axes.end(), *axis) != axes.end())
      throw InputError("sweep", "'" + name + "' is named twice");
    axes.push_back(*axis);
  }
  return axes;
}

std::vector<SweepPoint> sweep_points(SweepAxis axis, const RenderOptions& base) {
  std::vector<SweepPoint> points;
  const SweepPoint fixed{base.width, base.height, base.msaa, std::nullopt, std::nullopt};
  switch (axis) {
    case SweepAxis::Pixels:
      // 1x, 2x, ..., 32x the pixels of 480x540, ending at 3840x2160.
      for (auto [w, h] : {std::pair{480, 540}, {960, 540}, {960, 1080}, {1920, 1080}, {1920, 2160}, {3840, 2160}})
        points.push_back({w, h, base.msaa, std::nullopt, std::nullopt});
      break;
    case SweepAxis::Faces:
      for (int factor : {1, 2, 4, 10, 20, 40, 80}) {
        SweepPoint p = fixed;
        p.faces = kPaperFaces * factor;
        points.push_back(p);
      }
      break;
    case SweepAxis::Msaa:
      for (int rate : {1, 2, 4, 8, 16}) {
        SweepPoint p = fixed;
        p.msaa = rate;
        points.push_back(p);
      }
      break;
    case SweepAxis::Texels:
      for (int k = -3; k <= kMaxTextureScaleLog2; ++k) {
        SweepPoint p = fixed;
        p.texture_scale_log2 = k;
        points.push_back(p);
      }
      break;
  }
  return points;
}

bool sweep_reads_base_size(SweepAxis axis) { return axis != SweepAxis::Pixels; }

void validate_sweep(const std::vector<SweepAxis>& axes, const SweepSettings& settings) {
  if (axes.empty()) throw InputError("sweep", "names no sweep (known: " + known_axes() + ")");
  if (settings.methods.empty()) throw InputError("methods", "names no method");
  for (const std::string& method : settings.methods)
    if (!parse_method(method)) throw InputError("methods", "unknown method '" + method + "'");
  if (settings.repeats < 1 || settings.repeats > 100) throw InputError("sweep_repeats", "must be in 1..100");
  for (SweepAxis axis : axes) {
    if ((axis == SweepAxis::Faces || axis == SweepAxis::Texels) && settings.base.scene != "paper") {
      throw InputError("scene", "the " + to_string(axis) + " sweep subdivides or rescales the paper scene, not '" +
                                    settings.base.scene + "'");
    }
  }
  if (!settings.make_scene) throw std::invalid_argument("validate_sweep: no make_scene");
}

json run_scaling_sweeps(ClRuntime& runtime, const std::vector<SweepAxis>& axes, const SweepSettings& settings) {
  validate_sweep(axes, settings);
  const auto wall_start = std::chrono::steady_clock::now();
  json sweeps = json::array();
  for (SweepAxis axis : axes) {
    const std::vector<SweepPoint> points = sweep_points(axis, settings.base);
    const size_t method_count = settings.methods.size();
    std::vector<json> point_json(points.size());
    std::vector<std::vector<double>> totals(method_count, std::vector<double>(points.size()));  // medians
    std::vector<std::vector<double>> minima(method_count, std::vector<double>(points.size()));
    std::vector<double> xs(points.size());
    auto options_of = [&](const SweepPoint& point, size_t m) { return point_options(settings, point, settings.methods[m]); };
    // Points that share a scene (pixels, msaa: all of them) are measured together, the repeats
    // interleaved (every point and method once per round), so that the machine's load, which
    // drifts, falls on all of them alike. A point with a scene of its own (faces, texels) is
    // measured with the first point's renderer kept loaded beside it, the two rendered in turn, so
    // that its ratio to the first point is of renders side by side (a slow spell during one point
    // no longer skews its ratio): paired_first[i][m] holds those renders of the first point.
    std::optional<Camera> first_camera;  // the renderer holds its own copy of the scene
    std::unique_ptr<Renderer> first_renderer;
    std::vector<std::vector<std::vector<double>>> paired_first(points.size(), std::vector<std::vector<double>>(method_count));
    std::optional<SweepMemory> first_memory;
    for (const auto& [begin, end] : scene_groups(points)) {
      auto scene = std::make_unique<Scene>(make_point_scene(settings, points[begin]));
      // Before its Renderer allocates: a later group may need more than the machine has, and
      // the Renderer's byte limit would catch only the tile lists' growth mid-render.
      const SweepMemory memory = refuse_sweep_group_beyond_machine(
          axis, scene_sizes(*scene), std::vector<SweepPoint>(points.begin() + static_cast<long>(begin), points.begin() + static_cast<long>(end)),
          settings, first_renderer ? &*first_memory : nullptr, runtime.info());
      auto held = std::make_unique<Renderer>(runtime);
      Renderer& renderer = *held;
      renderer.set_device_byte_limit(settings.device_byte_limit);
      renderer.load_scene(*scene, settings.base.texels);
      for (size_t i = begin; i < end; ++i) {
        for (size_t m = 0; m < method_count; ++m) {
          if (settings.progress) {
            settings.progress("sweep " + to_string(axis) + ": " + std::to_string(points[i].width) + "x" +
                              std::to_string(points[i].height) + " msaa " + std::to_string(points[i].msaa) + ", " +
                              std::to_string(scene->faces.size()) + " faces, " + std::to_string(scene->texel_count()) +
                              " texels, " + settings.methods[m]);
          }
          renderer.warm_up(options_of(points[i], m));
        }
      }
      std::vector<std::vector<std::vector<StageTimes>>> runs(end - begin, std::vector<std::vector<StageTimes>>(method_count));
      std::vector<unsigned> fragments(end - begin, 0);
      const bool paired = first_renderer != nullptr;
      for (int r = 0; r < settings.repeats; ++r) {
        for (size_t i = begin; i < end; ++i) {
          for (size_t m = 0; m < method_count; ++m) {
            if (paired) {
              paired_first[i][m].push_back(first_renderer->render(*first_camera, options_of(points[0], m)).ms.total);
            }
            const RenderResult result = renderer.render(scene->camera, options_of(points[i], m));
            runs[i - begin][m].push_back(result.ms);
            fragments[i - begin] = result.stats.fragments;
          }
        }
      }
      for (size_t i = begin; i < end; ++i) {
        const SweepPoint& point = points[i];
        json results = json::array();
        for (size_t m = 0; m < method_count; ++m) {
          std::vector<double> total;
          for (const StageTimes& t : runs[i - begin][m]) total.push_back(t.total);
          json ms = bench_timing_stats(total);
          totals[m][i] = ms.at("median").get<double>();
          minima[m][i] = ms.at("min").get<double>();
          results.push_back({{"method", settings.methods[m]}, {"ms", ms}, {"stages", stage_medians(runs[i - begin][m])}});
        }
        const size_t pixels = static_cast<size_t>(point.width) * static_cast<size_t>(point.height);
        double x = 0;
        switch (axis) {
          case SweepAxis::Pixels: x = static_cast<double>(pixels); break;
          case SweepAxis::Faces: x = static_cast<double>(scene->faces.size()); break;
          case SweepAxis::Msaa: x = point.msaa; break;
          case SweepAxis::Texels: x = static_cast<double>(scene->texel_count()); break;
        }
        xs[i] = x;
        point_json[i] = {{"x", x},
                         {"width", point.width},
                         {"height", point.height},
                         {"pixels", pixels},
                         {"msaa", point.msaa},
                         {"faces", scene->faces.size()},
                         {"triangles", scene->triangle_count()},
                         {"texels", scene->texel_count()},
                         {"packed_texel_bytes", renderer.packed_scene().texture_bytes()},
                         {"fragments", fragments[i - begin]},
                         {"generator_faces", point.faces ? json(*point.faces) : json(nullptr)},
                         {"texture_scale_log2", point.texture_scale_log2 ? json(*point.texture_scale_log2) : json(nullptr)},
                         {"results", results}};
      }
      // The first point's scene and renderer stay for the points after it, when each has its own.
      if (begin == 0 && end < points.size()) {
        first_camera = scene->camera;
        first_renderer = std::move(held);
        first_memory = memory;
      }
    }
    first_renderer.reset();
    const json point_list = point_json;
    // Ratios from the first point: to the target's point (the first at or past its x ratio) and
    // to the last.
    json ratios = json::array();
    const std::optional<Target> target = target_of(axis);
    for (size_t m = 0; m < method_count; ++m) {
      std::vector<size_t> ends;
      if (target) {
        for (size_t i = 1; i < xs.size(); ++i) {
          if (xs[i] / xs[0] >= target->x_ratio * 0.97) {  // the generator's face counts are within 2% of asked
            ends.push_back(i);
            break;
          }
        }
      }
      if (xs.size() > 1 && (ends.empty() || ends.back() != xs.size() - 1)) ends.push_back(xs.size() - 1);
      for (size_t i : ends) {
        const double x_ratio = xs[i] / xs[0];
        // Against the first point's renders beside this point's where it had its own scene.
        const std::vector<double>& beside = paired_first[i][m];
        const double first_median = beside.empty() ? totals[m][0] : median_of(beside);
        const double first_minimum = beside.empty() ? minima[m][0] : *std::min_element(beside.begin(), beside.end());
        const double time_ratio = totals[m][i] / first_median;
        const bool has_target = target && std::abs(x_ratio / target->x_ratio - 1.0) < 0.05;
        ratios.push_back({{"method", settings.methods[m]},
                          {"from_x", xs[0]},
                          {"to_x", xs[i]},
                          {"x_ratio", x_ratio},
                          {"time_ratio", time_ratio},
                          // The fastest renders' ratio: the least disturbed by a shared machine.
                          {"time_ratio_of_minima", minima[m][i] / first_minimum},
                          // The first point's median over the renders this ratio divides by.
                          {"from_ms", first_median},
                          {"from_renders_beside", !beside.empty()},
                          {"from_frames", beside.empty() ? static_cast<size_t>(settings.repeats) : beside.size()},
                          {"max_time_ratio", has_target ? json(target->max_time_ratio) : json(nullptr)},
                          {"met", has_target ? json(time_ratio <= target->max_time_ratio) : json(nullptr)}});
      }
    }
    sweeps.push_back({{"axis", to_string(axis)}, {"x_label", x_label(axis)}, {"points", point_list}, {"ratios", ratios}});
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return {{"kind", "scaling_sweep"},
          {"device", runtime.device_description()},
          {"options", to_json(settings.base)},
          {"methods", settings.methods},
          {"repeats", settings.repeats},
          {"sweeps", sweeps},
          {"memory", {{"peak_rss_bytes", process_memory().peak_rss_bytes}}},
          {"wall_s", wall_s}};
}

}  // namespace seamcl
