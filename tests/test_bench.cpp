// seamcl bench (cli/bench_command.cpp) and the shared comparison loop (host/eval/comparison.h): the JSON
// shape and values on a small scene, bad input, and that `seamcl compare` still prints what its
// loop printed before it moved into host/eval/comparison.cpp.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/eval/reference.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>
#include "test_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace seamcl;

namespace {

struct BenchProcess {
  int exit_code = -1;
  std::string out, err;
};

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path bench_temp_dir() {
  std::string pattern = (fs::temp_directory_path() / "seamcl_bench_XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  return pattern;
}

BenchProcess run_cli(const fs::path& dir, const std::string& args) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = "cd '" + dir.string() + "' && SEAMCL_CACHE_DIR='" + (dir / "cache").string() + "' '" +
                              SEAMCL_BINARY + "' " + args + " >'" + out.string() + "' 2>'" + err.string() +
                              "' </dev/null";
  const int status = std::system(command.c_str());
  BenchProcess r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  r.out = read_all(out);
  r.err = read_all(err);
  return r;
}

const std::string kQuad2Bench = "bench --scene quad2 --methods discard,traverse,clamp --msaa 1,4 --size 48x48 --frames 3";

class Bench : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(bench_temp_dir());
    run_ = new BenchProcess(run_cli(*dir_, kQuad2Bench + " --json"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete run_;
  }
  static const json& bench_json() {
    static json j = json::parse(run_->out);
    return j;
  }
  static const json& result(const json& j, const std::string& method, int msaa) {
    for (const json& r : j["results"])
      if (r["method"] == method && r["msaa"] == msaa) return r;
    throw std::runtime_error("no result for " + method);
  }
  static fs::path* dir_;
  static BenchProcess* run_;
};
fs::path* Bench::dir_ = nullptr;
BenchProcess* Bench::run_ = nullptr;

TEST_F(Bench, Quad2JsonShapeAndValues) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  const json& j = bench_json();
  EXPECT_EQ(j["scene"], "quad2");
  EXPECT_EQ(j["size"], "48x48");
  EXPECT_EQ(j["frames"], 3);
  EXPECT_EQ(j["reference_frames"], 1);
  EXPECT_EQ(j["errors"], true);
  EXPECT_EQ(j["error_frames"], json::array({0, 1, 2}));
  EXPECT_EQ(j["reference"]["method"], default_reference_method());
  std::vector<std::pair<std::string, int>> seen;
  for (const json& r : j["results"]) seen.emplace_back(r["method"], r["msaa"]);
  const std::vector<std::pair<std::string, int>> expected = {{"discard", 1},  {"discard", 4},  {"traverse", 1},
                                                             {"traverse", 4}, {"clamp", 1},    {"clamp", 4}};
  EXPECT_EQ(seen, expected);
  for (const json& r : j["results"]) {
    SCOPED_TRACE(r["method"].get<std::string>() + " x" + std::to_string(r["msaa"].get<int>()));
    EXPECT_EQ(r["aniso"], 16);
    const json& ms = r["ms"];
    for (const char* k : {"median", "min", "max"}) EXPECT_GT(ms[k].get<double>(), 0.0) << k;
    EXPECT_LE(ms["min"].get<double>(), ms["median"].get<double>());
    EXPECT_LE(ms["median"].get<double>(), ms["max"].get<double>());
    EXPECT_GE(ms["spread"].get<double>(), 0.0);
    EXPECT_EQ(ms["frames"], 3);
    for (const char* k : {"setup", "binning", "raster", "shade", "readback"}) EXPECT_TRUE(ms["stages"].contains(k));
    EXPECT_EQ(r["ms_per_frame"].size(), 3u);
    EXPECT_EQ(r["nan_pixels_per_frame"], json::array({0, 0, 0}));
    EXPECT_EQ(r["nan_pixels"], 0);
    ASSERT_TRUE(r.contains("error"));
    EXPECT_EQ(r["error"]["frames"], 3);
    EXPECT_EQ(r["error"]["nan_pixels"], 0);
    EXPECT_EQ(r["error"]["pixels"], 3 * 48 * 48);
    for (const char* k : {"mean", "p99", "max", "seam_mean", "seam_p99"}) {
      EXPECT_GE(r["error"][k].get<double>(), 0.0) << k;
      EXPECT_LT(r["error"][k].get<double>(), 2.0) << k;
    }
    EXPECT_EQ(r["curve"].size(), static_cast<size_t>(kCurveSteps));
    EXPECT_EQ(r["error_per_frame"].size(), 3u);
    EXPECT_EQ(r["temporal"]["pairs"], 2);
    EXPECT_GE(r["temporal"]["mean"].get<double>(), 0.0);
    EXPECT_GT(r["texture_bytes"].get<size_t>(), 0u);
    EXPECT_EQ(r["padding_bytes"], 0);
    if (r["method"] == "traverse") {
      EXPECT_GT(r["adjacency_bytes"].get<size_t>(), 0u);
    } else {
      EXPECT_EQ(r["adjacency_bytes"], 0);
    }
  }
  // More samples, less error against the reference.
  EXPECT_LT(result(j, "discard", 4)["error"]["mean"].get<double>(), result(j, "discard", 1)["error"]["mean"].get<double>());
  // Figure 5 (left): discard vs traverse at each rate, over every frame.
  ASSERT_EQ(j["differences"].size(), 2u);
  for (const json& d : j["differences"]) {
    EXPECT_EQ(d["a"], "discard");
    EXPECT_EQ(d["b"], "traverse");
    EXPECT_EQ(d["frames"], 3);
    EXPECT_EQ(d["curve"].size(), static_cast<size_t>(kCurveSteps));
    EXPECT_GE(d["mean"].get<double>(), 0.0);
  }
}

