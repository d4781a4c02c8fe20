// The warm-up job: the geometry and downsample programs and every shading variant built (or
// loaded from the program cache, host/cl/program_cache.h) ahead of the first request on a thread
// per core (PoCL 3.1 compiles one program at a time in a process, so there the threads take
// turns), then one tiny frame of each rendered so that the driver compiles each kernel for its
// local size too (PoCL does this on a kernel's first enqueue, and with its own cache cold that is
// slow enough to show in a timed frame). What `seamcl warmup` runs. Its builds are written to the
// program cache on every driver, PoCL too (ClRuntime::CacheWrite::Always), so that later
// processes load them.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/options/option_table.h>
#include <seamcl/options/render_options.h>

namespace seamcl {

// One program variant: the render options that select it (method, filter, RGBA8 texels),
// whether it is the seam-mask build, and its build options (program_options).
struct WarmupVariant {
  std::string name;  // "traverse trilinear", "seam mask trilinear"
  RenderOptions options;
  bool seam_mask = false;
  std::string build_options;
};

// Every method x every filter at the default texel format (what renders and compares use), then
// the seam-mask build per filter (a compare's masks): 24 + 4 today.
std::vector<WarmupVariant> warmup_variants();

// threads (0: one per core), render (false: build only), list (print the variants only).
const OptionTable& warmup_option_table();

struct WarmupReport {
  int variants = 0;
  int built = 0;           // from source
  int loaded = 0;          // from the program cache
  int cache_rejected = 0;  // damaged entries built again
  int threads = 0;
  double build_ms = 0;     // wall time of the parallel build
  double render_ms = 0;    // wall time of the tiny frames
  double total_ms = 0;
  std::string cache_dir;   // the program cache's directory; empty: none
  nlohmann::json to_json() const;
};

// One line per finished build ("built 3/30: traverse trilinear (812 ms)"; the geometry stages' and
// the downsample's programs, which every variant shares, are two of them) and per tiny frame.
using WarmupProgress = std::function<void(const std::string&)>;

class WarmupJob {
 public:
  // Parses a request of warmup_option_table(); InputError naming the field.
  explicit WarmupJob(const nlohmann::json& request);
  int threads() const { return threads_; }  // 0: one per core
  bool render() const { return render_; }
  bool list() const { return list_; }

  // Builds `variants` with threads() threads, then (with render()) renders a 16x16 frame of the
  // built-in quad2 scene with each. Build errors propagate (describe_cl_exception reads them).
  WarmupReport run(ClRuntime& runtime, const std::vector<WarmupVariant>& variants,
                   const WarmupProgress& progress = {}) const;

 private:
  int threads_ = 0;
  bool render_ = true;
  bool list_ = false;
};

}  // namespace seamcl
