// Displacement seen the honest way: crack pixels on a closed mesh whose inside is a flag, over an
// orbit; the real Ptex displacement maps on plane.obj; the CLI, HTTP schema and error paths.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "http_server.h"
#include "server_support.h"
#include "pipeline/displacement_packing.h"
#include "pipeline/stages/tessellate_launcher.h"
#include "scene/displacement_map.h"
#include "test_support.h"

namespace {

using namespace seamcl;
using seamcl_tests::shared_runtime;
namespace fs = std::filesystem;

const std::string kAssets = std::string(SEAMCL_TEST_ASSETS_DIR) + "/ptex/";

RenderOptions small_options(DisplacementMethod method, int t) {
  RenderOptions o;
  o.width = 96;
  o.height = 96;
  o.msaa = 1;
  o.displacement = method;
  o.tessellation = t;
  return o;
}

TEST(DisplacementCracks, FlagShowsOnlyThroughCracksOverASixtyFrameOrbit) {
  const Scene scene = generate_scene("displaced", {});
  for (int t : {3, 8}) {
    for (DisplacementMethod method : {DisplacementMethod::Zipper, DisplacementMethod::Ownership, DisplacementMethod::Fixed}) {
      const DisplacementReport r = measure_displacement(shared_runtime(), scene, scene.camera, small_options(method, t), 60, 0);
      ASSERT_TRUE(r.crack_pixels.has_value());
      EXPECT_EQ(r.crack_frames, 60);
      EXPECT_EQ(*r.crack_pixels, 0u) << to_string(method) << " T=" << t;
    }
    const DisplacementReport naive =
        measure_displacement(shared_runtime(), scene, scene.camera, small_options(DisplacementMethod::Naive, t), 60, 0);
    ASSERT_TRUE(naive.crack_pixels.has_value());
    EXPECT_GT(*naive.crack_pixels, 0u) << "naive, T=" << t;
  }
}

TEST(DisplacementCracks, BackFacesAreTheFlagHiddenByAClosedSurfaceAndSeenWithoutIt) {
  // The flag test can fail both ways: with the front faces gone every covered pixel is flag; with
  // them in place on a watertight surface (fixed, no displacement: the base points alone) none is,
  // and the image covers exactly the pixels the front faces alone cover.
  const Scene scene = generate_scene("displaced", {});
  RenderOptions options = small_options(DisplacementMethod::Fixed, 4);
  Scene flat = scene;
  auto zero = std::make_shared<Displacement>(*scene.displacement);
  zero->scale = 0.0f;
  flat.displacement = zero;
  const Scene flagged = with_back_faces_flagged(flat, tessellate_displacement(shared_runtime(), flat, options), 4);
  const size_t surface_faces = scene.faces.size() * 4 * 4;
  ASSERT_EQ(flagged.faces.size(), 2 * surface_faces);
  const RenderOptions crack_options = crack_render_options(options);
  EXPECT_FALSE(crack_options.displacement.has_value());
  auto covered_pixels = [](const std::vector<uint32_t>& winners) {
    return count_flag_pixels(winners, 96, 96, 1, 0);  // every face counts
  };
  Renderer renderer(shared_runtime());
  renderer.load_scene(flagged);
  renderer.render(scene.camera, crack_options);
  const std::vector<uint32_t> both = renderer.read_sample_triangles();
  EXPECT_EQ(count_flag_pixels(both, 96, 96, 1, surface_faces), 0u);
  Scene front = flagged, back = flagged;
  front.faces.resize(surface_faces);
  back.faces.erase(back.faces.begin(), back.faces.begin() + static_cast<std::ptrdiff_t>(surface_faces));
  renderer.load_scene(front);
  renderer.render(scene.camera, crack_options);
  EXPECT_EQ(covered_pixels(renderer.read_sample_triangles()), covered_pixels(both));
  renderer.load_scene(back);
  renderer.render(scene.camera, crack_options);
  const size_t inside = covered_pixels(renderer.read_sample_triangles());
  EXPECT_GT(inside, 1000u);
  EXPECT_EQ(inside, covered_pixels(both)) << "the back faces alone cover the same silhouette";
  // The coverage balance: with the front faces gone every back face is open, every pixel a crack.
  EXPECT_EQ(count_crack_pixels(back, renderer.last_frame_params(), renderer.read_sample_triangles(), 0), inside);
  renderer.load_scene(flagged);
  renderer.render(scene.camera, crack_options);
  EXPECT_EQ(count_crack_pixels(flagged, renderer.last_frame_params(), renderer.read_sample_triangles(), surface_faces), 0u);
  EXPECT_FALSE(is_closed_mesh(generate_scene("quad2", {})));
  EXPECT_TRUE(is_closed_mesh(scene));
  // An orbit to count over is needed.
  Scene still = scene;
  still.orbit.reset();
  EXPECT_THROW(
      {
        try {
          measure_displacement(shared_runtime(), still, still.camera, options, 3, 0);
        } catch (const InputError& e) {
          EXPECT_EQ(e.field(), "crack_orbit");
          throw;
        }
      },
      InputError);
}

TEST(DisplacementPtex, RealMapsOnPlaneObj) {
  for (const char* file : {"rand_lo.ptx", "wave_lo.ptx"}) {
    Scene scene = load_scene_source(kAssets + "plane.obj");
    attach_ptex_displacement(scene, kAssets + file);
    ASSERT_TRUE(scene.displacement);
    ASSERT_EQ(scene.displacement->maps.size(), scene.faces.size());
    std::set<int> sides;
    for (const DisplacementMap& m : scene.displacement->maps) sides.insert(m.columns);
    EXPECT_GE(sides.size(), 2u) << "mixed face sizes";
    for (int t : {1, 4, 7, 16}) {
      for (DisplacementMethod method : {DisplacementMethod::Naive, DisplacementMethod::Zipper,
                                        DisplacementMethod::Ownership, DisplacementMethod::Fixed}) {
        const DisplacementReport r = measure_displacement(shared_runtime(), scene, scene.camera, small_options(method, t), 0, 0);
        EXPECT_FALSE(r.crack_pixels.has_value()) << "plane.obj is open";
        if (method == DisplacementMethod::Naive) {
          if (t > 1) EXPECT_GT(r.gap.max_gap, 0.0) << file << " T=" << t;
        } else {
          EXPECT_EQ(r.gap.max_gap, 0.0) << file << " " << to_string(method) << " T=" << t;
          EXPECT_EQ(r.gap.differing_pairs, 0u);
        }
        if (method == DisplacementMethod::Fixed) EXPECT_EQ(r.unmatched_edges, 0u);
      }
    }
  }
}

TEST(DisplacementPtex, RefusesFilesThatAreNotOneChannelMapsOfThisMesh) {
  auto field_of = [](const std::function<void()>& f, std::string* message = nullptr) -> std::string {
    try {
      f();
    } catch (const InputError& e) {
      if (message) *message = e.what();
      return e.field();
    }
    return "(none)";
  };
  Scene plane = load_scene_source(kAssets + "plane.obj");
  std::string message;
  EXPECT_EQ(field_of([&] { attach_ptex_displacement(plane, kAssets + "cellnoise.ptx"); }, &message), "displacement_map");
  EXPECT_NE(message.find("cellnoise.ptx"), std::string::npos) << message;
  Scene cube = load_scene_source(kAssets + "cube.obj");
  EXPECT_EQ(field_of([&] { attach_ptex_displacement(cube, kAssets + "rand_lo.ptx"); }, &message), "displacement_map");
  EXPECT_NE(message.find("faces"), std::string::npos) << message;
  EXPECT_EQ(field_of([&] { attach_ptex_displacement(plane, kAssets + "no_such_file.ptx"); }, &message), "displacement_map");
  EXPECT_EQ(message.find("texture"), std::string::npos) << "one field name, this one: " << message;
  // A truncated file.
  const fs::path cut = fs::temp_directory_path() / "seamcl_disp_truncated.ptx";
  {
    std::ifstream in(kAssets + "rand_lo.ptx", std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  }
  EXPECT_EQ(field_of([&] { attach_ptex_displacement(plane, cut.string()); }), "displacement_map");
  fs::remove(cut);
  EXPECT_FALSE(plane.displacement) << "a refused file changes nothing";
}

TEST(DisplacementService, OpenApiListsTheMethodsTheParserTakes) {
  const nlohmann::json doc = nlohmann::json::parse(server::openapi_json());
  const auto& body = doc.at("components").at("schemas").at("RenderRequest").at("properties");
  EXPECT_EQ(body.at("displacement_method").at("enum").get<std::vector<std::string>>(), displacement_method_names());
  EXPECT_EQ(body.at("tessellation").at("maximum"), SEAMCL_MAX_TESSELLATION);
  EXPECT_EQ(body.at("tessellation").at("default"), RenderOptions{}.tessellation);
  bool in_query = false;
  for (const auto& p : doc.at("paths").at("/v1/render").at("get").at("parameters")) {
    if (p.at("name") == "displacement_method") {
      in_query = true;
      EXPECT_EQ(p.at("schema").at("enum").get<std::vector<std::string>>(), displacement_method_names());
    }
  }
  EXPECT_TRUE(in_query);
}

TEST(DisplacementService, RendersOverHttpAndRefusesBadFields) {
  seamcl::server::ServerOptions server_options;
  seamcl_tests::LiveServer server(server_options);
  httplib::Client c("127.0.0.1", server.port());
  c.set_read_timeout(120, 0);
  const nlohmann::json body = {{"scene", "displaced"}, {"size", "48x48"}, {"displacement_method", "ownership"}, {"tessellation", 5}};
  auto ok = c.Post("/v1/render", body.dump(), "application/json");
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->status, 200) << ok->body;
  EXPECT_EQ(ok->get_header_value("Content-Type"), "image/png");
  auto get = c.Get("/v1/render?scene=displaced&size=48x48&displacement_method=ownership&tessellation=5");
  ASSERT_TRUE(get);
  EXPECT_EQ(get->status, 200);
  EXPECT_EQ(get->body, ok->body);
  for (const auto& [bad, field] : std::vector<std::pair<nlohmann::json, std::string>>{
           {{{"scene", "displaced"}, {"displacement_method", "wobbly"}}, "displacement_method"},
           {{{"scene", "displaced"}, {"displacement_method", "zipper"}, {"tessellation", 99}}, "tessellation"},
           {{{"scene", "paper"}, {"displacement_method", "zipper"}}, "displacement"}}) {
    auto res = c.Post("/v1/render", bad.dump(), "application/json");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 400) << bad.dump();
    EXPECT_EQ(nlohmann::json::parse(res->body).value("field", ""), field) << res->body;
  }
}

