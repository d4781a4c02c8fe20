// Loading Ptex files: read_ptex_file's wall time (read, inflate, decode to float RGBA, build the
// chains) for the two larger samples, and what their texels take: the file, the host's float
// RGBA chains, and the device's packed texels (RGBA8 sRGB or RGBA32F, without and with the
// default guardband band of 4 texels), from packed_texture_memory (exact, see render_memory.h).
//
// Run: build/seamcl_bench_ptex   (5 repetitions of one load each; reports mean, median, stddev)
#include <benchmark/benchmark.h>

#include <filesystem>
#include <string>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/memory/render_memory.h>

namespace {

void load_ptex(benchmark::State& state, const std::string& name) {
  const std::string path = std::string(SEAMCL_TEST_ASSETS_DIR) + "/ptex/" + name + ".ptx";
  seamcl::PtexFile file;
  for (auto _ : state) {
    seamcl::PtexFile loaded = seamcl::read_ptex_file(path);
    state.PauseTiming();
    file = std::move(loaded);  // the previous load is freed outside the timing
    state.ResumeTiming();
  }
  seamcl::SceneSizes sizes;
  for (const seamcl::MipChain& chain : file.textures) sizes.faces.emplace_back(chain.width(), chain.height());
  const auto device = [&](seamcl::TexelFormat format, int band) {
    return static_cast<double>(seamcl::packed_texture_memory(sizes, format, band).texture_bytes);
  };
  const double texels = static_cast<double>(seamcl::ptex_texel_count(file));
  state.counters["file_bytes"] = static_cast<double>(std::filesystem::file_size(path));
  state.counters["faces"] = static_cast<double>(file.faces.size());
  state.counters["texels"] = texels;
  state.counters["host_float_bytes"] = texels * 16;
  state.counters["device_rgba8_bytes"] = device(seamcl::TexelFormat::Rgba8, 0);
  state.counters["device_rgba8_band4_bytes"] = device(seamcl::TexelFormat::Rgba8, 4);
  state.counters["device_f32_bytes"] = device(seamcl::TexelFormat::Rgba32f, 0);
}

BENCHMARK_CAPTURE(load_ptex, cube_text, "cube_text")
    ->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(5)->ReportAggregatesOnly(true)->UseRealTime();
BENCHMARK_CAPTURE(load_ptex, cellnoise, "cellnoise")
    ->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(5)->ReportAggregatesOnly(true)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
