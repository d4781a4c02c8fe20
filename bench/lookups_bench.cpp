// Filtered texture lookups per second: seamcl's sampler on the OpenCL device (bilinear,
// trilinear, aniso with max anisotropy 16, ewa; RGBA8 and RGBA32F storage) against OpenImageIO's
// TextureSystem on two threads (NoMIP bilinear, trilinear, MipModeAniso with bilinear probes), on
// one 1024x1024 texture with a full mip chain and the same 4M random lookups.
//
// Lookups: uv uniform in [0,1]^2; footprints from isotropic to strongly anisotropic: minor axis
// 0.5..4 level-0 texels, major / minor 1..16, random orientation, either screen axis the major.
// seamcl time = the kernel's OpenCL profiling time (one launch of all 4M lookups per iteration;
// the read-back of the results is not timed). OIIO time = wall time of two std::threads each
// doing half the lookups with texture() (handle + per-thread info), from thread start to join.
// Both are reported as manual time; the counter lookups_per_s is 4M * iterations / total time.
//
// OIIO reads the RGBA32F texels as a tiled MIP-mapped float EXR (our own levels). An 8-bit
// OIIO texture would hold sRGB codes that OIIO (2.4, no colour transform) filters as if linear,
// i.e. different data, so OIIO is measured on the float file only and seamcl's RGBA8 figures
// are compared with that.
//
// At the end it prints the ratios, each of median rates over the repetitions: seamcl aniso16 /
// OIIO aniso, seamcl trilinear / OIIO trilinear, and aniso / (trilinear / mean probe count),
// where the mean probe count is computed on the host with the kernel's formula
// N = min(ceil(major / minor), 16).
//
// Run: build/seamcl_bench_lookups   (minutes: every filter on both sides; --benchmark_filter=
// seamcl or =oiio to run one side; --benchmark_format=json sends the ratios to stderr;
// --lookups=N, 1024..16M, runs N lookups per launch instead of 4M: seconds, for checking the
// benchmark rather than measuring with it).
#include <benchmark/benchmark.h>

#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <unistd.h>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/texture_lookups.h>
#include <seamcl/scene/scene.h>
#include "io/texture_file.h"
#include "pipeline/stages/texture_sample_twin.h"

using namespace seamcl;
namespace fs = std::filesystem;

