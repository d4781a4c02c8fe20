#include <seamcl/jobs/warmup_job.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <mutex>
#include <thread>

#include <seamcl/core/elapsed.h>
#include <seamcl/core/input_error.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

}  // namespace

std::vector<WarmupVariant> warmup_variants() {
  std::vector<WarmupVariant> out;
  for (const std::string& method : method_names()) {
    for (const std::string& filter : filter_names()) {
      if (is_ptex_filter(*parse_filter(filter))) continue;
      WarmupVariant v;
      v.name = method + " " + filter;
      v.options = parse_render_options({{"method", method}, {"filter", filter}});
      v.build_options = program_options(v.options.texels, sampler_params(v.options));
      out.push_back(std::move(v));
    }
  }
  // Ptex's own filters share one program whatever the filter and method (both are run-time
  // settings of the lookup), and have no seam mask.
  WarmupVariant ptex;
  ptex.name = "ptex filters";
  ptex.options = parse_render_options({{"method", "traverse"}, {"filter", "ptex-bilinear"}});
  ptex.build_options = program_options(ptex.options.texels, sampler_params(ptex.options));
  out.push_back(std::move(ptex));
  // The seam mask is rendered with black (footprint_seam_mask): its own build per filter.
  for (const std::string& filter : filter_names()) {
    if (is_ptex_filter(*parse_filter(filter))) continue;
    WarmupVariant v;
    v.name = "seam mask " + filter;
    v.options = parse_render_options({{"method", "black"}, {"filter", filter}});
    v.seam_mask = true;
    v.build_options = program_options(v.options.texels, sampler_params(v.options), true);
    out.push_back(std::move(v));
  }
  return out;
}

const OptionTable& warmup_option_table() {
  static const OptionTable table = [] {
    OptionSpec threads = make_option("threads", OptionType::Integer, "Programs built at once (0: one per core)");
    threads.minimum = 0;
    threads.maximum = 256;
    threads.default_value = 0;
    OptionSpec no_render = make_option("no_render", OptionType::Boolean,
                                       "Build the programs only, without the tiny frame per variant that makes the "
                                       "driver compile each kernel for its work-group size");
    no_render.default_value = false;
    OptionSpec list = make_option("list", OptionType::Boolean,
                                  "Print each variant's name and build options, one a line, and build nothing");
    list.default_value = false;
    return OptionTable{threads, no_render, list};
  }();
  return table;
}

WarmupJob::WarmupJob(const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  for (const auto& [key, value] : request.items()) {
    const OptionSpec* spec = find_option(warmup_option_table(), key);
    if (spec == nullptr) throw InputError(key, "is not a warmup option (threads, no_render, list)");
    const json checked = checked_option(*spec, value);
    if (key == "threads") threads_ = checked.get<int>();
    if (key == "no_render") render_ = !checked.get<bool>();
    if (key == "list") list_ = checked.get<bool>();
  }
}

json WarmupReport::to_json() const {
  return {{"variants", variants}, {"built", built},       {"loaded", loaded},       {"cache_rejected", cache_rejected},
          {"threads", threads},   {"build_ms", build_ms}, {"render_ms", render_ms}, {"total_ms", total_ms},
          {"program_cache", cache_dir}};
}

WarmupReport WarmupJob::run(ClRuntime& runtime, const std::vector<WarmupVariant>& variants,
                            const WarmupProgress& progress) const {
  const Clock::time_point start = Clock::now();
  WarmupReport report;
  report.variants = static_cast<int>(variants.size());
  report.cache_dir = runtime.program_cache_dir();
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  report.threads = std::clamp(threads_ == 0 ? cores : threads_, 1, report.variants + 1);
  const ClRuntime::ProgramStats before = runtime.program_stats();

  std::atomic<size_t> next{0};
  std::atomic<int> done{0};
  std::mutex report_mutex;  // progress lines and the first error
  std::exception_ptr failure;
  // Builds 0 and 1 are the programs every variant shares: the geometry stages, and the downsample
  // of every compare's reference; build i > 1 is variant i - 2's shading.
  constexpr size_t kShared = 2;
  const size_t builds = variants.size() + kShared;
  auto build = [&] {
    for (size_t i = next++; i < builds; i = next++) {
      const Clock::time_point one = Clock::now();
      const ClRuntime::ProgramStats was = runtime.program_stats();
      try {
        if (i < kShared) {
          runtime.program(i == 0 ? KernelProgram::Geometry : KernelProgram::Downsample, "", ClRuntime::CacheWrite::Always);
        } else {
          runtime.program(KernelProgram::Shading, variants[i - kShared].build_options, ClRuntime::CacheWrite::Always);
        }
      } catch (...) {
        std::lock_guard<std::mutex> lock(report_mutex);
        if (!failure) failure = std::current_exception();
        next = builds;  // the others stop after their current build
        return;
      }
      const int finished = ++done;
      if (progress) {
        // Another thread may have counted meanwhile: "loaded" is a hint, the totals are exact.
        const bool loaded = runtime.program_stats().loaded > was.loaded;
        char line[256];
        std::snprintf(line, sizeof line, "built %d/%zu: %s (%.0f ms%s)", finished, builds,
                      i == 0 ? "geometry stages" : i == 1 ? "downsample" : variants[i - kShared].name.c_str(),
                      ms_since(one),
                      loaded ? ", from the program cache" : "");
        std::lock_guard<std::mutex> lock(report_mutex);
        progress(line);
      }
    }
  };
  std::vector<std::thread> helpers;
  for (int t = 1; t < report.threads; ++t) helpers.emplace_back(build);
  build();
  for (std::thread& helper : helpers) helper.join();
  if (failure) std::rethrow_exception(failure);
  report.build_ms = ms_since(start);

  if (render_) {
    const Clock::time_point render_start = Clock::now();
    Renderer renderer(runtime);
    renderer.load_scene(generate_scene("quad2", GeneratorOptions{}));
    int rendered = 0;
    for (const WarmupVariant& variant : variants) {
      // The warm-up scene has no .ptx for Ptex's filters to read: their program is built only.
      if (is_ptex_filter(variant.options.filter)) continue;
      RenderOptions tiny = variant.options;
      tiny.width = SEAMCL_TILE_SIZE;
      tiny.height = SEAMCL_TILE_SIZE;
      renderer.render(renderer.scene().camera, tiny, variant.seam_mask);
      if (progress) {
        progress("rendered " + std::to_string(++rendered) + "/" + std::to_string(variants.size()) + ": " + variant.name);
      }
    }
    report.render_ms = ms_since(render_start);
  }
  const ClRuntime::ProgramStats after = runtime.program_stats();
  report.built = after.built - before.built;
  report.loaded = after.loaded - before.loaded;
  report.cache_rejected = after.cache_rejected - before.cache_rejected;
  report.total_ms = ms_since(start);
  return report;
}

}  // namespace seamcl
