// The compare job: one frame rendered with every method x MSAA rate, each measured against the
// references (host/eval/reference.h) with the seam mask, timed; what `seamcl compare`, POST
// /v1/compare and seamcl.compare() run. The sequence, once: parse -> entries -> plan (estimate) ->
// [the front end refuses or admits] -> targets (seam masks, references) -> entries -> result JSON.
#pragma once
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/reference.h>
#include <seamcl/jobs/job.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

// The compare request's options: the frame's render options (but `method`, and `msaa`, which is a
// list here) and the compare's own: methods, msaa, repeat, reference, reference_method,
// reference_msaa, constant_color.
const OptionTable& compare_option_table();

// A compare's images and figures, for the front end to answer with.
struct CompareRun {
  ComparisonTargets targets;
  std::vector<EntryResult> measured;
  nlohmann::json displacement;  // the displaced surface's gap and cracks (a displaced frame only)
  // Wall milliseconds of run()'s parts: the seam masks and references (targets), the entries
  // (warm-up and timed renders and their measurement), the whole run. The reference goal of
  // docs/benchmarks.md: total_ms within 1.2x targets_ms + entries_ms.
  struct Timing {
    double setup_ms = 0;  // scene hash, Renderer, scene load
    double targets_ms = 0;
    double entries_ms = 0;
    double total_ms = 0;
  } timing;
};

// The lock a service holds while one reference is read or made, so that two compares of the same
// reference at once render it once; keyed by reference_cache_key. Empty: no lock.
using ReferenceLock = std::function<std::unique_lock<std::mutex>(const std::string& cache_key)>;

class CompareJob {
 public:
  // Parses and checks everything a compare reads before any work; InputError naming the field.
  explicit CompareJob(const nlohmann::json& request);

  const RenderOptions& frame() const { return frame_; }
  const std::vector<MethodEntry>& entries() const { return entries_; }  // method-major
  const std::vector<std::string>& methods() const { return methods_; }
  const std::vector<int>& rates() const { return rates_; }
  const std::vector<ReferenceKind>& reference_kinds() const { return kinds_; }
  int repeat() const { return repeat_; }
  // The reference settings of the request; the cache (directory, bounds, use) is the front end's.
  ReferenceSettings& reference_settings() { return reference_; }
  const ReferenceSettings& reference_settings() const { return reference_; }
  // How the scene is made for this compare (tint, constant_color); textures deferred.
  GeneratorOptions generator_options() const;
  // The camera of the frame on `scene`: its orbit frame, or its own camera.
  Camera camera(const Scene& scene) const;

  // The most memory the run needs on the device and the host, from the scene's sizes alone.
  JobPlan plan(const Scene& scene) const;

  // Renders the seam masks and references (or reads them from the cache), then every entry.
  // Cancelled when control.should_stop says so (between entries and renders, and between the
  // stages of every render: the seam masks' and references' too).
  CompareRun run(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                 const ReferenceLock& lock_reference = {});

  // The documented answer: scene, size, device, repeat, options, results, the references'
  // summary (reference, references, seam_pixels, seam_mask), frame and frames with an orbit frame,
  // displacement for a displaced frame, the run's timing {setup_ms, targets_ms, entries_ms,
  // total_ms}. with_cache_path: where a cached reference lies (the command line's; a service
  // keeps its paths to itself).
  nlohmann::json result_json(const CompareRun& run, const Scene& scene, const std::string& device,
                             bool with_cache_path) const;

 private:
  RenderOptions frame_;
  std::vector<MethodEntry> entries_;
  std::vector<std::string> methods_;
  std::vector<int> rates_;
  std::vector<ReferenceKind> kinds_;
  ReferenceSettings reference_;
  int repeat_ = 3;
  std::optional<glm::vec3> constant_color_;
};

// Writes the compare's images into `directory` (made by the caller): each entry's image and error
// heat map (log scale 1e-4..1), each reference and seam mask, as PNG. Returns, per result in order,
// {"image": path, "error": path}.
std::vector<nlohmann::json> write_compare_images(const CompareRun& run, const RenderOptions& frame,
                                                 const std::string& directory);

}  // namespace seamcl
