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
  EntryResult out;
  out.entry = entry;
  for (int i = 0; i < repeat; ++i) {
    throw_if_stopped(should_stop, "between renders of " + entry.method_name + " at msaa " + std::to_string(entry.options.msaa));
    out.last = renderer.render(camera, entry.options);
    out.runs.push_back(out.last.ms);
  }
  if (reference) out.errors = compare_images(out.last.pixels, *reference, seam_mask);
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
  std::vector<EntryResult> results;
  for (const MethodEntry& entry : entries) {
    throw_if_stopped(should_stop, "before " + entry.method_name + " at msaa " + std::to_string(entry.options.msaa));
    renderer.load_scene(scene, entry.options.texels);
    renderer.warm_up(entry.options);
    results.push_back(measure_entry(renderer, camera, entry, repeat, reference, seam_mask, should_stop));
  }
  return results;
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
          {"nan_pixels", errors.nan_pixels},
          {"seam_nan_pixels", errors.seam_nan_pixels},
          {"pixels", errors.all.pixels},
          {"seam_pixels", errors.seam.pixels}};
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
  return item;
}

}  // namespace seamcl
