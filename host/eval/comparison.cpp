#include <seamcl/eval/comparison.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>

#include <seamcl/core/input_error.h>

namespace seamcl {

using nlohmann::json;

std::vector<std::string> split_list(const std::string& text, const std::string& field) {
  std::vector<std::string> items;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const size_t a = item.find_first_not_of(" \t"), b = item.find_last_not_of(" \t");
    if (a == std::string::npos) throw InputError(field, "empty item in list '" + text + "'");
    items.push_back(item.substr(a, b - a + 1));
  }
  if (items.empty() || text.back() == ',') throw InputError(field, "must be a comma list, got '" + text + "'");
  return items;
}

std::vector<int> parse_int_list(const std::string& text, const std::string& field) {
  std::vector<int> values;
  for (const std::string& item : split_list(text, field)) {
    size_t used = 0;
    int value = 0;
    try {
      value = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size()) throw InputError(field, "not an integer: '" + item + "'");
    values.push_back(value);
  }
  return values;
}

std::vector<MethodEntry> method_entries(const json& base, const std::vector<std::string>& methods,
                                        const std::vector<int>& rates) {
  std::vector<MethodEntry> entries;
  for (const std::string& method : methods) {
    for (int msaa : rates) {
      json request = base;
      request["method"] = method;
      request["msaa"] = msaa;
      try {
        entries.push_back({method, parse_render_options(request)});
      } catch (const InputError& e) {
        if (e.field() == "method") throw InputError("methods", std::string(e.what()).substr(e.field().size() + 2));
        throw;
      }
    }
  }
  return entries;
}

std::vector<double> EntryResult::total_ms() const {
  std::vector<double> ms;
  for (const StageTimes& t : runs) ms.push_back(t.total);
  return ms;
}

EntryResult measure_entry(Renderer& renderer, const Camera& camera, const MethodEntry& entry, int repeat,
                          const std::vector<glm::vec4>* reference, const std::vector<uint8_t>* seam_mask,
                          const ShouldStop& should_stop) {
  EntryTargets targets;
  if (reference) targets.references.emplace_back("paper", reference);
  targets.seam_mask = seam_mask;
  return measure_entry(renderer, camera, entry, repeat, targets, should_stop);
}

EntryResult measure_entry(Renderer& renderer, const Camera& camera, const MethodEntry& entry, int repeat,
                          const EntryTargets& targets, const ShouldStop& should_stop) {
  EntryResult out;
  out.entry = entry;
  for (int i = 0; i < repeat; ++i) {
    throw_if_stopped(should_stop, "between renders of " + entry.method_name + " at msaa " + std::to_string(entry.options.msaa));
    out.last = renderer.render(camera, entry.options);
    out.runs.push_back(out.last.ms);
  }
  for (const auto& [name, reference] : targets.references) {
    out.errors_by_reference.emplace_back(name, compare_images(out.last.pixels, *reference, targets.seam_mask));
  }
  if (!out.errors_by_reference.empty()) out.errors = out.errors_by_reference.front().second;
  const PackedScene& packed = renderer.packed_scene();
  out.texture_bytes = packed.texture_bytes();
  out.padding_bytes = packed.padding_bytes();
  out.adjacency_bytes = reads_adjacency(entry.options.method) ? packed.adjacency_bytes() : 0;
  return out;
}

std::vector<EntryResult> compare_methods(Renderer& renderer, const Scene& scene, const Camera& camera,
                                         const std::vector<MethodEntry>& entries,
                                         const std::vector<glm::vec4>* reference,
                                         const std::vector<uint8_t>* seam_mask, int repeat,
                                         const ShouldStop& should_stop) {
  EntryTargets targets;
  if (reference) targets.references.emplace_back("paper", reference);
  targets.seam_mask = seam_mask;
  return compare_methods(renderer, scene, camera, entries, [&](const MethodEntry&) { return targets; }, repeat,
                         should_stop, {});
}

