// seamcl warmup: the geometry and downsample programs and every shading variant built ahead (or loaded from the
// program cache), on a thread per core, with a line per build on stderr; --list prints the variants' build options instead
// (scripts and the kernel portability check read them). The work is the library's WarmupJob.
#include <cstdio>
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/jobs/warmup_job.h>
#include "commands.h"
#include "option_flags.h"

namespace seamcl::cli {
namespace {

struct WarmupArgs {
  std::unique_ptr<OptionFlags> options;
  bool json_out = false;
  bool no_progress = false;
};

int run_warmup(const WarmupArgs& args, const GlobalOptions& global) {
  const WarmupJob job(args.options->request());
  const std::vector<WarmupVariant> variants = warmup_variants();
  if (job.list()) {
    for (const WarmupVariant& v : variants) std::cout << v.name << "\t" << v.build_options << "\n";
    return 0;
  }
  ClRuntime& runtime = cli::command_runtime(global.device);
  WarmupProgress progress;
  if (!args.no_progress) progress = [](const std::string& line) { std::fprintf(stderr, "warmup: %s\n", line.c_str()); };
  const WarmupReport report = job.run(runtime, variants, progress);
  if (args.json_out) {
    nlohmann::json out = report.to_json();
    out["device"] = runtime.device_description();
    std::cout << out.dump(2) << "\n";
  } else {
    std::printf("%d variants (and the geometry and downsample programs): %d built, %d from the program cache (%d damaged entries rebuilt), %d threads; "
                "build %.0f ms, frames %.0f ms, total %.0f ms\n",
                report.variants, report.built, report.loaded, report.cache_rejected, report.threads, report.build_ms,
                report.render_ms, report.total_ms);
  }
  return 0;
}

}  // namespace

Command add_warmup_command(CLI::App& app) {
  auto args = std::make_shared<WarmupArgs>();
  CLI::App* cmd = app.add_subcommand(
      "warmup", "Build every program variant ahead (into the program cache) so that later renders start at once");
  args->options = std::make_unique<OptionFlags>(cmd, warmup_option_table());
  cmd->add_flag("--no-progress", args->no_progress, "Do not print progress lines on stderr");
  cmd->add_flag("--json", args->json_out, "Print one JSON object");
  return Command{cmd, [args](const GlobalOptions& global) { return run_warmup(*args, global); }};
}

}  // namespace seamcl::cli
