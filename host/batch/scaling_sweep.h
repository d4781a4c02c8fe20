// Scaling sweeps (seamcl bench --sweep, issue 14): one render configuration timed while one
// quantity grows and the others stay put, to show what the pipeline's time is proportional to.
//   pixels: the image from 480x540 to 3840x2160 (32x), the scene and rate fixed;
//   faces:  the paper scene subdivided from 2,474 to 197,920 faces (80x) at the same image size,
//           its textures scaled to keep about the same texels (GeneratorOptions::faces);
//   msaa:   rates 1, 2, 4, 8, 16;
//   texels: the paper scene's texture sides times 2^k, k = -3..1 (about 1/64x to 4x the texels).
// Points that share a scene (all of pixels' and msaa's) are measured together: a warm-up render
// of each, then `repeats` rounds in which every point and method renders once, so that a shared
// machine's drifting load falls on them alike; a faces or texels point loads its own scene and is
// measured alone. Times are OpenCL profiling's (median, min, max). The targets of issue 14 are
// evaluated in the output: 32x pixels in at most 34x time, 40x faces in at most 1.2x time. Each
// group of points is refused before its Renderer allocates when the machine cannot hold it
// (refuse_sweep_group_beyond_machine); bench --sweep refuses the whole sweep before it starts.
#pragma once
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {

enum class SweepAxis { Pixels, Faces, Msaa, Texels };
std::optional<SweepAxis> parse_sweep_axis(std::string_view name);  // pixels, faces, msaa, texels
std::string to_string(SweepAxis axis);
std::vector<std::string> sweep_axis_names();

// "all" (every axis) or a comma list of axis names, in the order given, each once. Anything else
// is InputError("sweep") naming the known values.
std::vector<SweepAxis> parse_sweep(const std::string& value);

// One point of a sweep: what differs from the base options.
struct SweepPoint {
  int width = 0, height = 0, msaa = 1;
  std::optional<int> faces;               // GeneratorOptions::faces
  std::optional<int> texture_scale_log2;  // GeneratorOptions::texture_scale_log2
};
// The points of an axis over `base` (its size and rate where the axis does not set them).
std::vector<SweepPoint> sweep_points(SweepAxis axis, const RenderOptions& base);
// Whether the axis's points render at the base's size: all but pixels, whose points set their own.
bool sweep_reads_base_size(SweepAxis axis);

struct SweepSettings {
  RenderOptions base;                // scene, texel format, filter, size and rate where fixed
  std::vector<std::string> methods;  // each timed at every point (parse_method names)
  int repeats = 5;                   // timed renders per method and point, 1..100
  // Makes the scene of a point from the generator options it asks for (faces, texture scale;
  // defer_textures is set): the CLI's load_scene_source, which host/eval cannot call itself.
  std::function<Scene(const GeneratorOptions&)> make_scene;
  std::function<void(const std::string&)> progress;  // one line per point; may be empty
  size_t device_byte_limit = 0;  // every point's Renderer is held to it (Renderer::set_device_byte_limit; 0: none)
};

// Throws InputError: "sweep" for no axis, "methods" for an unknown method, "sweep_repeats" for
// repeats out of range (bench's --sweep-repeats), "scene" for the faces or texels axis on a scene
// other than paper.
void validate_sweep(const std::vector<SweepAxis>& axes, const SweepSettings& settings);

// Refuses, as refuse_beyond_machine refuses a render (OverBudget naming the largest share of the
// limit exceeded), a group of the axis's points that share a scene (`points`, all made of `scene`)
// and whose renders `device` (and the machine's memory) cannot hold: one Renderer renders every
// method at every point of the group and keeps the largest of each buffer (render_memory, the
// frame buffers split as frame_buffers_field of the point's rate: "size" for the pixels sweep's,
// "msaa" for the msaa sweep's above 1), beside `first` (the first group's figures, kept loaded
// for a group with a scene of its own; nullptr for none). Returns the group's figures (for the
// groups after the first). From the scene's sizes alone: nothing is allocated on the device.
struct SweepMemory {
  MemoryShares device, host;
};
SweepMemory refuse_sweep_group_beyond_machine(SweepAxis axis, const SceneSizes& scene, const std::vector<SweepPoint>& points,
                                             const SweepSettings& settings, const SweepMemory* first, const DeviceInfo& device);

// The same for every group of every axis before anything renders: each group's scene is made
// (settings.make_scene, its textures deferred: no texel is baked), its sizes taken and dropped.
// For bench --sweep and its --check.
void refuse_sweeps_beyond_machine(const std::vector<SweepAxis>& axes, const SweepSettings& settings, const DeviceInfo& device);

// {"kind": "scaling_sweep", "device", "options", "methods", "repeats",
//  "sweeps": [{"axis", "x_label", "points": [{"x", "width", "height", "pixels", "msaa", "faces",
//               "triangles", "texels", "packed_texel_bytes", "fragments",
//               "results": [{"method", "ms": {median, min, max, ...}, "stages": {setup, ...}}]}],
//              "ratios": [{"method", "from_x", "to_x", "x_ratio", "time_ratio" (of the medians),
//                          "time_ratio_of_minima", "from_ms" (the first point's median it divides
//                          by), "from_renders_beside" (true where the point has a scene of its own,
//                          faces and texels: the first point re-rendered in turn with it, its
//                          renderer kept loaded, rather than its own point's median),
//                          "from_frames" (how many renders from_ms is the median of),
//                          "max_time_ratio" (null: no target),
//                          "met" (null: no target; judged on the medians)}]}],
//  "memory": {"peak_rss_bytes"}, "wall_s"}
nlohmann::json run_scaling_sweeps(ClRuntime& runtime, const std::vector<SweepAxis>& axes, const SweepSettings& settings);

}  // namespace seamcl