std::vector<EntryResult> compare_methods(Renderer& renderer, const Scene& scene, const Camera& camera,
                                         const std::vector<MethodEntry>& entries, const TargetsFor& targets,
                                         int repeat, const ShouldStop& should_stop, const Progress& progress) {
  std::vector<EntryResult> results;
  for (size_t i = 0; i < entries.size(); ++i) {
    const MethodEntry& entry = entries[i];
    throw_if_stopped(should_stop, "before " + entry.method_name + " at msaa " + std::to_string(entry.options.msaa));
    if (progress) {
      progress("entry " + std::to_string(i + 1) + "/" + std::to_string(entries.size()) + ": " + entry.method_name +
               " at msaa " + std::to_string(entry.options.msaa));
    }
    // Only into an empty renderer: render() repacks by itself when an entry's texel format or
    // guard band differs, so loading again only copied and baked the scene once more (about 2 s
    // of paper's compare, its textures baked from their functions face by face).
    if (i == 0 && !renderer.has_scene()) renderer.load_scene(scene, entry.options.texels);
    renderer.warm_up(entry.options);
    results.push_back(measure_entry(renderer, camera, entry, repeat, targets(entry), should_stop));
  }
  return results;
}

EntryTargets ComparisonTargets::for_entry(const MethodEntry& entry) const {
  EntryTargets t;
  size_t next_high_res = 0;
  for (ReferenceKind kind : kinds) {
    const ReferenceImage& reference =
        kind == ReferenceKind::Seamless ? seamless_by_rate.at(entry.options.msaa) : high_res.at(next_high_res++);
    t.references.emplace_back(to_string(kind), &reference.pixels);
  }
  t.seam_mask = &masks.at(entry.options.msaa);
  return t;
}

const ReferenceImage& ComparisonTargets::first() const {
  return kinds.front() == ReferenceKind::Seamless ? seamless_by_rate.begin()->second : high_res.front();
}

json ComparisonTargets::summary_json(int first_rate, bool with_cache_path) const {
  json references = json::array();
  size_t next_high_res = 0;
  for (ReferenceKind kind : kinds) {
    references.push_back(kind == ReferenceKind::Seamless ? reference_json(seamless_by_rate.begin()->second, with_cache_path)
                                                         : reference_json(high_res.at(next_high_res++), with_cache_path));
  }
  json by_msaa = json::object();
  for (const auto& [msaa, mask] : masks) {
    const size_t pixels = static_cast<size_t>(std::count(mask.begin(), mask.end(), uint8_t{SEAMCL_MASK_SEAM}));
    const size_t boundary = static_cast<size_t>(std::count(mask.begin(), mask.end(), uint8_t{SEAMCL_MASK_BOUNDARY}));
    by_msaa[std::to_string(msaa)] = {
        {"pixels", pixels},
        {"coverage", mask.empty() ? 0.0 : static_cast<double>(pixels) / static_cast<double>(mask.size())},
        {"boundary_pixels", boundary}};
  }
  const std::vector<uint8_t>& mask = masks.at(first_rate);
  return {{"reference_method", first().method},
          {"reference", reference_json(first(), with_cache_path)},
          {"references", references},
          {"seam_pixels", static_cast<size_t>(std::count(mask.begin(), mask.end(), uint8_t{SEAMCL_MASK_SEAM}))},
          {"seam_mask", {{"definition", "footprint"}, {"by_msaa", by_msaa}}}};
}

