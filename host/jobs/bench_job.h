// The bench job: an orbit of frames, every method x MSAA rate rendered on each frame (frame-major,
// so machine noise falls on all methods alike), timed from OpenCL profiling events and measured
// against each error frame's reference (host/eval/reference.h, cached): pooled errors, NaN pixels,
// temporal stability near seams, memory per method, the discard-traverse differences of the
// paper's Figure 5 (left). Or, with `sweep`, the scaling sweeps (host/batch/scaling_sweep.h) in
// place of the orbit. What `seamcl bench` runs.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/batch/scaling_sweep.h>
#include <seamcl/batch/shard.h>
#include <seamcl/jobs/job.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

// The bench request's options: the frame's render options (but `method`, `msaa` and `frame`: the
// orbit renders every frame), the methods and msaa lists and the reference's method and rate
// (compare's), and the bench's own: reference_frames, no_errors, shard, seam_mask, sweep,
// sweep_repeats.
const OptionTable& bench_option_table();

// The folder of error frame k's images under a bench's images directory: frame_<k, 6 digits>.
std::string frame_images_folder(int frame);

class BenchJob {
 public:
  // Parses and checks everything a bench reads before any work; InputError naming the field, also
  // for an option the chosen mode would ignore ("sweep_repeats: is ignored without sweep").
  explicit BenchJob(const nlohmann::json& request);

  bool is_sweep() const { return !sweep_axes_.empty(); }
  const std::string& sweep() const { return sweep_text_; }
  const RenderOptions& frame() const { return frame_; }
  const std::vector<MethodEntry>& entries() const { return entries_; }
  const Shard& shard() const { return shard_; }
  const FrameRange& range() const { return range_; }
  // The reference settings of the request; the cache (directory, bounds, use) is the front end's.
  ReferenceSettings& reference_settings() { return reference_; }
  const ReferenceSettings& reference_settings() const { return reference_; }
  // How the scene is made for this bench (tint; textures deferred).
  GeneratorOptions generator_options() const;

  // The orbit's memory at most, from the scene's sizes alone. A sweep has no one figure: its
  // groups of points are held one after another (refuse_beyond_machine below).
  JobPlan plan(const Scene& scene) const;
  // Refuses (OverBudget naming the share) a bench `device` and this machine cannot hold: the
  // orbit's plan, or every sweep group (each group's scene made with its textures deferred).
  void refuse_beyond_machine(const Scene& scene, const DeviceInfo& device) const;

  // Runs the orbit (or the sweeps) and returns the documented JSON: for the orbit scene, size,
  // device, frames, shard, reference_frames, errors, error_frames, order, seam_mask, seam_radius,
  // seam_pixels_per_frame, options, wall_s, results, differences and, with errors, reference; for
  // sweeps run_scaling_sweeps' JSON. One progress line per frame (per sweep point); Cancelled
  // between frames (points) when control.should_stop says so. With `images_dir` (an existing
  // directory; refuse_images says when it is allowed) every error frame k also writes, into
  // images_dir/frame_images_folder(k), what compare --images writes for its frame: reference.png,
  // seam_mask_msaa<N>.png per rate and <method>_msaa<N>.png per entry (for FLIP afterwards:
  // examples/orbit_flip.py).
  nlohmann::json run(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                     const std::string& images_dir = "");
  // InputError naming `field` when this bench has no error frames to write images of (a sweep,
  // no_errors).
  void refuse_images(const std::string& field) const;

 private:
  SweepSettings sweep_settings() const;
  nlohmann::json run_orbit(ClRuntime& runtime, const Scene& scene, const JobControl& control,
                           const std::string& images_dir);
  int error_frame_count() const;

  RenderOptions frame_;
  std::vector<MethodEntry> entries_;
  std::vector<std::string> methods_;
  ReferenceSettings reference_;
  bool with_errors_ = true;
  int reference_frames_ = 1;
  Shard shard_;
  FrameRange range_;
  SeamMaskKind mask_kind_ = SeamMaskKind::Band;
  std::vector<SweepAxis> sweep_axes_;
  std::string sweep_text_;
  int sweep_repeats_ = 5;
};

}  // namespace seamcl