namespace {

constexpr int kSide = 1024;
constexpr size_t kDefaultLookups = size_t{1} << 22;  // 4M per kernel launch
constexpr size_t kMinLookups = 1024, kMaxLookups = size_t{1} << 24;
size_t g_lookups = kDefaultLookups;  // --lookups=N: smaller runs that check the benchmark, not measure it
constexpr int kMaxAniso = 16;

struct Workload {
  std::vector<Lookup> lookups;
  double mean_probes = 0.0;       // seamcl aniso: N = min(ceil(major / minor), 16)
  double oiio_mean_samples = 0.0; // OIIO MipModeAniso: bilinear probes per level, max(1, int(2 aspect - 1))
};

Workload make_workload() {
  Workload w;
  w.lookups.resize(g_lookups);
  std::mt19937 rng(2024u);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float side = static_cast<float>(kSide);
  double probes = 0.0, samples = 0.0;
  for (Lookup& l : w.lookups) {
    l.u = unit(rng);
    l.v = unit(rng);
    const float minor = 0.5f + 3.5f * unit(rng);      // texels
    const float major = minor * (1.0f + 15.0f * unit(rng));
    const float theta = 2.0f * std::numbers::pi_v<float> * unit(rng);
    const float c = std::cos(theta), s = std::sin(theta);
    float ax_u = major * c / side, ax_v = major * s / side;    // major axis, uv per pixel
    float ay_u = -minor * s / side, ay_v = minor * c / side;   // minor axis
    if (rng() & 1u) {
      std::swap(ax_u, ay_u);
      std::swap(ax_v, ay_v);
    }
    l.dudx = ax_u, l.dvdx = ax_v, l.dudy = ay_u, l.dvdy = ay_v;
    // The kernel's probe count (accumulate_aniso), from the same float arithmetic.
    const float len2_x = (l.dudx * side) * (l.dudx * side) + (l.dvdx * side) * (l.dvdx * side);
    const float len2_y = (l.dudy * side) * (l.dudy * side) + (l.dvdy * side) * (l.dvdy * side);
    const float major2 = std::max(len2_x, len2_y), minor2 = std::min(len2_x, len2_y);
    const float ratio = minor2 > 0.0f ? std::sqrt(major2 / minor2) : static_cast<float>(kMaxAniso);
    probes += std::clamp(static_cast<int>(std::ceil(std::min(ratio, 16.0f))), 1, kMaxAniso);
    // OIIO's sample count (texture_lookup: aspect clamped to `anisotropic`; the axes are
    // orthogonal here, so the ellipse axes are the two derivative lengths).
    const float aspect = std::clamp(std::sqrt(major2 / minor2), 1.0f, static_cast<float>(kMaxAniso));
    samples += std::max(1, static_cast<int>(2.0f * aspect - 1.0f));
  }
  w.mean_probes = probes / static_cast<double>(g_lookups);
  w.oiio_mean_samples = samples / static_cast<double>(g_lookups);
  return w;
}

const Workload& workload() {
  static const Workload w = make_workload();
  return w;
}

Scene texture_scene() {
  std::mt19937 rng(7u);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  TextureLevel level{kSide, kSide, {}};
  level.texels.reserve(static_cast<size_t>(kSide) * kSide);
  for (int i = 0; i < kSide * kSide; ++i) level.texels.emplace_back(unit(rng), unit(rng), unit(rng), 1.0f);
  Scene scene;
  scene.name = "bench-lookups";
  scene.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  Face face;
  face.vertices = {0, 1, 2, 3};
  face.texture = build_mip_chain(std::move(level));
  scene.faces.push_back(std::move(face));
  return scene;
}

// Everything both sides share, built once in main.
struct Setup {
  ClRuntime runtime;
  std::map<TexelFormat, std::unique_ptr<TextureLookups>> lookups;
  fs::path dir;
  std::string exr_path;
  OIIO::TextureSystem* oiio = nullptr;
};
Setup* g_setup = nullptr;
// benchmark name -> lookups per second of each repetition (--benchmark_repetitions runs a
// benchmark that many times; the ratios use the median, as the aggregates do)
std::map<std::string, std::vector<double>> g_rates;

void record(benchmark::State& state, const std::string& name, double lookups, double seconds) {
  const double rate = seconds > 0.0 ? lookups / seconds : 0.0;
  state.counters["lookups_per_s"] = rate;
  g_rates[name].push_back(rate);
}

void bm_seamcl(benchmark::State& state, Filter filter, TexelFormat format, const std::string& name) {
  TextureLookups& lookups = *g_setup->lookups.at(format);
  const SamplerParams sampler = sampler_params(Method::Clamp, filter, kMaxAniso, ZeroCoverage::Clamp);
  double ms = 0.0;
  lookups.sample(sampler, &ms);  // warm-up: builds the program variant, PoCL's per-size compile
  double total_ms = 0.0;
  double launches = 0.0;
  for (auto _ : state) {
    lookups.sample(sampler, &ms);
    state.SetIterationTime(ms / 1000.0);
    total_ms += ms;
    launches += 1.0;
  }
  record(state, name, launches * static_cast<double>(g_lookups), total_ms / 1000.0);
  if (filter == Filter::Aniso) state.counters["mean_probes"] = workload().mean_probes;
}

void oiio_range(OIIO::TextureOpt::MipMode mip, size_t begin, size_t end, float* out) {
  OIIO::TextureSystem* ts = g_setup->oiio;
  OIIO::TextureSystem::Perthread* thread_info = ts->create_thread_info();
  OIIO::TextureSystem::TextureHandle* handle =
      ts->get_texture_handle(OIIO::ustring(g_setup->exr_path), thread_info);
  OIIO::TextureOpt opt;
  opt.swrap = OIIO::TextureOpt::WrapClamp;
  opt.twrap = OIIO::TextureOpt::WrapClamp;
  opt.mipmode = mip;
  opt.interpmode = OIIO::TextureOpt::InterpBilinear;
  opt.anisotropic = kMaxAniso;
  const std::vector<Lookup>& lookups = workload().lookups;
  for (size_t i = begin; i < end; ++i) {
    const Lookup& l = lookups[i];
    ts->texture(handle, thread_info, opt, l.u, l.v, l.dudx, l.dvdx, l.dudy, l.dvdy, 4, out + 4 * i);
  }
  ts->destroy_thread_info(thread_info);
}

// Seconds for lookups [0, count) on two threads, half each.
double oiio_run(OIIO::TextureOpt::MipMode mip, size_t count, std::vector<float>& out) {
  const auto start = std::chrono::steady_clock::now();
  std::thread first(oiio_range, mip, size_t{0}, count / 2, out.data());
  std::thread second(oiio_range, mip, count / 2, count, out.data());
  first.join();
  second.join();
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void bm_oiio(benchmark::State& state, OIIO::TextureOpt::MipMode mip, const std::string& name) {
  std::vector<float> out(4 * g_lookups);
  oiio_run(mip, g_lookups / 8, out);  // warm-up: tiles into the cache, thread-local state
  double total = 0.0, runs = 0.0;
  for (auto _ : state) {
    const double seconds = oiio_run(mip, g_lookups, out);
    state.SetIterationTime(seconds);
    total += seconds;
    runs += 1.0;
  }
  benchmark::DoNotOptimize(out.data());
  record(state, name, runs * static_cast<double>(g_lookups), total);
  if (mip == OIIO::TextureOpt::MipModeAniso) state.counters["mean_samples_per_level"] = workload().oiio_mean_samples;
}

void print_ratios(std::FILE* f) {
  auto rate = [](const std::string& name) {
    auto it = g_rates.find(name);
    if (it == g_rates.end() || it->second.empty()) return std::nan("");
    std::vector<double> rates = it->second;
    std::sort(rates.begin(), rates.end());
    const size_t n = rates.size();
    return n % 2 == 1 ? rates[n / 2] : 0.5 * (rates[n / 2 - 1] + rates[n / 2]);
  };
  auto line = [&](const char* what, double value, const char* goal) {
    if (std::isnan(value)) {
      std::fprintf(f, "  %-58s    n/a (not run)\n", what);
    } else {
      std::fprintf(f, "  %-58s %6.2f%s\n", what, value, goal);
    }
  };
  const double probes = workload().mean_probes;
  std::fprintf(f, "\nRatios (mean aniso probe count N = %.2f; OIIO aniso mean samples per level = %.2f):\n", probes,
               workload().oiio_mean_samples);
  for (const char* fmt : {"rgba32f", "rgba8"}) {
    const std::string s = fmt;
    std::fprintf(f, " seamcl %s (OIIO: float EXR, 2 threads):\n", fmt);
    line("seamcl aniso16 / OIIO aniso", rate("seamcl/aniso16/" + s) / rate("oiio/aniso16/f32"), "   (goal >= 10)");
    line("seamcl trilinear / OIIO trilinear", rate("seamcl/trilinear/" + s) / rate("oiio/trilinear/f32"),
         "   (goal >= 25)");
    line("seamcl bilinear / OIIO bilinear (NoMIP)", rate("seamcl/bilinear/" + s) / rate("oiio/bilinear/f32"), "");
    line("seamcl aniso16 / (seamcl trilinear / mean probes)",
         rate("seamcl/aniso16/" + s) / (rate("seamcl/trilinear/" + s) / probes), "   (goal >= 1.3)");
  }
}

}  // namespace

// Takes --lookups=N out of argv (Google Benchmark refuses flags it does not know); false and a
// message when N is not a whole number in [kMinLookups, kMaxLookups].
bool take_lookups_flag(int& argc, char** argv) {
  const std::string prefix = "--lookups=";
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind(prefix, 0) != 0) {
      argv[kept++] = argv[i];
      continue;
    }
    const std::string value = arg.substr(prefix.size());
    size_t used = 0;
    unsigned long long n = 0;
    try {
      n = std::stoull(value, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != value.size() || n < kMinLookups || n > kMaxLookups) {
      std::fprintf(stderr, "--lookups must be a whole number from %zu to %zu, got '%s'\n", kMinLookups, kMaxLookups,
                   value.c_str());
      return false;
    }
    g_lookups = static_cast<size_t>(n);
  }
  argc = kept;
  return true;
}