struct CliRun {
  int code = -1;
  std::string out, err;
};

CliRun run_cli(const std::string& args) {
  // Per process and call: CTest runs the tests of this file in parallel processes.
  static int calls = 0;
  const fs::path dir = fs::temp_directory_path();
  const std::string stem = "seamcl_disp_" + std::to_string(::getpid()) + "_" + std::to_string(++calls);
  const std::string out = (dir / (stem + "_out.txt")).string(), err = (dir / (stem + "_err.txt")).string();
  const int status = std::system((std::string(SEAMCL_BINARY) + " " + args + " >" + out + " 2>" + err + " </dev/null").c_str());
  CliRun r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const std::string& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  r.out = slurp(out);
  r.err = slurp(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

TEST(DisplacementCli, RenderJsonReportsTheGapAndCracks) {
  const CliRun ok = run_cli("render --scene displaced --displacement-method zipper --tessellation 7 --size 64x64 --json");
  ASSERT_EQ(ok.code, 0) << ok.err;
  const nlohmann::json j = nlohmann::json::parse(ok.out);
  const auto& d = j.at("displacement");
  EXPECT_EQ(d.at("method"), "zipper");
  EXPECT_EQ(d.at("tessellation"), 7);
  EXPECT_EQ(d.at("max_gap"), 0.0);
  EXPECT_EQ(d.at("crack_pixels"), 0);
  EXPECT_GT(d.at("samples").get<size_t>(), d.at("vertices").get<size_t>()) << "zipper samples twice on edges";
  EXPECT_GT(d.at("frame_ms").get<double>(), 0.0);
  EXPECT_EQ(j.at("options").at("displacement_method"), "zipper");

  const CliRun naive = run_cli("render --scene displaced --displacement-method naive --tessellation 7 --size 64x64 --json");
  ASSERT_EQ(naive.code, 0) << naive.err;
  EXPECT_GT(nlohmann::json::parse(naive.out).at("displacement").at("max_gap").get<double>(), 0.0);

  const CliRun plain = run_cli("render --scene displaced --size 32x32 --json");
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_FALSE(nlohmann::json::parse(plain.out).contains("displacement"));
}

TEST(DisplacementCli, BadInputExitsTwoNamingTheField) {
  struct Case {
    std::string args, field;
  };
  for (const Case& c : std::vector<Case>{
           {"--scene displaced --displacement-method wobbly", "displacement_method"},
           {"--scene displaced --displacement-method fixed --tessellation 0", "tessellation"},
           {"--scene displaced --displacement-method fixed --tessellation 65", "tessellation"},
           {"--scene displaced --displacement-method fixed --displacement-level 17", "displacement_level"},
           {"--scene displaced --displacement-method fixed --crack-orbit -1", "crack_orbit"},
           {"--scene cube --displacement-method fixed", "displacement"},
           {"--scene " + kAssets + "plane.obj --displacement-map " + kAssets + "cellnoise.ptx --displacement-method fixed",
            "displacement_map"},
       }) {
    const CliRun r = run_cli("render " + c.args + " --size 16x16");
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.find(c.field + ":") != std::string::npos, true) << c.args << "\n" << r.err;
  }
}

// seamcl displacement-metrics: every method at every T in one JSON; the watertight methods must
// measure exactly 0 and the others not, so the command cannot pass by reporting zeros.
TEST(DisplacementMetricsCli, EveryMethodAndLevelInOneJson) {
  const CliRun r = run_cli(
      "displacement-metrics --size 48x54 --msaa 1 --frames 3 --tessellation 2,5 --repeat 1 --no-progress --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("scene"), "displaced");
  EXPECT_EQ(j.at("crack_frames"), 3);
  EXPECT_TRUE(j.at("closed_mesh").get<bool>());
  const auto& results = j.at("results");
  ASSERT_EQ(results.size(), 2u * seamcl::displacement_method_names().size());
  std::set<std::pair<std::string, int>> seen;
  for (const auto& e : results) {
    const std::string method = e.at("method");
    const int t = e.at("tessellation");
    seen.insert({method, t});
    EXPECT_EQ(e.at("crack_frames"), 3) << method;
    EXPECT_GT(e.at("frame_ms").get<double>(), 0.0) << method;
    EXPECT_EQ(e.at("vertices").get<size_t>(), 24u * static_cast<size_t>((t + 1) * (t + 1))) << method << " T " << t;
    const bool watertight = method == "zipper" || method == "ownership" || method == "fixed";
    if (watertight) {
      EXPECT_EQ(e.at("max_gap").get<double>(), 0.0) << method << " T " << t;
      EXPECT_EQ(e.at("differing_pairs").get<size_t>(), 0u) << method << " T " << t;
      EXPECT_EQ(e.at("crack_pixels").get<size_t>(), 0u) << method << " T " << t;
    } else {
      EXPECT_GT(e.at("max_gap").get<double>(), 0.0) << method << " T " << t;
    }
  }
  EXPECT_EQ(seen.size(), results.size()) << "each (method, T) once";
}

TEST(DisplacementMetricsCli, BadInputExitsTwoNamingTheField) {
  struct Case {
    std::string args, field;
  };
  for (const Case& c : std::vector<Case>{
           {"--methods naive,wobbly", "methods"},
           {"--tessellation 4,0", "tessellation"},
           {"--tessellation 65", "tessellation"},
           {"--tessellation four", "tessellation"},
           {"--level 17", "level"},
           {"--frames -1", "frames"},
           {"--repeat 0", "repeat"},
           {"--scene paper", "scene"},
           {"--size 0x4", "size"},
       }) {
    // The case's option, then small defaults for the others (so a check that failed to refuse
    // still ends quickly).
    std::string command = "displacement-metrics --no-progress " + c.args;
    for (const std::string& option : {"--size 16x16", "--frames 1", "--repeat 1"}) {
      if (c.args.find(option.substr(0, option.find(' ') + 1)) == std::string::npos) command += " " + option;
    }
    const CliRun r = run_cli(command);
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.field + ":"), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << c.args << ": nothing measured before the check";
  }
}

// The micro-triangle bound (patches * 2 * T^2) of every level, checked by displacement-metrics
// before its first render (no asset has enough patches for T <= 64 to cross it, so the check is
// held here on a scene's face count: paper's 2474 faces).
TEST(DisplacementMetricsCli, TriangleBoundOfEveryLevelCheckedUpFront) {
  const seamcl::Scene paper = seamcl::generate_scene("paper", {});
  ASSERT_EQ(paper.faces.size(), 2474u);
  EXPECT_NO_THROW(seamcl::check_tessellation_levels(paper, {1, 4, 16}));  // 2474 * 2 * 256 = 1,266,688
  try {
    seamcl::check_tessellation_levels(paper, {1, 4, 32});
    FAIL() << "T = 32 on 2474 patches is over the bound";
  } catch (const seamcl::InputError& e) {
    EXPECT_EQ(e.field(), "tessellation");
    EXPECT_NE(std::string(e.what()).find("2474 patches at T = 32 make 5066752 triangles, over the limit of " +
                                         std::to_string(seamcl::kMaxTessellatedTriangles)),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(seamcl::check_tessellation_levels(paper, {0}), seamcl::InputError);
  EXPECT_THROW(seamcl::check_tessellation_levels(paper, {65}), seamcl::InputError);
}

// compare takes the displacement options (their names as render's) and reports the displaced
// frame's gap and cracks beside the seam methods' errors.
TEST(DisplacementCompareCli, CompareMeasuresTheDisplacedFrame) {
  const CliRun r = run_cli(
      "compare --scene displaced --displacement-method fixed --tessellation 3 --methods discard --msaa 1 --size 32x36 "
      "--repeat 1 --no-cache --no-progress --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("options").at("displacement_method"), "fixed");
  EXPECT_EQ(j.at("options").at("tessellation"), 3);
  const auto& d = j.at("displacement");
  EXPECT_EQ(d.at("method"), "fixed");
  EXPECT_EQ(d.at("max_gap").get<double>(), 0.0);
  EXPECT_EQ(d.at("crack_pixels").get<size_t>(), 0u);

  const CliRun bad = run_cli("compare --scene displaced --displacement-method wobbly --size 16x16 --no-progress");
  EXPECT_EQ(bad.code, 2) << bad.err;
  EXPECT_NE(bad.err.find("displacement_method:"), std::string::npos) << bad.err;
}

}  // namespace