ComparisonTargets prepare_targets(ClRuntime& runtime, Renderer& renderer, const Camera& camera,
                                  const RenderOptions& frame, const std::vector<MethodEntry>& entries,
                                  const ReferenceSettings& settings, const std::vector<ReferenceKind>& kinds,
                                  const Progress& progress) {
  ComparisonTargets targets;
  targets.kinds = kinds;
  if (kinds.empty()) throw InputError("reference", "name at least one reference");
  const Scene& scene = renderer.scene();
  std::vector<ReferenceKind> high_res_kinds;
  for (ReferenceKind kind : kinds)
    if (kind != ReferenceKind::Seamless) high_res_kinds.push_back(kind);
  const bool analytic = std::find(kinds.begin(), kinds.end(), ReferenceKind::Analytic) != kinds.end();
  if (analytic && !scene.albedo) {
    throw InputError("reference", "the analytic reference needs the function the textures were baked from; scene '" +
                                      scene.name + "' has none (its textures came from files)");
  }
  std::optional<Scene> seamless;
  if (high_res_kinds.size() != kinds.size()) seamless = seamless_scene(scene);
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };

  for (const MethodEntry& entry : entries) {
    if (targets.masks.count(entry.options.msaa)) continue;
    say("seam mask at msaa " + std::to_string(entry.options.msaa));
    targets.masks[entry.options.msaa] = footprint_seam_mask(renderer, camera, entry.options);
  }
  // The masks' frame buffers go before the references' (compare_memory counts them apart).
  renderer.release_frame_buffers();
  if (!high_res_kinds.empty()) {
    const RenderOptions high = reference_render_options(frame, settings);
    std::string names;
    for (ReferenceKind kind : high_res_kinds) names += (names.empty() ? "" : ", ") + to_string(kind);
    say("references " + names + " from one " + std::to_string(high.width) + "x" + std::to_string(high.height) +
        " render (or the cache)");
    targets.high_res = reference_images(renderer, camera, frame, settings, high_res_kinds);
  }
  if (seamless) {
    Renderer seamless_renderer(runtime);
    seamless_renderer.set_device_byte_limit(renderer.device_byte_limit());  // the caller's bound is the compare's
    seamless_renderer.load_scene(*seamless, frame.texels);
    for (const MethodEntry& entry : entries) {
      if (targets.seamless_by_rate.count(entry.options.msaa)) continue;
      say("seamless reference at msaa " + std::to_string(entry.options.msaa));
      targets.seamless_by_rate[entry.options.msaa] = seamless_reference(seamless_renderer, camera, entry.options);
    }
  }
  return targets;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double finite_or_zero(double v) { return std::isfinite(v) ? v : 0.0; }

json curve_json(const ErrorStats& stats) {
  const std::vector<double> xs = error_curve_thresholds();
  json curve = json::array();
  for (size_t i = 0; i < xs.size() && i < stats.curve.size(); ++i) curve.push_back({xs[i], stats.curve[i]});
  return curve;
}

json errors_json(const ImageErrors& errors) {
  return {{"mean", finite_or_zero(errors.all.mean)},
          {"p99", finite_or_zero(errors.all.p99)},
          {"max", finite_or_zero(errors.all.max)},
          {"seam_mean", finite_or_zero(errors.seam.mean)},
          {"seam_p99", finite_or_zero(errors.seam.p99)},
          {"seam_max", finite_or_zero(errors.seam.max)},
          {"off_seam_mean", finite_or_zero(errors.off_seam.mean)},
          {"off_seam_p99", finite_or_zero(errors.off_seam.p99)},
          {"off_seam_max", finite_or_zero(errors.off_seam.max)},
          {"nan_pixels", errors.nan_pixels},
          {"seam_nan_pixels", errors.seam_nan_pixels},
          {"pixels", errors.all.pixels},
          {"seam_pixels", errors.seam.pixels},
          {"off_seam_pixels", errors.off_seam.pixels},
          {"seam_coverage", finite_or_zero(errors.seam_coverage)}};
}

json compare_result_json(const EntryResult& result) {
  const RenderOptions& options = result.entry.options;
  const std::vector<double> ms = result.total_ms();
  json item = {{"method", result.entry.method_name},
               {"msaa", options.msaa},
               {"aniso", options.aniso},
               {"filter", to_string(options.filter)},
               {"ms",
                {{"median", median_of(ms)},
                 {"min", ms.empty() ? 0.0 : *std::min_element(ms.begin(), ms.end())},
                 {"max", ms.empty() ? 0.0 : *std::max_element(ms.begin(), ms.end())},
                 {"runs", ms.size()}}},
               {"texture_bytes", result.texture_bytes}};
  if (result.errors) {
    item["error"] = errors_json(*result.errors);
    item["curve"] = curve_json(result.errors->all);
    item["seam_curve"] = curve_json(result.errors->seam);
  }
  if (result.errors_by_reference.size() > 1) {
    json by_reference = json::object();
    for (const auto& [name, errors] : result.errors_by_reference) by_reference[name] = errors_json(errors);
    item["errors"] = by_reference;
  }
  return item;
}

}  // namespace seamcl
