// Ptex's own filters (kernels/ptex_filter.cl): lookups per second on the device and, for scale,
// of its scalar twin on one host thread, on cellnoise.ptx (306 faces, 64 to 256 texels a side,
// valence 3, 4 and 9) and cube_text.ptx (72 faces of 512 x 512), per filter. The queries are the
// same random ones for both: any face, any point (a third near an edge or corner), widths from a
// texel to a quarter face. Device time is the kernel's (OpenCL profiling events), queries uploaded.
//
// Run: build/seamcl_bench_ptex_filter   (counters: lookups_per_s, median of 5 repetitions)
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/cl/cl_runtime.h>

#include "pipeline/stages/ptex_filter_launcher.h"
#include "ptexfilter/ptex_filter_texture.h"

namespace {

constexpr int kQueries = 1 << 18;

seamcl::ClRuntime& runtime() {
  static seamcl::ClRuntime r;
  return r;
}

const seamcl::PtexFilterData& texture(const std::string& name) {
  static std::map<std::string, std::unique_ptr<seamcl::PtexFilterData>> cache;
  auto& slot = cache[name];
  if (!slot)
    slot = std::make_unique<seamcl::PtexFilterData>(seamcl::build_ptex_filter_data(
        seamcl::read_ptex_stored(std::string(SEAMCL_TEST_ASSETS_DIR) + "/ptex/" + name + ".ptx")));
  return *slot;
}

std::vector<PtexFilterQuery> queries(int faces, int filter, int count) {
  std::mt19937 random(5);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  std::vector<PtexFilterQuery> out(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    PtexFilterQuery& q = out[static_cast<size_t>(i)];
    q.face = static_cast<int>(random() % static_cast<unsigned>(faces));
    q.filter = filter;
    q.u = i % 3 == 0 ? 0.02f * unit(random) : unit(random);
    q.v = unit(random);
    q.uw = q.vw = std::exp2(-9.0f * unit(random) - 2.0f);
  }
  return out;
}

void device_lookups(benchmark::State& state, const std::string& name, int filter) {
  const seamcl::PtexFilterData& data = texture(name);
  const std::vector<PtexFilterQuery> q = queries(static_cast<int>(data.faces.size()), filter, kQueries);
  seamcl::PtexFilterLauncher launcher(runtime());
  launcher.load(data);
  launcher.time(q, 1);  // the kernel compiled for its local size
  for (auto _ : state) {
    const std::vector<double> ms = launcher.time(q, 1);
    state.SetIterationTime(ms.front() * 1e-3);
  }
  state.counters["lookups_per_s"] = benchmark::Counter(static_cast<double>(kQueries), benchmark::Counter::kIsIterationInvariantRate);
}

void twin_lookups(benchmark::State& state, const std::string& name, int filter) {
  const seamcl::PtexFilterData& data = texture(name);
  const std::vector<PtexFilterQuery> q = queries(static_cast<int>(data.faces.size()), filter, kQueries / 16);
  float sink = 0.0f;
  for (auto _ : state)
    for (const PtexFilterQuery& one : q) sink += seamcl::ptex_filter_twin(data, one)[0];
  benchmark::DoNotOptimize(sink);
  state.counters["lookups_per_s"] = benchmark::Counter(static_cast<double>(q.size()), benchmark::Counter::kIsIterationInvariantRate);
}

#define SEAMCL_PTEX_BENCH(file, filter_name, code)                                                          \
  BENCHMARK_CAPTURE(device_lookups, file##_##filter_name, #file, code)                                      \
      ->UseManualTime()->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);          \
  BENCHMARK_CAPTURE(twin_lookups, file##_##filter_name, #file, code)                                        \
      ->Unit(benchmark::kMillisecond)->Repetitions(3)->ReportAggregatesOnly(true);

SEAMCL_PTEX_BENCH(cellnoise, bilinear, SEAMCL_PTEX_BILINEAR)
SEAMCL_PTEX_BENCH(cellnoise, box, SEAMCL_PTEX_BOX)
SEAMCL_PTEX_BENCH(cellnoise, gaussian, SEAMCL_PTEX_GAUSSIAN)
SEAMCL_PTEX_BENCH(cellnoise, bicubic, SEAMCL_PTEX_BICUBIC)
SEAMCL_PTEX_BENCH(cube_text, bilinear, SEAMCL_PTEX_BILINEAR)
SEAMCL_PTEX_BENCH(cube_text, box, SEAMCL_PTEX_BOX)
SEAMCL_PTEX_BENCH(cube_text, gaussian, SEAMCL_PTEX_GAUSSIAN)
SEAMCL_PTEX_BENCH(cube_text, bicubic, SEAMCL_PTEX_BICUBIC)

}  // namespace

BENCHMARK_MAIN();