int main(int argc, char** argv) {
  if (!take_lookups_flag(argc, argv)) return 2;
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  bool console = true;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--benchmark_format=", 0) == 0 && arg != "--benchmark_format=console") console = false;
  }

  Setup setup;
  g_setup = &setup;
  {
    const Scene scene = texture_scene();
    const PackedScene f32 = pack_scene(scene, TexelFormat::Rgba32f);
    const PackedScene u8 = pack_scene(scene, TexelFormat::Rgba8);
    setup.dir = fs::temp_directory_path() / ("seamcl-bench-" + std::to_string(::getpid()));
    fs::create_directories(setup.dir);
    setup.exr_path = (setup.dir / "texture.exr").string();
    write_face_mip_exr(f32, 0, setup.exr_path);
    for (const PackedScene* packed : {&f32, &u8}) {
      auto lookups = std::make_unique<TextureLookups>(setup.runtime, *packed);
      lookups->set_lookups(workload().lookups);
      setup.lookups[packed->format] = std::move(lookups);
    }
  }
  setup.oiio = OIIO::TextureSystem::create(true);
  setup.oiio->attribute("max_memory_MB", 1024.0f);  // the whole chain (22 MB) stays cached

  struct FilterCase {
    Filter filter;
    const char* name;
    int iterations;
  };
  const FilterCase filters[] = {{Filter::Bilinear, "bilinear", 5},
                                {Filter::Trilinear, "trilinear", 5},
                                {Filter::Aniso, "aniso16", 3},
                                {Filter::Ewa, "ewa16", 2}};
  for (const FilterCase& fc : filters) {
    for (TexelFormat format : {TexelFormat::Rgba8, TexelFormat::Rgba32f}) {
      const std::string name =
          std::string("seamcl/") + fc.name + (format == TexelFormat::Rgba8 ? "/rgba8" : "/rgba32f");
      benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& s) { bm_seamcl(s, fc.filter, format, name); })
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->Iterations(fc.iterations);
    }
  }
  const std::pair<OIIO::TextureOpt::MipMode, const char*> modes[] = {
      {OIIO::TextureOpt::MipModeNoMIP, "oiio/bilinear/f32"},
      {OIIO::TextureOpt::MipModeTrilinear, "oiio/trilinear/f32"},
      {OIIO::TextureOpt::MipModeAniso, "oiio/aniso16/f32"}};
  for (const auto& [mip, name_c] : modes) {
    const std::string name = name_c;
    const auto mode = mip;
    benchmark::RegisterBenchmark(name.c_str(), [=](benchmark::State& s) { bm_oiio(s, mode, name); })
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond)
        ->Iterations(2);
  }

  std::fprintf(console ? stdout : stderr, "device: %s; %zu lookups per launch, %dx%d texture, %u host threads\n",
               setup.runtime.device_description().c_str(), g_lookups, kSide, kSide,
               std::thread::hardware_concurrency());
  std::fflush(console ? stdout : stderr);
  benchmark::RunSpecifiedBenchmarks();
  print_ratios(console ? stdout : stderr);
  benchmark::Shutdown();

  OIIO::TextureSystem::destroy(setup.oiio);
  setup.lookups.clear();
  std::error_code ignored;
  fs::remove_all(setup.dir, ignored);
  return 0;
}
