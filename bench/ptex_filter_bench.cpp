// Ptex's own filters (kernels/ptex_filter.cl): lookups per second on the device, of its scalar
// twin on one host thread and, when built against a Ptex install (-DSEAMCL_PTEX_ROOT=prefix), of
// the Ptex library's PtexFilter on one thread and on every core (one PtexFilter per std::thread,
// one PtexCache shared as a renderer shares it). Files: cellnoise.ptx (306 faces, 64 to 256 texels
// a side, valence 3, 4 and 9) and cube_text.ptx (72 faces of 512 x 512); every filter seamcl has.
//
// The queries are the same for every side: seeded, any face, widths from one texel of the face to
// the whole face (log-uniform), 40% interior, 35% near an edge, 25% near a corner.
//
// What is timed (wall clock; lookups_per_s = lookups over the seconds of all iterations):
//   device/...          PtexFilterLauncher::run into an array made before timing, as the Ptex
//                       rows write theirs: the buffers made over the queries and the array, the
//                       kernel, the values mapped back, the buffers released; kernel_lookups_per_s
//                       is the kernel alone (OpenCL profiling events). The program and kernel are
//                       built beforehand.
//   twin/...            ptex_filter_twin on this thread, over a sixteenth of the queries.
//   ptex_1_thread/...   PtexFilter::eval over the queries on this thread.
//   ptex_all_cores/...  the queries split in contiguous slices over hardware_concurrency threads,
//                       from the threads' start to their join.
// Face data is read into memory before timing on every side (Ptex reads faces lazily). Each row
// also gives the process's CPU seconds over the same loop: lookups_per_cpu_s, and cpu_per_wall (the
// cores in use: on a machine shared with other jobs, lookups_per_s drops with the share it gets).
//
// Equal work: device values are checked against the twin's on the first sixteenth of the queries
// (max_abs_diff_vs_twin) and, with Ptex, against the Ptex library's on every query
// (max_abs_diff_vs_device, on the ptex_* rows); a difference above 1e-4 ends the benchmark with an
// error instead of a rate.
//
// Run: build/seamcl_bench_ptex_filter [--queries=N] [Google Benchmark flags]
//      (N lookups per benchmark, default 262144; docs/benchmarks.md has the table's commands)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/cl/cl_runtime.h>

#include "pipeline/stages/ptex_filter_launcher.h"
#include "ptexfilter/ptex_filter_texture.h"

#ifdef SEAMCL_WITH_PTEX
#include <Ptexture.h>
#endif

