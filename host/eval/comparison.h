// Rendering one frame with several methods x MSAA rates, timing each (OpenCL profiling) and
// measuring it against a reference image: the loop `seamcl compare` runs once, `seamcl bench` runs
// per frame of an orbit, and the HTTP service can run for POST /v1/compare. Also the comma-list
// parsing those commands share, and the JSON forms of the results (the keys of design.md's
// compare/bench contract).
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/core/cancelled.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/pipeline/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// "a,b , c" -> {"a", "b", "c"}; InputError(field) for an empty list or an empty item.
std::vector<std::string> split_list(const std::string& text, const std::string& field);
// "1,2,4" -> {1, 2, 4}; InputError(field) for a non-integer item.
std::vector<int> parse_int_list(const std::string& text, const std::string& field);

// One method at one MSAA rate: the name as given and the parsed options of the render.
struct MethodEntry {
  std::string method_name;
  RenderOptions options;
};

// Every method x every rate over `base` (a parse_render_options request), method-major.
// Validates everything; an unknown method is InputError("methods"), a bad rate InputError("msaa").
std::vector<MethodEntry> method_entries(const nlohmann::json& base, const std::vector<std::string>& methods,
                                        const std::vector<int>& rates);

struct EntryResult {
  MethodEntry entry;
  std::vector<StageTimes> runs;           // one per timed render
  RenderResult last;                      // the last render (its pixels are measured)
  std::optional<ImageErrors> errors;      // against the reference, when one was given
  size_t texture_bytes = 0;               // packed texture memory the method used (bands included)
  size_t padding_bytes = 0;               // the guard bands' share of texture_bytes
  size_t adjacency_bytes = 0;             // the neighbour table (read by traverse only)
  std::vector<double> total_ms() const;   // runs[i].total
};

// Renders `options` `repeat` times with `renderer` (scene loaded, warmed up by the caller) and,
// with a reference (and optionally a seam mask) of the same size, measures the last image.
// should_stop is asked before every render; when it says stop, Cancelled is thrown.
EntryResult measure_entry(Renderer& renderer, const Camera& camera, const MethodEntry& entry, int repeat,
                          const std::vector<glm::vec4>* reference, const std::vector<uint8_t>* seam_mask,
                          const ShouldStop& should_stop = {});

// seamcl compare's loop: per entry, (re)load `scene` in the entry's texel format, warm up, then
// measure_entry. Entries are measured one after the other (entry-major). should_stop is asked
// before every entry and before every timed render (so a stop waits for one render at most);
// when it says stop, Cancelled is thrown and nothing is returned.
std::vector<EntryResult> compare_methods(Renderer& renderer, const Scene& scene, const Camera& camera,
                                         const std::vector<MethodEntry>& entries,
                                         const std::vector<glm::vec4>* reference,
                                         const std::vector<uint8_t>* seam_mask, int repeat,
                                         const ShouldStop& should_stop = {});

double median_of(std::vector<double> values);
// JSON numbers must be finite: NaN/Inf become 0.
double finite_or_zero(double v);

// [[x_0, y_0], ...] for error_curve_thresholds() and `stats.curve`.
nlohmann::json curve_json(const ErrorStats& stats);
// {"mean","p99","max","seam_mean","seam_p99","seam_max","nan_pixels","seam_nan_pixels","pixels","seam_pixels"}
nlohmann::json errors_json(const ImageErrors& errors);
// One `results` item of seamcl compare: method, msaa, aniso, filter, ms {median,min,max,runs},
// error, texture_bytes, curve, seam_curve (the last three need errors).
nlohmann::json compare_result_json(const EntryResult& result);

}  // namespace seamcl
