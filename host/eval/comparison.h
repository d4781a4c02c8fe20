// Rendering one frame with several methods x MSAA rates, timing each (OpenCL profiling) and
// measuring it against a reference image: the loop `seamcl compare` runs once, `seamcl bench` runs
// per frame of an orbit, and the HTTP service can run for POST /v1/compare. Also the comma-list
// parsing those commands share, and the JSON forms of the results (the keys of design.md's
// compare/bench contract).
#pragma once
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/core/cancelled.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/options/render_options.h>
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

// What one entry's image is measured against: named references (the first is the one `errors`
// and the JSON's `error` report) and the seam mask of the entry's frame (its rate, shading,
// filter and anisotropy). The pointers must outlive the measurement.
struct EntryTargets {
  std::vector<std::pair<std::string, const std::vector<glm::vec4>*>> references;
  const std::vector<uint8_t>* seam_mask = nullptr;
};
using TargetsFor = std::function<EntryTargets(const MethodEntry&)>;
// One line of progress ("entry 3/10: traverse at msaa 8"), for a long compare to report on stderr.
using Progress = std::function<void(const std::string&)>;

struct EntryResult {
  MethodEntry entry;
  std::vector<StageTimes> runs;           // one per timed render
  RenderResult last;                      // the last render (its pixels are measured)
  std::optional<ImageErrors> errors;      // against the (first) reference, when one was given
  std::vector<std::pair<std::string, ImageErrors>> errors_by_reference;  // every reference, named
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

// measure_entry against every target reference and the target mask.
EntryResult measure_entry(Renderer& renderer, const Camera& camera, const MethodEntry& entry, int repeat,
                          const EntryTargets& targets, const ShouldStop& should_stop = {});

// seamcl compare's loop: the scene the renderer holds (`scene` is loaded only into a renderer that
// holds none; a caller loads it first, as it made the targets from it), then per entry warm up and
// measure_entry. Entries are measured one after the other (entry-major). should_stop is asked
// before every entry and before every timed render (so a stop waits for one render at most);
// when it says stop, Cancelled is thrown and nothing is returned.
std::vector<EntryResult> compare_methods(Renderer& renderer, const Scene& scene, const Camera& camera,
                                         const std::vector<MethodEntry>& entries,
                                         const std::vector<glm::vec4>* reference,
                                         const std::vector<uint8_t>* seam_mask, int repeat,
                                         const ShouldStop& should_stop = {});
// The same, measuring each entry against targets(entry), and reporting each entry to `progress`
// before it starts.
std::vector<EntryResult> compare_methods(Renderer& renderer, const Scene& scene, const Camera& camera,
                                         const std::vector<MethodEntry>& entries, const TargetsFor& targets,
                                         int repeat, const ShouldStop& should_stop, const Progress& progress);

// Everything a compare measures against, made before the entries run: the footprint seam mask
// of each rate measured, the 8x references (paper, box, analytic: one render for all), and the
// seamless reference of each rate. The references come in the order asked for.
struct ComparisonTargets {
  std::vector<ReferenceKind> kinds;
  std::vector<ReferenceImage> high_res;             // the kinds other than seamless, in order
  std::map<int, ReferenceImage> seamless_by_rate;   // with seamless
  std::map<int, std::vector<uint8_t>> masks;        // footprint_seam_mask per rate
  // Each reference by name (the first is `error`'s), with the entry's rate's mask.
  EntryTargets for_entry(const MethodEntry& entry) const;
  // The first reference (for the seamless kind, its lowest rate's).
  const ReferenceImage& first() const;
  // The compare answer's keys about them: reference_method, reference, references (each
  // reference_json), seam_pixels (the mask of the first entry's rate) and seam_mask
  // {definition: "footprint", by_msaa: {"1": {pixels, coverage, boundary_pixels}, ...}}.
  nlohmann::json summary_json(int first_rate, bool with_cache_path) const;
};

// Validates and makes the targets. A seamless reference on a scene that has none, or analytic
// on a scene without an albedo function, is InputError("reference") before any render.
// `runtime` builds the seamless scene's own Renderer, held to `renderer`'s device byte limit.
ComparisonTargets prepare_targets(ClRuntime& runtime, Renderer& renderer, const Camera& camera,
                                  const RenderOptions& frame, const std::vector<MethodEntry>& entries,
                                  const ReferenceSettings& settings, const std::vector<ReferenceKind>& kinds,
                                  const Progress& progress = {});

double median_of(std::vector<double> values);
// JSON numbers must be finite: NaN/Inf become 0.
double finite_or_zero(double v);

// [[x_0, y_0], ...] for error_curve_thresholds() and `stats.curve`.
nlohmann::json curve_json(const ErrorStats& stats);
// {"mean","p99","max","seam_mean","seam_p99","seam_max","off_seam_mean","off_seam_p99",
//  "off_seam_max","nan_pixels","seam_nan_pixels","pixels","seam_pixels","off_seam_pixels",
//  "seam_coverage"}
nlohmann::json errors_json(const ImageErrors& errors);
// One `results` item of seamcl compare: method, msaa, aniso, filter, ms {median,min,max,runs},
// error, texture_bytes, curve, seam_curve (the last three need errors), and with more than one
// reference `errors` {name: errors_json} for each.
nlohmann::json compare_result_json(const EntryResult& result);

}  // namespace seamcl