namespace {

int g_queries = 1 << 18;
constexpr double kParityLimit = 1e-4;

struct FilterKind {
  const char* name;
  int code;
  float sharpness;
#ifdef SEAMCL_WITH_PTEX
  PtexFilter::FilterType ptex;
#endif
};

#ifdef SEAMCL_WITH_PTEX
#define SEAMCL_PTEX_TYPE(t) , PtexFilter::t
#else
#define SEAMCL_PTEX_TYPE(t)
#endif

// bspline, catmullrom and mitchell are bicubic at sharpness 0, 1 and 2/3 on both sides.
const FilterKind kFilters[] = {
    {"point", SEAMCL_PTEX_POINT, 0.0f SEAMCL_PTEX_TYPE(f_point)},
    {"bilinear", SEAMCL_PTEX_BILINEAR, 0.0f SEAMCL_PTEX_TYPE(f_bilinear)},
    {"box", SEAMCL_PTEX_BOX, 0.0f SEAMCL_PTEX_TYPE(f_box)},
    {"gaussian", SEAMCL_PTEX_GAUSSIAN, 0.0f SEAMCL_PTEX_TYPE(f_gaussian)},
    {"bspline", SEAMCL_PTEX_BICUBIC, 0.0f SEAMCL_PTEX_TYPE(f_bspline)},
    {"catmullrom", SEAMCL_PTEX_BICUBIC, 1.0f SEAMCL_PTEX_TYPE(f_catmullrom)},
    {"mitchell", SEAMCL_PTEX_BICUBIC, 2.0f / 3.0f SEAMCL_PTEX_TYPE(f_mitchell)},
};
const char* const kFiles[] = {"cellnoise", "cube_text"};

std::string asset_path(const std::string& name) { return std::string(SEAMCL_TEST_ASSETS_DIR) + "/ptex/" + name + ".ptx"; }

seamcl::ClRuntime& runtime() {
  static seamcl::ClRuntime r;
  return r;
}

const seamcl::PtexFilterData& texture(const std::string& name) {
  static std::map<std::string, std::unique_ptr<seamcl::PtexFilterData>> cache;
  auto& slot = cache[name];
  if (!slot) slot = std::make_unique<seamcl::PtexFilterData>(seamcl::build_ptex_filter_data(seamcl::read_ptex_stored(asset_path(name))));
  return *slot;
}

seamcl::PtexFilterLauncher& launcher(const std::string& name) {
  static std::map<std::string, std::unique_ptr<seamcl::PtexFilterLauncher>> cache;
  auto& slot = cache[name];
  if (!slot) {
    slot = std::make_unique<seamcl::PtexFilterLauncher>(runtime());
    slot->load(texture(name));
  }
  return *slot;
}

// A stream of its own rather than <random>'s distributions, whose outputs differ between standard
// libraries: the same seed gives the same queries with any compiler.
struct Random {
  uint64_t state;
  explicit Random(uint64_t seed) : state(seed * 0x9E3779B97F4A7C15ull + 1) {}
  uint32_t next() {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return static_cast<uint32_t>(state >> 32);
  }
  float unit() { return static_cast<float>(next() >> 8) * (1.0f / 16777216.0f); }
};

// Within `reach` of 0 or of 1 (which one by `high`), inside the face.
float near_side(Random& r, bool high, float reach) {
  const float d = std::min(reach, 1.0f) * r.unit();
  return high ? 1.0f - d : d;
}

// Face, point and widths only; the filter is set per benchmark.
std::vector<PtexFilterQuery> base_queries(const seamcl::PtexFilterData& data, int count) {
  Random r(2026);
  const int faces = static_cast<int>(data.faces.size());
  std::vector<PtexFilterQuery> out(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    PtexFilterQuery& q = out[static_cast<size_t>(i)];
    q = PtexFilterQuery{};
    q.face = static_cast<int>(r.next() % static_cast<uint32_t>(faces));
    const PtexFilterFace& f = data.faces[static_cast<size_t>(q.face)];
    // One texel of the face (2^-log2) to the whole face, log-uniform; square for a third.
    q.uw = std::exp2(-static_cast<float>(f.ulog2) * r.unit());
    q.vw = i % 3 == 0 ? q.uw : std::exp2(-static_cast<float>(f.vlog2) * r.unit());
    const float reach_u = 2.0f * std::max(q.uw, std::exp2(-static_cast<float>(f.ulog2)));
    const float reach_v = 2.0f * std::max(q.vw, std::exp2(-static_cast<float>(f.vlog2)));
    q.u = r.unit();
    q.v = r.unit();
    const int place = i % 20;
    if (place >= 8 && place < 15) {  // near an edge
      const uint32_t edge = r.next() % 4u;
      if (edge % 2 == 0) q.v = near_side(r, edge == 2, reach_v);
      else q.u = near_side(r, edge == 1, reach_u);
    } else if (place >= 15) {  // near a corner
      const uint32_t corner = r.next() % 4u;
      q.u = near_side(r, corner == 1 || corner == 2, reach_u);
      q.v = near_side(r, corner >= 2, reach_v);
    }
  }
  return out;
}

const std::vector<PtexFilterQuery>& queries(const std::string& file, const FilterKind& filter) {
  static std::map<std::string, std::vector<PtexFilterQuery>> cache;
  auto& slot = cache[file + "/" + filter.name];
  if (slot.empty()) {
    slot = base_queries(texture(file), g_queries);
    for (PtexFilterQuery& q : slot) {
      q.filter = filter.code;
      q.sharpness = filter.sharpness;
    }
  }
  return slot;
}

const std::vector<float>& device_values(const std::string& file, const FilterKind& filter) {
  static std::map<std::string, std::vector<float>> cache;
  auto& slot = cache[file + "/" + filter.name];
  if (slot.empty()) slot = launcher(file).run(queries(file, filter));
  return slot;
}

double max_abs_diff(const std::vector<float>& a, const std::vector<float>& b, size_t lookups, int channels) {
  double worst = 0.0;
  for (size_t i = 0; i < lookups; ++i)
    for (int c = 0; c < channels; ++c) {
      const double d = std::fabs(static_cast<double>(a[4 * i + static_cast<size_t>(c)]) - b[4 * i + static_cast<size_t>(c)]);
      worst = std::isnan(d) ? INFINITY : std::max(worst, d);
    }
  return worst;
}

void set_rate(benchmark::State& state, double lookups, double seconds, const char* key = "lookups_per_s") {
  state.counters[key] = seconds > 0.0 ? lookups / seconds : 0.0;
}

// CPU seconds of every thread of the process (PoCL's workers included).
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Wall and process CPU time of the timed loop: cpu_per_wall is the cores the side kept busy (2 on
// 2 idle cores; less when other jobs share the machine), lookups_per_cpu_s its work per core.
struct Clocks {
  double wall = 0.0, cpu = 0.0;
  double cpu_start = 0.0;
  std::chrono::steady_clock::time_point start;
  void begin() {
    cpu_start = process_cpu_seconds();
    start = std::chrono::steady_clock::now();
  }
  double end() {
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    cpu += process_cpu_seconds() - cpu_start;
    wall += s;
    return s;
  }
  void report(benchmark::State& state, double lookups_per_iteration) const {
    const double lookups = lookups_per_iteration * static_cast<double>(state.iterations());
    set_rate(state, lookups, wall);
    set_rate(state, lookups, cpu, "lookups_per_cpu_s");
    state.counters["cpu_per_wall"] = wall > 0.0 ? cpu / wall : 0.0;
  }
};

void device_lookups(benchmark::State& state, std::string file, FilterKind filter) {
  const std::vector<PtexFilterQuery>& q = queries(file, filter);
  seamcl::PtexFilterLauncher& l = launcher(file);
  const std::vector<float>& values = device_values(file, filter);  // also compiles the kernel for its local size
  const size_t checked = q.size() / 16;
  std::vector<float> twin(4 * checked);
  for (size_t i = 0; i < checked; ++i) {
    const std::array<float, 4> t = seamcl::ptex_filter_twin(texture(file), q[i]);
    std::copy(t.begin(), t.end(), twin.begin() + static_cast<std::ptrdiff_t>(4 * i));
  }
  const double diff = max_abs_diff(values, twin, checked, texture(file).texture.channels);
  state.counters["max_abs_diff_vs_twin"] = diff;
  if (!(diff <= kParityLimit)) {
    state.SkipWithError("device values differ from the twin's by more than 1e-4");
    return;
  }
  std::vector<float> out(4 * q.size());
  Clocks clocks;
  for (auto _ : state) {
    clocks.begin();
    l.run(q, out.data());
    benchmark::DoNotOptimize(out.data());
    state.SetIterationTime(clocks.end());
  }
  clocks.report(state, static_cast<double>(q.size()));
  std::vector<double> kernel_ms = l.time(q, 3);
  std::sort(kernel_ms.begin(), kernel_ms.end());
  set_rate(state, static_cast<double>(q.size()), kernel_ms[1] * 1e-3, "kernel_lookups_per_s");
  state.counters["queries"] = static_cast<double>(q.size());
}

void twin_lookups(benchmark::State& state, std::string file, FilterKind filter) {
  const seamcl::PtexFilterData& data = texture(file);
  const std::vector<PtexFilterQuery>& all = queries(file, filter);
  const std::vector<PtexFilterQuery> q(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(all.size() / 16));
  float sink = 0.0f;
  Clocks clocks;
  for (auto _ : state) {
    clocks.begin();
    for (const PtexFilterQuery& one : q) sink += seamcl::ptex_filter_twin(data, one)[0];
    state.SetIterationTime(clocks.end());
  }
  benchmark::DoNotOptimize(sink);
  clocks.report(state, static_cast<double>(q.size()));
}

#ifdef SEAMCL_WITH_PTEX

PtexTexture* ptex_texture(const std::string& file) {
  // Big enough never to evict: the timed loops then read faces already in memory, as the device does.
  static PtexCache* cache = PtexCache::create(0, size_t(4) << 30);
  static std::map<std::string, PtexTexture*> open;
  PtexTexture*& slot = open[file];
  if (!slot) {
    Ptex::String error;
    slot = cache->get(asset_path(file).c_str(), error);
    if (!slot) throw std::runtime_error(asset_path(file) + ": " + error.c_str());
  }
  return slot;
}

void ptex_eval(PtexFilter* f, const std::vector<PtexFilterQuery>& q, size_t begin, size_t end, int channels, float* out) {
  for (size_t i = begin; i < end; ++i)
    f->eval(out + 4 * i, 0, channels, q[i].face, q[i].u, q[i].v, q[i].uw, 0.0f, 0.0f, q[i].vw);
}

void ptex_lookups(benchmark::State& state, std::string file, FilterKind filter, int threads) {
  const std::vector<PtexFilterQuery>& q = queries(file, filter);
  PtexTexture* tx = ptex_texture(file);
  const int channels = tx->numChannels();
  const PtexFilter::Options options(filter.ptex, false, filter.sharpness);
  std::vector<PtexFilter*> filters;
  for (int t = 0; t < threads; ++t) filters.push_back(PtexFilter::getFilter(tx, options));
  std::vector<float> values(4 * q.size(), 0.0f);
  ptex_eval(filters[0], q, 0, q.size(), channels, values.data());  // reads every face it needs
  const double diff = max_abs_diff(values, device_values(file, filter), q.size(), channels);
  state.counters["max_abs_diff_vs_device"] = diff;
  if (!(diff <= kParityLimit)) {
    for (PtexFilter* f : filters) f->release();
    state.SkipWithError("the Ptex library's values differ from the device's by more than 1e-4");
    return;
  }
  Clocks clocks;
  for (auto _ : state) {
    clocks.begin();
    if (threads == 1) {
      ptex_eval(filters[0], q, 0, q.size(), channels, values.data());
    } else {
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t)
        pool.emplace_back(ptex_eval, filters[static_cast<size_t>(t)], std::cref(q), q.size() * static_cast<size_t>(t) / static_cast<size_t>(threads),
                          q.size() * static_cast<size_t>(t + 1) / static_cast<size_t>(threads), channels, values.data());
      for (std::thread& t : pool) t.join();
    }
    state.SetIterationTime(clocks.end());
  }
  benchmark::DoNotOptimize(values.data());
  for (PtexFilter* f : filters) f->release();
  clocks.report(state, static_cast<double>(q.size()));
  state.counters["threads"] = threads;
}

#endif

// --queries=N, taken out of argv before Google Benchmark reads its own flags.
void take_own_flags(int& argc, char** argv) {
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const char* flag = "--queries=";
    if (std::strncmp(argv[i], flag, std::strlen(flag)) == 0) {
      const char* text = argv[i] + std::strlen(flag);
      char* end = nullptr;
      const long n = std::strtol(text, &end, 10);
      if (*text == '\0' || *end != '\0' || n < 64 || n > (1L << 24)) {
        std::fprintf(stderr, "--queries: must be a whole number from 64 to 16777216, not '%s'\n", text);
        std::exit(2);
      }
      g_queries = static_cast<int>(n);
    } else {
      argv[kept++] = argv[i];
    }
  }
  argc = kept;
}

}  // namespace

