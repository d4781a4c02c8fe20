// seamcl bench: the bench job (host/jobs/bench_job.h) from the command line: its flags from the
// job's option table, the reference cache's settings, the error frames' images where --images says,
// --check (the plan's refusal only), a table or the job's JSON printed.
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/batch/bench_merge.h>
#include <seamcl/batch/scaling_sweep.h>
#include <seamcl/batch/shard.h>
#include <seamcl/cl/cl_runtime.h>
#include <seamcl/jobs/bench_job.h>
#include <seamcl/memory/render_memory.h>
#include "commands.h"
#include "option_flags.h"
#include "reference_cache_flags.h"

namespace seamcl::cli {
namespace {

using nlohmann::json;

struct BenchArgs {
  std::unique_ptr<OptionFlags> options;
  ReferenceCacheFlags cache;
  std::optional<std::string> images;  // a directory; empty is refused, not taken for none
  bool check_only = false;
  bool json_out = false;
};

void print_sweeps(const json& out) {
  for (const json& sweep : out.at("sweeps")) {
    for (const json& r : sweep.at("ratios")) {
      std::printf("%-7s %-10s x %8.2f -> time x %7.3f%s\n", sweep.at("axis").get<std::string>().c_str(),
                  r.at("method").get<std::string>().c_str(), r.at("x_ratio").get<double>(), r.at("time_ratio").get<double>(),
                  r.at("met").is_null() ? "" : (r.at("met").get<bool>() ? " (target met)" : " (target missed)"));
    }
  }
}

void print_orbit(const json& out) {
  const bool with_errors = out["errors"].get<bool>();
  const std::string errors = with_errors ? "on every " + std::to_string(out["reference_frames"].get<int>()) + ". frame vs " +
                                               out["reference"]["method"].get<std::string>() + " 8x reference"
                                         : "off";
  std::printf("%s %s, %d frames (orbit), errors %s; %.1f s\n", out["scene"].get<std::string>().c_str(),
              out["size"].get<std::string>().c_str(), out["frames"].get<int>(), errors.c_str(), out["wall_s"].get<double>());
  const json& shard = out["shard"];
  if (shard["count"].get<int>() != 1) {
    std::printf("part %d/%d: frames %d..%d (seamcl merge combines the parts' --json output)\n", shard["index"].get<int>(),
                shard["count"].get<int>(), shard["first_frame"].get<int>(), shard["end_frame"].get<int>() - 1);
  }
  std::printf("%-10s %4s %9s %9s %9s %7s %5s %10s %10s %10s %12s\n", "method", "msaa", "ms_med", "ms_min", "ms_max",
              "spread", "nan", "mean", "seam_mean", "temporal", "tex_bytes");
  for (const json& r : out["results"]) {
    const bool e = r.contains("error");
    std::printf("%-10s %4d %9.3f %9.3f %9.3f %7.3f %5zu %10.3e %10.3e %10.3e %12zu\n",
                r["method"].get<std::string>().c_str(), r["msaa"].get<int>(), r["ms"]["median"].get<double>(),
                r["ms"]["min"].get<double>(), r["ms"]["max"].get<double>(), r["ms"]["spread"].get<double>(),
                r["nan_pixels"].get<size_t>(), e ? r["error"]["mean"].get<double>() : 0.0,
                e ? r["error"]["seam_mean"].get<double>() : 0.0, r["temporal"]["seam_mean"].get<double>(),
                r["texture_bytes"].get<size_t>());
  }
  for (const json& d : out["differences"]) {
    std::printf("||%s - %s|| at %dx: mean %.3e, seam_mean %.3e, p99 %.3e\n", d["a"].get<std::string>().c_str(),
                d["b"].get<std::string>().c_str(), d["msaa"].get<int>(), d["mean"].get<double>(),
                d["seam_mean"].get<double>(), d["p99"].get<double>());
  }
}

int run_bench(BenchArgs& args, const GlobalOptions& global) {
  // Validate everything before any work.
  const std::string images_dir = given_value(args.images, "images", "leave out --images to write no images");
  BenchJob job(args.options->request());
  if (!images_dir.empty()) job.refuse_images("images");
  args.cache.apply(job.reference_settings());  // checked with --sweep too: an empty --cache is a mistake
  ClRuntime& runtime = cli::command_runtime(global.device);
  SceneSourceOptions source;
  source.generator = job.generator_options();
  source.displacement_map = job.frame().displacement_map;
  const Scene scene = load_scene_source(job.frame().scene, job.frame().texture, source);
  // An estimate, so --check makes it too: a batch's pre-check (scripts/farm) must not pass a part
  // that would then be refused.
  job.refuse_beyond_machine(scene, runtime.info());
  if (args.check_only) {
    if (job.is_sweep()) {
      std::printf("sweep options valid: %s\n", job.sweep().c_str());
    } else {
      std::printf("bench options valid: %s, part %s: frames %d..%d of %d\n", scene.name.c_str(),
                  to_string(job.shard()).c_str(), job.range().first, job.range().end - 1, job.frame().frames);
    }
    return 0;
  }
  if (!images_dir.empty()) make_output_directory(images_dir, "images");
  JobControl control;
  control.progress = [](const std::string& line) { std::fprintf(stderr, "bench: %s\n", line.c_str()); };
  control.should_stop = stop_on_interrupt();
  control.device_byte_limit = device_memory_bound(runtime.info());
  const json out = job.run(runtime, scene, control, images_dir);
  if (args.json_out) {
    std::cout << out.dump(2) << "\n";
  } else if (job.is_sweep()) {
    print_sweeps(out);
  } else {
    print_orbit(out);
  }
  return 0;
}

}  // namespace

Command add_bench_command(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Time every method x MSAA rate side by side over an orbit of frames, with errors against the reference");
  args->options = std::make_unique<OptionFlags>(cmd, bench_option_table());
  args->cache.add_to(cmd);
  cmd->add_option("--images", args->images,
                  "Write each error frame's reference, seam masks and every entry's image (PNG) into DIR/frame_<k>/, "
                  "as compare --images does for its frame (FLIP over them: scripts/farm --flip, examples/orbit_flip.py)")
      ->type_name("DIR");
  cmd->add_flag("--check", args->check_only,
                "Validate the options (and the scene), refuse a bench this machine cannot hold, and exit without rendering");
  cmd->add_flag("--json", args->json_out, "Print one JSON object");
  return Command{cmd, [args](const GlobalOptions& global) { return run_bench(*args, global); }};
}

}  // namespace seamcl::cli