TEST_F(Bench, ErrorsMatchCompareOnTheSameFrame) {
  ASSERT_EQ(run_->exit_code, 0) << run_->err;
  // Same cache dir, so compare reads the reference bench stored for orbit frame 1 of 3.
  const BenchProcess c = run_cli(*dir_, "compare --scene quad2 --methods discard,clamp --msaa 4 --size 48x48 --frame 1 "
                                        "--frames 3 --repeat 1 --json");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json cj = json::parse(c.out);
  EXPECT_TRUE(cj["reference"]["from_cache"].get<bool>());
  for (const json& r : cj["results"]) {
    const json& b = result(bench_json(), r["method"], r["msaa"]);
    const json& frame1 = b["error_per_frame"][1];
    EXPECT_EQ(frame1["frame"], 1);
    EXPECT_DOUBLE_EQ(frame1["mean"].get<double>(), r["error"]["mean"].get<double>()) << r["method"];
    EXPECT_DOUBLE_EQ(frame1["seam_mean"].get<double>(), r["error"]["seam_mean"].get<double>()) << r["method"];
  }
}

// --seam-mask footprint pools each rate's footprint mask, as compare measures one frame: bench's
// per-frame seam error and seam pixels then equal compare's on the same frame, while the band mask
// (the default) covers other pixels.
TEST_F(Bench, FootprintSeamMaskMatchesCompare) {
  const std::string common = "--scene quad2 --methods discard,clamp,black --msaa 1,4 --size 48x48 --frames 3";
  const BenchProcess b = run_cli(*dir_, "bench " + common + " --seam-mask footprint --json");
  ASSERT_EQ(b.exit_code, 0) << b.err;
  const json bj = json::parse(b.out);
  EXPECT_EQ(bj["seam_mask"], "footprint");
  EXPECT_EQ(bench_json()["seam_mask"], "band");
  const BenchProcess c = run_cli(*dir_, "compare " + common + " --frame 0 --repeat 1 --json");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json cj = json::parse(c.out);
  int compared = 0;
  for (const json& r : cj["results"]) {
    SCOPED_TRACE(r["method"].get<std::string>() + " x" + std::to_string(r["msaa"].get<int>()));
    const json& frame0 = result(bj, r["method"], r["msaa"])["error_per_frame"][0];
    ASSERT_EQ(frame0["frame"], 0);
    EXPECT_DOUBLE_EQ(frame0["seam_mean"].get<double>(), r["error"]["seam_mean"].get<double>());
    EXPECT_GT(r["error"]["seam_pixels"].get<size_t>(), 0u);  // frame 0 has the shared edge in view
    // seam_pixels_per_frame counts the lowest rate's mask.
    if (r["msaa"] == 1) EXPECT_EQ(bj["seam_pixels_per_frame"][0], r["error"]["seam_pixels"]);
    ++compared;
  }
  EXPECT_EQ(compared, 6);
  // Pooled over the mask's complement too (value 0: neither seam nor boundary), as compare splits it.
  for (const json& r : bj["results"]) {
    const json& e = r["error"];
    EXPECT_GT(e["off_seam_pixels"].get<size_t>(), 0u);
    EXPECT_LE(e["seam_pixels"].get<size_t>() + e["off_seam_pixels"].get<size_t>(), e["pixels"].get<size_t>());
  }
  // The controls stand apart over the footprint mask: black's seam error is far above discard's.
  EXPECT_GT(result(bj, "black", 4)["error"]["seam_mean"].get<double>(),
            2.0 * result(bj, "discard", 4)["error"]["seam_mean"].get<double>());
  // The two masks are different pixel sets (the band is 5 px wide around every face boundary).
  EXPECT_NE(bj["seam_pixels_per_frame"], bench_json()["seam_pixels_per_frame"]);

  const BenchProcess bad = run_cli(*dir_, "bench " + common + " --seam-mask halo --json");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("seam_mask: unknown mask 'halo' (known: footprint, band)"), std::string::npos) << bad.err;
  EXPECT_TRUE(bad.out.empty());
}