int main(int argc, char** argv) {
  take_own_flags(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 2;
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
#ifdef SEAMCL_WITH_PTEX
  benchmark::AddCustomContext("ptex_library", "yes");
#else
  benchmark::AddCustomContext("ptex_library", "no (configure with -DSEAMCL_PTEX_ROOT=prefix to compare)");
#endif
  benchmark::AddCustomContext("hardware_threads", std::to_string(cores));
  benchmark::AddCustomContext("queries", std::to_string(g_queries));
  // Each file's rows side by side, so that a change in the machine's load touches all of them.
  for (const char* file : kFiles)
    for (const FilterKind& filter : kFilters) {
      const std::string tail = std::string(file) + "/" + filter.name;
      benchmark::RegisterBenchmark(("device/" + tail).c_str(), device_lookups, file, filter)
          ->UseManualTime()->Unit(benchmark::kMillisecond);
#ifdef SEAMCL_WITH_PTEX
      benchmark::RegisterBenchmark(("ptex_1_thread/" + tail).c_str(), ptex_lookups, file, filter, 1)
          ->UseManualTime()->Unit(benchmark::kMillisecond);
      benchmark::RegisterBenchmark(("ptex_all_cores/" + tail).c_str(), ptex_lookups, file, filter, cores)
          ->UseManualTime()->Unit(benchmark::kMillisecond);
#endif
      benchmark::RegisterBenchmark(("twin/" + tail).c_str(), twin_lookups, file, filter)
          ->UseManualTime()->Unit(benchmark::kMillisecond);
    }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
