// Program binaries kept on disk (host/cl/program_cache.h) and the warm-up that fills them
// (host/jobs/warmup_job.h): a hit skips the build, a damaged entry is built again and replaced,
// the key follows everything the binary depends on, concurrent requests build once.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/cl/program_cache.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/reference.h>
#include <seamcl/jobs/warmup_job.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/stages/downsample_twin.h"

using namespace seamcl;
namespace fs = std::filesystem;

namespace {

// A fresh directory per test, removed after.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name) {
    path = fs::temp_directory_path() / ("seamcl-program-cache-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

// The default render's program variant: what most tests build anyway (PoCL's own cache then
// makes the from-source builds here quick).
std::string default_variant() {
  const RenderOptions options;
  return program_options(options.texels, sampler_params(options));
}

// A 16x16 frame of quad2 rendered with `runtime`'s programs.
std::vector<glm::vec4> tiny_frame(ClRuntime& runtime) {
  Renderer renderer(runtime);
  renderer.load_scene(generate_scene("quad2", GeneratorOptions{}));
  RenderOptions options;
  options.width = options.height = 16;
  return renderer.render(renderer.scene().camera, options).pixels;
}

std::vector<char> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& path, const std::vector<char>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace

TEST(ProgramCache, HitSkipsTheBuildAndRendersTheSameImage) {
  TempDir dir("hit");
  const std::string options = default_variant();
  ClRuntime first;
  first.set_program_cache_dir(dir.path.string());
  const std::vector<glm::vec4> built_image = tiny_frame(first);
  const ClRuntime::ProgramStats built = first.program_stats();
  EXPECT_EQ(built.built, 2) << "a frame builds the geometry program and one shading variant";
  EXPECT_EQ(built.loaded, 0);
  EXPECT_EQ(built.stored, 2);
  const fs::path entry = ProgramCache(dir.path.string()).path(first.program_cache_key(KernelProgram::Shading, options));
  ASSERT_TRUE(fs::is_regular_file(entry)) << entry;

  ClRuntime second;  // a new process, as far as the cache can tell: nothing built yet
  second.set_program_cache_dir(dir.path.string());
  const std::vector<glm::vec4> loaded_image = tiny_frame(second);
  const ClRuntime::ProgramStats loaded = second.program_stats();
  EXPECT_EQ(loaded.built, 0) << "a whole entry was there: nothing may be built from source";
  EXPECT_EQ(loaded.loaded, 2);
  EXPECT_EQ(loaded.stored, 0);
  ASSERT_EQ(loaded_image.size(), built_image.size());
  EXPECT_EQ(0, std::memcmp(loaded_image.data(), built_image.data(), built_image.size() * sizeof(glm::vec4)))
      << "the loaded binary renders other pixels than the one built from source";
}

TEST(ProgramCache, TruncatedCorruptOrRefusedEntryIsBuiltAgainAndReplaced) {
  TempDir dir("corrupt");
  const std::string options = default_variant();
  ClRuntime writer;
  writer.set_program_cache_dir(dir.path.string());
  writer.program(KernelProgram::Shading, options);
  const ProgramCache cache(dir.path.string());
  const ProgramCacheKey key = writer.program_cache_key(KernelProgram::Shading, options);
  const fs::path entry = cache.path(key);
  const std::vector<char> whole = read_bytes(entry);
  ASSERT_GT(whole.size(), 200u);
  ASSERT_TRUE(cache.load(key).has_value());

  std::vector<char> flipped = whole;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x5a);  // inside the binary
  const std::vector<std::pair<std::string, std::vector<char>>> damages = {
      {"truncated", std::vector<char>(whole.begin(), whole.begin() + static_cast<std::ptrdiff_t>(whole.size() / 2))},
      {"a byte flipped", flipped},
      {"empty", {}},
  };
  for (const auto& [what, bytes] : damages) {
    SCOPED_TRACE(what);
    write_bytes(entry, bytes);
    EXPECT_FALSE(cache.load(key).has_value());
    ClRuntime reader;
    reader.set_program_cache_dir(dir.path.string());
    reader.program(KernelProgram::Shading, options);
    const ClRuntime::ProgramStats stats = reader.program_stats();
    EXPECT_EQ(stats.cache_rejected, 1);
    EXPECT_EQ(stats.built, 1);
    EXPECT_EQ(stats.loaded, 0);
    EXPECT_EQ(stats.stored, 1);
    EXPECT_TRUE(cache.load(key).has_value()) << "the rebuilt program was not stored whole again";
  }

  // A well-formed entry whose binary the driver refuses (garbage where the binary goes).
  ASSERT_TRUE(cache.store(key, std::vector<unsigned char>(4096, 0xab)));
  ClRuntime reader;
  reader.set_program_cache_dir(dir.path.string());
  reader.program(KernelProgram::Shading, options);
  EXPECT_EQ(reader.program_stats().cache_rejected, 1);
  EXPECT_EQ(reader.program_stats().built, 1);
  const std::optional<std::vector<unsigned char>> replaced = cache.load(key);
  ASSERT_TRUE(replaced.has_value());
  EXPECT_NE(*replaced, std::vector<unsigned char>(4096, 0xab));
}

TEST(ProgramCache, KeyFollowsBuildOptionsSourceDeviceAndDriver) {
  ClRuntime runtime;
  const ProgramCacheKey a = runtime.program_cache_key(KernelProgram::Shading, "-DSEAMCL_TEXELS_F32=0");
  const ProgramCacheKey b = runtime.program_cache_key(KernelProgram::Shading, "-DSEAMCL_TEXELS_F32=1");
  EXPECT_NE(a.key(), runtime.program_cache_key(KernelProgram::Sampling, "-DSEAMCL_TEXELS_F32=0").key())
      << "programs of other files under the same options share a key";
  EXPECT_NE(a.key(), b.key());
  EXPECT_NE(a.file_name(), b.file_name());
  EXPECT_NE(a.build_options.find("-DSEAMCL_TEXELS_F32=0"), std::string::npos);
  EXPECT_EQ(a.device, runtime.info().name);
  EXPECT_FALSE(a.driver_version.empty());
  EXPECT_EQ(a.key(), runtime.program_cache_key(KernelProgram::Shading, "-DSEAMCL_TEXELS_F32=0").key())
      << "the key must be stable";
  for (std::string ProgramCacheKey::*field : {&ProgramCacheKey::platform, &ProgramCacheKey::device,
                                              &ProgramCacheKey::device_version, &ProgramCacheKey::driver_version,
                                              &ProgramCacheKey::source_hash}) {
    ProgramCacheKey other = a;
    other.*field += "x";
    EXPECT_NE(other.file_name(), a.file_name());
  }

  // An entry found under another key's name (a hash collision, a file copied) is a miss.
  TempDir dir("key");
  const ProgramCache cache(dir.path.string());
  ASSERT_TRUE(cache.store(a, {1, 2, 3}));
  fs::copy_file(cache.path(a), cache.path(b));
  EXPECT_FALSE(cache.load(b).has_value());
  EXPECT_EQ(cache.load(a), (std::vector<unsigned char>{1, 2, 3}));
}

TEST(ProgramCache, TrimKeepsTheMostRecentlyUsedWithinTheBound) {
  TempDir dir("trim");
  const ProgramCache cache(dir.path.string());
  std::vector<ProgramCacheKey> keys(3);
  for (size_t i = 0; i < keys.size(); ++i) {
    keys[i].build_options = "-DN=" + std::to_string(i);
    ASSERT_TRUE(cache.store(keys[i], std::vector<unsigned char>(1000, static_cast<unsigned char>(i))));
    fs::last_write_time(cache.path(keys[i]), fs::file_time_type::clock::now() - std::chrono::minutes(10 - i));
  }
  ASSERT_TRUE(cache.load(keys[0]).has_value());  // used now: the most recent
  EXPECT_EQ(cache.trim(2 * (1000 + 200)), 1u);
  EXPECT_TRUE(cache.load(keys[0]).has_value());
  EXPECT_FALSE(fs::exists(cache.path(keys[1])));
  EXPECT_TRUE(cache.load(keys[2]).has_value());
}

TEST(ProgramCache, ConcurrentRequestsForOneVariantBuildItOnce) {
  TempDir dir("once");
  ClRuntime runtime;
  runtime.set_program_cache_dir(dir.path.string());
  const std::string options = default_variant();
  std::vector<const cl::Program*> seen(4);
  std::vector<std::thread> threads;
  for (size_t i = 0; i < seen.size(); ++i) threads.emplace_back([&, i] { seen[i] = &runtime.program(KernelProgram::Shading, options); });
  for (std::thread& t : threads) t.join();
  for (const cl::Program* p : seen) EXPECT_EQ(p, seen.front());
  EXPECT_EQ(runtime.program_stats().built + runtime.program_stats().loaded, 1);
}

// build_programs_ahead builds each distinct variant of the renders it is given once (two renders
// that share one, and a seam-mask render that needs another), and the downsample program for a
// render reduced on the device, and the renders that follow find every program built.
TEST(ProgramCache, VariantsBuiltAheadAreTheOnesTheRendersUse) {
  ClRuntime runtime;
  runtime.set_program_cache_dir("");  // builds only: PoCL keeps its own cache
  const Scene scene = generate_scene("quad2", GeneratorOptions{});
  RenderOptions plain;
  plain.width = plain.height = 16;
  RenderOptions mask = plain;
  mask.method = Method::Black;  // footprint_seam_mask's render
  RenderOptions reduced = plain;
  reduced.width = reduced.height = 64;
  build_programs_ahead(runtime, scene, {{plain, false}, {plain, false}, {mask, true}, {reduced, false, true}}).get();
  const ClRuntime::ProgramStats ahead = runtime.program_stats();
  EXPECT_EQ(ahead.built + ahead.loaded, 4) << "the geometry program, two shading variants and the downsample program";
  Renderer renderer(runtime);
  renderer.load_scene(scene);
  renderer.render(scene.camera, plain);
  renderer.render(scene.camera, mask, true);
  const RenderResult small = renderer.render_downsampled(scene.camera, reduced, box_taps());
  EXPECT_GT(small.width, 0);
  EXPECT_LT(small.width, reduced.width) << "reduced on the device";
  const ClRuntime::ProgramStats after = runtime.program_stats();
  EXPECT_EQ(after.built + after.loaded, 4) << "a render built a program the builds ahead did not";
}

TEST(Warmup, VariantsCoverEveryMethodAndFilterOnce) {
  const std::vector<WarmupVariant> variants = warmup_variants();
  // Ptex's filters: one variant for all of them (filter and seam rule are run-time settings), no seam mask.
  size_t patch_filters = 0;
  for (const std::string& filter : filter_names()) patch_filters += !is_ptex_filter(*parse_filter(filter));
  EXPECT_EQ(variants.size(), method_names().size() * patch_filters + 1 + patch_filters);
  std::set<std::string> names, options;
  for (const WarmupVariant& v : variants) {
    names.insert(v.name);
    options.insert(v.build_options);
    EXPECT_EQ(v.build_options, program_options(v.options.texels, sampler_params(v.options), v.seam_mask));
  }
  EXPECT_EQ(names.size(), variants.size());
  // Methods that differ only in what the host does may share a program; the seam-mask builds never do.
  EXPECT_GE(options.size(), patch_filters * 2 + 1);
}

TEST(Warmup, BuildsInParallelThenRendersEachWithProgress) {
  TempDir dir("warmup");
  ClRuntime runtime;
  runtime.set_program_cache_dir(dir.path.string());
  std::vector<WarmupVariant> variants = warmup_variants();
  const std::vector<WarmupVariant> three = {variants[0], variants[1], variants.back()};
  const WarmupJob job(nlohmann::json{{"threads", 2}});
  std::vector<std::string> lines;
  const WarmupReport report = job.run(runtime, three, [&](const std::string& line) { lines.push_back(line); });
  EXPECT_EQ(report.variants, 3);
  EXPECT_EQ(report.threads, 2);
  EXPECT_EQ(report.built + report.loaded, static_cast<int>(std::set<std::string>{three[0].build_options,
                                                                                 three[1].build_options,
                                                                                 three[2].build_options}
                                                                 .size()) + 2)
      << "each distinct shading variant and the geometry and downsample programs they share";
  ASSERT_EQ(lines.size(), 8u);  // five built (the geometry and downsample programs among them), three rendered
  EXPECT_NE(lines[0].find("built 1/5"), std::string::npos) << lines[0];
  EXPECT_EQ(std::count_if(lines.begin(), lines.end(),
                          [](const std::string& l) { return l.find(": geometry stages") != std::string::npos; }),
            1);
  EXPECT_EQ(std::count_if(lines.begin(), lines.end(),
                          [](const std::string& l) { return l.find(": downsample") != std::string::npos; }),
            1);
  EXPECT_NE(lines[7].find("rendered 3/3: " + three[2].name), std::string::npos) << lines[7];
  EXPECT_EQ(report.cache_dir, dir.path.string());
  EXPECT_GE(report.total_ms, report.build_ms + report.render_ms - 1.0);

  // A second warm-up in a new runtime loads every program from the cache.
  ClRuntime restarted;
  restarted.set_program_cache_dir(dir.path.string());
  const WarmupReport again = WarmupJob(nlohmann::json{{"no_render", true}}).run(restarted, three);
  EXPECT_EQ(again.built, 0);
  EXPECT_EQ(again.loaded, report.built + report.loaded);
  EXPECT_EQ(again.render_ms, 0.0);
}

TEST(Warmup, RequestIsChecked) {
  try {
    WarmupJob(nlohmann::json{{"threads", -1}});
    FAIL() << "threads -1 accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "threads");
  }
  try {
    WarmupJob(nlohmann::json{{"thread", 2}});
    FAIL() << "an unknown key accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "thread");
  }
}

// The program cache as a process finds it ($SEAMCL_CACHE_DIR, no $SEAMCL_PROGRAM_CACHE): on PoCL a
// render reads binaries but writes none (asking PoCL for one compiles every kernel), a warm-up
// writes them, and the next process's render loads them and draws the same image. Elsewhere the
// render writes them itself.
TEST(ProgramCache, WarmupWritesWhatLaterProcessesLoad) {
  TempDir dir("default");
  // The suite's tests share a process: the variables go back as they were.
  struct RestoreEnv {
    std::vector<std::pair<std::string, std::optional<std::string>>> saved;
    RestoreEnv() {
      for (const char* name : {"SEAMCL_CACHE_DIR", "SEAMCL_PROGRAM_CACHE"}) {
        const char* value = std::getenv(name);
        saved.emplace_back(name, value ? std::optional<std::string>(value) : std::nullopt);
      }
    }
    ~RestoreEnv() {
      for (const auto& [name, value] : saved) value ? ::setenv(name.c_str(), value->c_str(), 1) : ::unsetenv(name.c_str());
    }
  } restore;
  ::setenv("SEAMCL_CACHE_DIR", dir.path.string().c_str(), 1);
  ::unsetenv("SEAMCL_PROGRAM_CACHE");
  const std::string programs = (dir.path / "programs").string();
  std::vector<glm::vec4> before_warmup;
  bool pocl = false;
  {
    ClRuntime runtime;
    pocl = runtime.info().platform.find("Portable Computing Language") != std::string::npos;
    EXPECT_EQ(runtime.program_cache_dir(), programs);
    EXPECT_EQ(runtime.program_cache_writes(), !pocl);
    before_warmup = tiny_frame(runtime);
    const ClRuntime::ProgramStats stats = runtime.program_stats();
    EXPECT_EQ(stats.built, 2);
    EXPECT_EQ(stats.stored, pocl ? 0 : 2);
  }
  const RenderOptions defaults;
  const std::string default_options = program_options(defaults.texels, sampler_params(defaults));
  const std::vector<WarmupVariant> all = warmup_variants();
  const auto variant = std::find_if(all.begin(), all.end(), [&](const WarmupVariant& v) { return v.build_options == default_options; });
  ASSERT_NE(variant, all.end()) << "no warm-up variant builds the default render's program";
  {
    ClRuntime runtime;
    const WarmupReport report = WarmupJob(nlohmann::json{{"no_render", true}}).run(runtime, {*variant});
    EXPECT_EQ(report.built + report.loaded, 3) << "the geometry, downsample and default shading programs";
    EXPECT_EQ(runtime.program_stats().stored, report.built) << "a warm-up writes what it builds, PoCL too";
  }
  ClRuntime later;
  const std::vector<glm::vec4> after_warmup = tiny_frame(later);
  const ClRuntime::ProgramStats stats = later.program_stats();
  EXPECT_EQ(stats.built, 0);
  EXPECT_EQ(stats.loaded, 2);
  ASSERT_EQ(after_warmup.size(), before_warmup.size());
  for (size_t p = 0; p < after_warmup.size(); ++p) ASSERT_EQ(after_warmup[p], before_warmup[p]) << "pixel " << p;
  ::setenv("SEAMCL_PROGRAM_CACHE", "off", 1);
  ClRuntime without;
  EXPECT_EQ(without.program_cache_dir(), "");
  EXPECT_FALSE(without.program_cache_writes());
}