TEST_F(Bench, NoErrorsAndReferenceFrames) {
  const BenchProcess n = run_cli(*dir_, "bench --scene quad2 --methods discard --msaa 1 --size 48x48 --frames 3 "
                                        "--no-errors --json --no-cache");
  ASSERT_EQ(n.exit_code, 0) << n.err;
  const json nj = json::parse(n.out);
  EXPECT_EQ(nj["errors"], false);
  EXPECT_FALSE(nj.contains("reference"));
  ASSERT_EQ(nj["results"].size(), 1u);
  EXPECT_FALSE(nj["results"][0].contains("error"));
  EXPECT_EQ(nj["results"][0]["nan_pixels_per_frame"], json::array({0, 0, 0}));

  const BenchProcess k = run_cli(*dir_, "bench --scene quad2 --methods discard --msaa 1 --size 48x48 --frames 3 "
                                        "--reference-frames 2 --json");
  ASSERT_EQ(k.exit_code, 0) << k.err;
  const json kj = json::parse(k.out);
  EXPECT_EQ(kj["error_frames"], json::array({0, 2}));
  EXPECT_EQ(kj["results"][0]["error"]["frames"], 2);
  EXPECT_EQ(kj["results"][0]["ms_per_frame"].size(), 3u);
  // Not a terminal: plain progress lines on stderr, one per frame.
  EXPECT_NE(k.err.find("bench: frame 3/3"), std::string::npos) << k.err;
}

TEST_F(Bench, BadInputExits2NamingTheField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--methods discard,bogus", "methods"}, {"--methods ''", "methods"},   {"--msaa 1,3", "msaa"},
      {"--msaa 1,x", "msaa"},                 {"--frames 0", "frames"},     {"--frames abc", "frames"},
      {"--reference-frames 0", "reference"},  {"--size 0x10", "size"},      {"--guard-band 0", "guard_band"},
      {"--cube-method bogus", "cube_method"}};
  for (const auto& [flags, field] : cases) {
    const BenchProcess p = run_cli(*dir_, "bench --scene quad2 --size 32x32 --frames 2 --no-errors " + flags);
    EXPECT_EQ(p.exit_code, 2) << flags << ": " << p.err;
    EXPECT_NE(p.err.find(field), std::string::npos) << flags << ": " << p.err;
    EXPECT_TRUE(p.out.empty()) << flags;
  }
}

