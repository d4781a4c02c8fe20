#include <seamcl/jobs/render_job.h>

#include <algorithm>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/stage_stop.h>
#include "io/mesh_export.h"
#include "pipeline/displacement_packing.h"
#include "pipeline/stages/tessellate_launcher.h"
#include "pipeline/tessellation_factors.h"
#include "ptexfilter/ptex_filter_texture.h"

namespace seamcl {
namespace {

using nlohmann::json;

const OptionTable& render_own_options() {
  static const OptionTable table = [] {
    OptionSpec repeat = make_option("repeat", OptionType::Integer, "Render N times and report the median time per stage");
    repeat.minimum = 1;
    repeat.maximum = 1000;
    repeat.default_value = 1;
    OptionSpec crack_orbit = make_option("crack_orbit", OptionType::Integer,
                           "Displacement: count crack pixels over N frames of the scene's orbit instead of this frame");
    crack_orbit.minimum = 0;
    crack_orbit.maximum = 3600;
    crack_orbit.default_value = 0;
    // A path on the machine that renders: the command line's (and the Python module's) only, the
    // HTTP service refuses it (a client must not name files on the server's disk).
    OptionSpec export_mesh = make_option("export_mesh", OptionType::String,
                                         "Displacement: write the frame's tessellated patches, not merged, to a .obj or .ply file");
    export_mesh.absent = "none";
    return OptionTable{repeat, crack_orbit, export_mesh};
  }();
  return table;
}

}  // namespace

const OptionTable& render_job_option_table() {
  static const OptionTable table = [] {
    OptionTable out = render_option_table();
    for (const OptionSpec& spec : render_own_options()) out.push_back(spec);
    return out;
  }();
  return table;
}

RenderJob::RenderJob(const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  json render_request = json::object();
  for (const auto& [key, value] : request.items()) {
    if (const OptionSpec* own = find_option(render_own_options(), key)) {
      const json checked = checked_option(*own, value);
      if (key == "repeat") repeat_ = checked.get<int>();
      if (key == "crack_orbit") crack_orbit_ = checked.get<int>();
      if (key == "export_mesh") export_mesh_ = checked.get<std::string>();
    } else {
      render_request[key] = value;
    }
  }
  if (render_request.contains("frames") && !render_request.contains("frame"))
    throw InputError("frames", "is ignored without frame (the scene's own camera renders): leave it out");
  options_ = parse_render_options(render_request);
  if (is_ptex_filter(options_.filter)) ptex_seam_rule(options_.method);  // refuses the methods they cannot take
  if (crack_orbit_ > 0 && !options_.displacement)
    throw InputError("crack_orbit", "counts the cracks of a displaced render: give displacement_method too");
  if (!export_mesh_.empty()) {
    // Refused here, before any work: a render that ends in a bad path wastes the render.
    check_mesh_path(export_mesh_, "export_mesh");
    if (!options_.displacement)
      throw InputError("export_mesh", "writes the tessellated patches of a displaced render: give displacement_method too");
  }
}

GeneratorOptions RenderJob::generator_options() const {
  GeneratorOptions options;
  options.tint = options_.tint;
  options.defer_textures = true;  // baked face by face while packing: no float copy of them all
  return options;
}

Camera RenderJob::camera(const Scene& scene) const {
  return options_.frame ? orbit_camera(scene, *options_.frame, options_.frames) : scene.camera;
}

JobPlan RenderJob::plan(const Scene& scene, size_t held_scene_bytes) const {
  const RenderMemory memory = render_memory(scene_sizes(scene), options_);
  const std::string field = frame_buffers_field(options_.msaa);
  JobPlan plan{"this render", memory.device_shares(field), memory.host_shares(), memory.process_shares(field, true)};
  plan.host.add("scene", held_scene_bytes);
  plan.unified.add("scene", held_scene_bytes);
  return plan;
}

RenderRun RenderJob::run(ClRuntime& runtime, Renderer& renderer, const Scene& scene, const JobControl& control,
                         bool measure_watertightness) const {
  const Camera view = camera(scene);
  // The renderer asks the same between its stages (a long cube-map bake, kernel builds), for this
  // run only (host/pipeline/stage_stop.h).
  const StageStopScope stage_stop(control.should_stop);
  throw_if_stopped(control.should_stop, "before the kernels");
  // Ptex's own filters read the scene's .ptx again, in its own units: once per file a Renderer keeps.
  const std::string& ptex_file = renderer.scene().ptex_file;
  if (is_ptex_filter(options_.filter) && !ptex_file.empty() && renderer.ptex_texture_file() != ptex_file) {
    renderer.set_ptex_texture(std::make_shared<const PtexFilterData>(build_ptex_filter_data(read_ptex_stored(ptex_file))),
                              ptex_file);
  }
  renderer.warm_up(options_);
  RenderRun run;
  // Each run's times, and only the last run's image: holding every frame kept `repeat` images
  // alive at once.
  for (int i = 0; i < repeat_; ++i) {
    throw_if_stopped(control.should_stop, "before render " + std::to_string(i + 1) + " of " + std::to_string(repeat_));
    if (repeat_ > 1) control.report("render " + std::to_string(i + 1) + "/" + std::to_string(repeat_));
    run.last = renderer.render(view, options_);
    run.times.push_back(run.last.ms);
  }
  auto stage_median = [&](double StageTimes::*stage) {
    std::vector<double> values;
    for (const StageTimes& t : run.times) values.push_back(t.*stage);
    return median_of(values);
  };
  for (double StageTimes::*stage : {&StageTimes::setup, &StageTimes::binning, &StageTimes::raster, &StageTimes::shade,
                                    &StageTimes::readback, &StageTimes::total, &StageTimes::tessellate})
    run.median.*stage = stage_median(stage);
  if (measure_watertightness && options_.displacement) {
    // The gap and crack pixels of this frame (docs/displacement.md), the times of the renders above.
    control.report("displacement: gap and crack pixels of " + to_string(*options_.displacement));
    DisplacementReport report =
        measure_displacement(runtime, scene, view, options_, crack_orbit_, 0, renderer.device_byte_limit());
    report.frame_ms = run.median.total;
    report.tessellate_ms = run.median.tessellate;
    run.displacement = report.to_json();
  }
  if (!export_mesh_.empty()) {
    // The frame's patches tessellated once more by the same kernel on the same packed patches:
    // each vertex is one work item's function of the packed patches alone, built without
    // contraction, so these are the rendered frame's vertices bit for bit (the test holds the file
    // to the stage's read-back), read without touching the Renderer's buffers.
    throw_if_stopped(control.should_stop, "before the mesh export");
    control.report("export_mesh: " + export_mesh_);
    TessellateLauncher stage(runtime);
    stage.load(pack_displacement(scene, displacement_settings(scene, options_, view)));
    const std::vector<TessVertex> vertices = stage.tessellate();
    const int slots = stage.packed().params.tessellation;
    stage.release();
    write_patch_mesh(export_mesh_, vertices, slots, "export_mesh");
  }
  return run;
}

json RenderJob::stage_ms_json(const StageTimes& t) {
  return {{"total", t.total}, {"setup", t.setup},   {"binning", t.binning},
          {"raster", t.raster}, {"shade", t.shade}, {"readback", t.readback}};
}

json RenderJob::result_json(const RenderRun& run, const Renderer& renderer, const std::string& device) const {
  const PackedScene& packed = renderer.packed_scene();
  json out = {{"device", device},
              {"options", to_json(options_)},
              {"ms", stage_ms_json(run.median)},
              {"runs", repeat_},
              {"triangles", renderer.scene().triangle_count()},
              {"visible_triangles", run.last.stats.visible_triangles},
              {"fragments", run.last.stats.fragments},
              {"texture_bytes", packed.texture_bytes()},
              {"padding_bytes", packed.padding_bytes()},
              {"adjacency_bytes", reads_adjacency(options_.method) ? packed.adjacency_bytes() : 0},
              {"bin_entries", run.last.stats.bin_entries}};
  if (!run.displacement.is_null()) {
    out["displacement"] = run.displacement;
    out["triangles"] = run.displacement.at("triangles");
  }
  return out;
}

}  // namespace seamcl