// compare and bench take render's frame options; these three once were render's alone.
TEST_F(Bench, CompareTakesGuardBandCubeMethodAndCentroid) {
  const BenchProcess c = run_cli(*dir_, "compare --scene quad2 --methods guardband --msaa 4 --size 32x32 --repeat 1 "
                                        "--guard-band 2 --cube-method cube-clamp --centroid --json --no-progress");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json options = json::parse(c.out).at("options");
  EXPECT_EQ(options.at("guard_band"), 2);
  EXPECT_EQ(options.at("cube_method"), "cube-clamp");
  EXPECT_EQ(options.at("shading"), "centroid");
  const BenchProcess bad = run_cli(*dir_, "compare --scene quad2 --methods guardband --size 32x32 --guard-band 17");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("guard_band"), std::string::npos) << bad.err;
}

// Every entry of `compare --json`, its timings aside, is what the library's parts give for it
// rendered and scored one by one here (Renderer, footprint_seam_mask, compare_images): compare
// prints what it computed, for every method and rate.
TEST_F(Bench, CompareJsonIsEachEntryRenderedAndScoredDirectlyButTimings) {
  const BenchProcess c = run_cli(*dir_, "compare --scene quad2 --methods discard,clamp,traverse,guardband --msaa 1,4 "
                                        "--size 64x64 --repeat 1 --json");
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const json cj = json::parse(c.out);

  json request = {{"scene", "quad2"}, {"size", "64x64"}};
  const RenderOptions frame = parse_render_options(request);
  const Scene scene = load_scene("quad2", GeneratorOptions{});
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene, frame.texels);
  ReferenceSettings settings;
  settings.cache_dir = (*dir_ / "cache").string();
  const ReferenceImage reference = reference_image(renderer, scene.camera, frame, settings);
  EXPECT_TRUE(reference.from_cache);
  const std::vector<double> xs = error_curve_thresholds();
  json direct = json::array();
  for (const std::string method : {"discard", "clamp", "traverse", "guardband"}) {
    for (int msaa : {1, 4}) {
      json r = request;
      r["method"] = method;
      r["msaa"] = msaa;
      const RenderOptions options = parse_render_options(r);
      renderer.load_scene(scene, options.texels);
      renderer.warm_up(options);
      // The seam mask is the footprint mask of the rate rendered (metrics.h), made before the
      // render as compare makes it, so that the packed scene is the method's.
      const std::vector<uint8_t> mask = footprint_seam_mask(renderer, scene.camera, options);
      const RenderResult result = renderer.render(scene.camera, options);
      const ImageErrors errors = compare_images(result.pixels, reference.pixels, &mask);
      json curve = json::array(), seam_curve = json::array();
      for (size_t i = 0; i < xs.size(); ++i) curve.push_back({xs[i], errors.all.curve[i]});
      for (size_t i = 0; i < xs.size(); ++i) seam_curve.push_back({xs[i], errors.seam.curve[i]});
      direct.push_back({{"method", method},
                        {"msaa", options.msaa},
                        {"aniso", options.aniso},
                        {"filter", to_string(options.filter)},
                        {"error",
                         {{"mean", errors.all.mean},
                          {"p99", errors.all.p99},
                          {"max", errors.all.max},
                          {"seam_mean", errors.seam.mean},
                          {"seam_p99", errors.seam.p99},
                          {"seam_max", errors.seam.max},
                          {"off_seam_mean", errors.off_seam.mean},
                          {"off_seam_p99", errors.off_seam.p99},
                          {"off_seam_max", errors.off_seam.max},
                          {"nan_pixels", errors.nan_pixels},
                          {"seam_nan_pixels", errors.seam_nan_pixels},
                          {"pixels", errors.all.pixels},
                          {"seam_pixels", errors.seam.pixels},
                          {"off_seam_pixels", errors.off_seam.pixels},
                          {"seam_coverage", errors.seam_coverage}}},
                        {"texture_bytes", renderer.packed_scene().texture_bytes()},
                        {"curve", curve},
                        {"seam_curve", seam_curve}});
    }
  }
  ASSERT_EQ(cj["results"].size(), direct.size());
  for (size_t i = 0; i < direct.size(); ++i) {
    json printed = cj["results"][i];
    ASSERT_TRUE(printed.contains("ms"));
    EXPECT_EQ(printed["ms"]["runs"], 1);
    printed.erase("ms");
    // Through text and back, as the CLI's numbers went.
    EXPECT_EQ(printed, json::parse(direct[i].dump())) << i;
  }
}

}  // namespace
