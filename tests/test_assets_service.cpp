// Assets through the front ends: the real seamcl binary on bad .obj and .ptx files (exit 2, one
// line naming the field, nothing written) and on a good pair, and `seamcl serve --assets DIR`:
// the listing, renders of assets, and every way out of DIR refused with 400 naming the field.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/io/image_io.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/options/render_options.h>
#include "server_support.h"

namespace fs = std::filesystem;
using nlohmann::json;
using seamcl_tests::LiveServer;

namespace {

std::string ptex_sample_path(const std::string& name) { return std::string(SEAMCL_TEST_ASSETS_DIR "/ptex/") + name; }

class Workspace {
 public:
  Workspace() {
    std::string pattern = (fs::temp_directory_path() / "seamcl_assets_service_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp");
    root_ = pattern;
    fs::create_directories(root_ / "assets" / "maps");
    fs::create_directories(root_ / "outside");
  }
  ~Workspace() {
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }
  fs::path path(const std::string& relative) const { return root_ / relative; }
  std::string write(const std::string& relative, const std::string& text) const {
    std::ofstream(root_ / relative, std::ios::binary) << text;
    return (root_ / relative).string();
  }

  struct Result {
    int exit_code;
    std::string err;
  };
  Result run(const std::string& args) const {
    const std::string err = (root_ / "stderr.txt").string();
    const std::string command = "cd '" + root_.string() + "' && '" + SEAMCL_BINARY + "' " + args + " >/dev/null 2>'" + err + "' </dev/null";
    const int status = std::system(command.c_str());
    std::ifstream in(err);
    std::stringstream text;
    text << in.rdbuf();
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text.str()};
  }

 private:
  fs::path root_;
};

}  // namespace

TEST(AssetsCli, BadMeshesAndPtexFilesExit2WithOneLineNamingTheField) {
  Workspace w;
  w.write("triangle.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  w.write("broken.ptx", "Ptex but not really");
  struct Case {
    std::string args, field, text;
  };
  for (const Case& c : {Case{"render --scene triangle.obj -o out.png", "scene:", "face 0 (0-based; line 4) has 3 vertices"},
                        Case{"render --scene " + ptex_sample_path("plane.obj") + " --texture broken.ptx -o out.png", "texture:", "broken.ptx"},
                        Case{"render --scene broken.ptx -o out.png", "scene:", "broken.ptx"},
                        Case{"render --scene " + ptex_sample_path("plane.obj") + " --texture " + ptex_sample_path("cube_text.ptx") + " -o out.png",
                             "texture:", "has 72 faces"},
                        Case{"compare --scene paper --texture " + ptex_sample_path("wave_lo.ptx") + " --methods discard --msaa 1", "texture:",
                             "goes with an .obj scene"},
                        Case{"bench --scene missing.obj --methods discard --msaa 1 --frames 1 --no-errors", "scene:", "no such file"}}) {
    SCOPED_TRACE(c.args);
    const Workspace::Result r = w.run(c.args);
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.field), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.text), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(w.path("out.png")));
  }
}

TEST(AssetsCli, RendersAMeshWithItsPtexAtTheAskedSize) {
  Workspace w;
  const Workspace::Result r =
      w.run("render --scene " + ptex_sample_path("plane.obj") + " --texture " + ptex_sample_path("wave_lo.ptx") + " --frame 3 --frames 8 --size 40x30 -o plane.png");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int width = 0, height = 0;
  seamcl::read_image(w.path("plane.png").string(), width, height);
  EXPECT_EQ(width, 40);
  EXPECT_EQ(height, 30);
}

TEST(AssetsService, ListsRendersAndRefusesEveryWayOutOfTheDirectory) {
  Workspace w;
  fs::copy_file(ptex_sample_path("plane.obj"), w.path("assets/plane.obj"));
  fs::copy_file(ptex_sample_path("wave_lo.ptx"), w.path("assets/maps/wave_lo.ptx"));
  w.write("outside/secret.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  fs::create_symlink(w.path("outside/secret.obj"), w.path("assets/escape.obj"));

  seamcl::server::ServerOptions options;
  options.threads = 1;
  options.assets_dir = w.path("assets").string();
  LiveServer server(options);
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(120, 0);

  const auto listing = client.Get("/v1/assets");
  ASSERT_TRUE(listing);
  ASSERT_EQ(listing->status, 200);
  const json assets = json::parse(listing->body);
  EXPECT_EQ(assets.at("enabled"), true);
  ASSERT_EQ(assets.at("assets").size(), 2u) << assets.dump();  // the symlink out is not listed
  EXPECT_EQ(assets.at("assets")[0].at("name"), "maps/wave_lo.ptx");
  EXPECT_EQ(assets.at("assets")[0].at("kind"), "ptex");
  EXPECT_EQ(assets.at("assets")[1].at("name"), "plane.obj");
  EXPECT_EQ(assets.at("assets")[1].at("bytes"), fs::file_size(ptex_sample_path("plane.obj")));

  const json render = {{"scene", "plane.obj"}, {"texture", "maps/wave_lo.ptx"}, {"size", "32x24"}, {"method", "traverse"}};
  for (int i = 0; i < 2; ++i) {
    const auto image = client.Post("/v1/render", render.dump(), "application/json");
    ASSERT_TRUE(image);
    EXPECT_EQ(image->status, 200) << image->body;
    EXPECT_EQ(image->get_header_value("Content-Type"), "image/png");
  }
  const auto get = client.Get("/v1/render?scene=plane.obj&texture=maps/wave_lo.ptx&size=16x16");
  ASSERT_TRUE(get);
  EXPECT_EQ(get->status, 200) << get->body;

  struct Refusal {
    json body;
    std::string field, text;
  };
  for (const Refusal& r : {Refusal{{{"scene", "../outside/secret.obj"}}, "scene", "'..' is not allowed"},
                           Refusal{{{"scene", w.path("outside/secret.obj").string()}}, "scene", "not an absolute path"},
                           Refusal{{{"scene", "escape.obj"}}, "scene", "leads out of the asset directory"},
                           Refusal{{{"scene", "plane.obj"}, {"texture", "maps/../../outside/x.ptx"}}, "texture", "'..'"},
                           Refusal{{{"scene", "plane.obj"}, {"texture", "nothing.ptx"}}, "texture", "no asset"},
                           Refusal{{{"scene", "paper"}, {"texture", "maps/wave_lo.ptx"}}, "texture", "goes with an .obj"}}) {
    SCOPED_TRACE(r.body.dump());
    const auto answer = client.Post("/v1/render", r.body.dump(), "application/json");
    ASSERT_TRUE(answer);
    EXPECT_EQ(answer->status, 400) << answer->body;
    const json error = json::parse(answer->body);
    EXPECT_EQ(error.at("field"), r.field);
    EXPECT_NE(error.at("error").get<std::string>().find(r.text), std::string::npos) << answer->body;
  }
  // The kinds the document lists are the library's names.
  EXPECT_EQ(json::parse(seamcl::server::openapi_json())
                .at("components").at("schemas").at("Assets").at("properties").at("assets").at("items").at("properties")
                .at("kind").at("enum"),
            json(seamcl::asset_kind_names()));
}

TEST(AssetsService, WithoutAssetsNoFileIsReachableAndAHugeAssetIsRefusedNotLoaded) {
  Workspace w;
  fs::copy_file(ptex_sample_path("plane.obj"), w.path("assets/plane.obj"));
  fs::copy_file(ptex_sample_path("wave_lo.ptx"), w.path("assets/wave_lo.ptx"));
  {
    seamcl::server::ServerOptions options;
    options.threads = 1;
    LiveServer server(options);
    httplib::Client client("127.0.0.1", server.port());
    const auto listing = client.Get("/v1/assets");
    ASSERT_TRUE(listing);
    EXPECT_EQ(json::parse(listing->body).at("enabled"), false);
    const auto answer = client.Post("/v1/render", json{{"scene", ptex_sample_path("plane.obj")}}.dump(), "application/json");
    ASSERT_TRUE(answer);
    EXPECT_EQ(answer->status, 400);
    EXPECT_EQ(json::parse(answer->body).at("field"), "scene");
  }
  // A host budget below what the texture packs to at 4 bytes a texel: refused by the reader's limit, as a 4xx.
  seamcl::server::ServerOptions options;
  options.threads = 1;
  options.assets_dir = w.path("assets").string();
  options.max_request_host_bytes = 4096;
  LiveServer server(options);
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(60, 0);
  const auto answer = client.Post("/v1/render", json{{"scene", "plane.obj"}, {"texture", "wave_lo.ptx"}}.dump(), "application/json");
  ASSERT_TRUE(answer);
  EXPECT_TRUE(answer->status == 400 || answer->status == 413) << answer->status << " " << answer->body;
  EXPECT_EQ(json::parse(answer->body).at("field"), "texture");
}

// A deferred .ptx keeps its file's bytes to make the faces from (Scene::texture_source_bytes), and
// a request's host budget counts them once (with the Renderer's copy of the scene: issue 35, they
// and the float texels no copy holds were counted twice): one byte short of the figure is a 413
// naming the budget, at exactly the figure it renders.
TEST(AssetsService, ADeferredPtexsKeptBytesCountAgainstTheHostBudget) {
  Workspace w;
  fs::copy_file(ptex_sample_path("ptex_test_object.obj"), w.path("assets/object.obj"));
  fs::copy_file(ptex_sample_path("cellnoise.ptx"), w.path("assets/cellnoise.ptx"));
  const json body = {{"scene", "object.obj"}, {"texture", "cellnoise.ptx"}, {"size", "16x16"}};

  // What the server measures a request against, from the library as the server loads the asset.
  seamcl::SceneSourceOptions source;
  source.generator.defer_textures = true;
  const seamcl::Scene scene =
      seamcl::load_scene_source(w.path("assets/object.obj").string(), w.path("assets/cellnoise.ptx").string(), source);
  const seamcl::RenderOptions options = seamcl::parse_render_options(body);
  const seamcl::SceneSizes sizes = seamcl::scene_sizes(scene);
  const seamcl::RenderMemory render = seamcl::render_memory(sizes, options);
  const size_t render_bytes = std::max(seamcl::scene_render_memory(sizes, options).host_bytes(), render.host_bytes());
  const size_t kept = scene.texture_source_bytes;
  ASSERT_EQ(kept, fs::file_size(ptex_sample_path("cellnoise.ptx")));
  ASSERT_EQ(render.host_scene, seamcl::scene_host_bytes(sizes) + kept);  // the file, with the Renderer's copy
  const size_t held = seamcl::scene_host_bytes(sizes);  // the request's own copy: records, no texels
  ASSERT_LT(render_bytes + held, scene.texel_count() * sizeof(glm::vec4)) << "a float copy of the texels is counted";
  ASSERT_LE(scene.texel_count() * sizeof(uint32_t), render_bytes) << "the reader's own limit must not refuse it first";

  // One byte short of the figure, then the figure.
  for (const size_t budget : {render_bytes + held - 1, render_bytes + held}) {
    SCOPED_TRACE(budget);
    seamcl::server::ServerOptions server_options;
    server_options.threads = 1;
    server_options.assets_dir = w.path("assets").string();
    server_options.max_request_host_bytes = budget;
    LiveServer server(server_options);
    httplib::Client client("127.0.0.1", server.port());
    client.set_read_timeout(120, 0);
    const auto answer = client.Post("/v1/render", body.dump(), "application/json");
    ASSERT_TRUE(answer);
    if (budget < render_bytes + held) {
      ASSERT_EQ(answer->status, 413) << answer->body;
      const json error = json::parse(answer->body);
      EXPECT_EQ(error.at("field"), "scene");
      EXPECT_NE(error.at("error").get<std::string>().find("of host memory, over this server's limit of"), std::string::npos)
          << answer->body;
    } else {
      EXPECT_EQ(answer->status, 200) << answer->body;
    }
  }
}

// The displacement map of a render over HTTP: an asset of the server's directory, resolved and
// refused like the texture (every refusal a 400 naming displacement_map), and part of the asset
// cache's key (two maps on the same mesh are two scenes, not one served twice).
TEST(AssetsService, DisplacementMapIsAnAssetNamedByItsField) {
  Workspace w;
  fs::copy_file(ptex_sample_path("plane.obj"), w.path("assets/plane.obj"));
  fs::copy_file(ptex_sample_path("rand_lo.ptx"), w.path("assets/maps/rand_lo.ptx"));
  fs::copy_file(ptex_sample_path("wave_lo.ptx"), w.path("assets/maps/wave_lo.ptx"));
  fs::copy_file(ptex_sample_path("cellnoise.ptx"), w.path("assets/cellnoise.ptx"));
  fs::copy_file(ptex_sample_path("rand_lo.ptx"), w.path("outside/secret.ptx"));
  fs::create_symlink(w.path("outside/secret.ptx"), w.path("assets/escape.ptx"));

  seamcl::server::ServerOptions options;
  options.threads = 1;
  options.assets_dir = w.path("assets").string();
  LiveServer server(options);
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(120, 0);

  const json base = {{"scene", "plane.obj"}, {"displacement_method", "fixed"}, {"tessellation", 4}, {"size", "48x36"}};
  auto render = [&](const std::string& map) {
    json body = base;
    body["displacement_map"] = map;
    const auto answer = client.Post("/v1/render", body.dump(), "application/json");
    EXPECT_TRUE(answer);
    if (!answer) return std::string();
    EXPECT_EQ(answer->status, 200) << answer->body;
    EXPECT_EQ(answer->get_header_value("Content-Type"), "image/png");
    return answer->body;
  };
  const std::string rand_lo = render("maps/rand_lo.ptx");
  const std::string wave_lo = render("maps/wave_lo.ptx");
  EXPECT_NE(rand_lo, wave_lo) << "each map displaces the mesh its own way";
  EXPECT_EQ(render("maps/rand_lo.ptx"), rand_lo) << "the same map again: the same image";
  const auto get =
      client.Get("/v1/render?scene=plane.obj&displacement_method=zipper&tessellation=3&size=16x16&displacement_map=maps/wave_lo.ptx");
  ASSERT_TRUE(get);
  EXPECT_EQ(get->status, 200) << get->body;

  struct Refusal {
    json body;
    std::string field, text;
  };
  auto with = [&](json extra) {
    json body = base;
    for (const auto& [key, value] : extra.items()) body[key] = value;
    return body;
  };
  for (const Refusal& r : {
           Refusal{with({{"displacement_map", "maps/../../outside/secret.ptx"}}), "displacement_map", "'..'"},
           Refusal{with({{"displacement_map", w.path("outside/secret.ptx").string()}}), "displacement_map", "absolute"},
           Refusal{with({{"displacement_map", "escape.ptx"}}), "displacement_map", "leads out of the asset directory"},
           Refusal{with({{"displacement_map", "nothing.ptx"}}), "displacement_map", "no asset"},
           Refusal{with({{"displacement_map", "cellnoise.ptx"}}), "displacement_map", "channel"},
           Refusal{with({{"displacement_map", ""}}), "displacement_map", ""},
           Refusal{with({{"displacement_map", 7}}), "displacement_map", ""},
           Refusal{with({{"scene", "displaced"}, {"displacement_map", "maps/rand_lo.ptx"}}), "displacement_map",
                   "goes with a scene of the asset directory"},
           Refusal{{{"scene", "plane.obj"}, {"displacement_map", "maps/rand_lo.ptx"}}, "displacement_map",
                   "displacement_method"},
       }) {
    SCOPED_TRACE(r.body.dump());
    const auto answer = client.Post("/v1/render", r.body.dump(), "application/json");
    ASSERT_TRUE(answer);
    EXPECT_GE(answer->status, 400) << answer->body;
    EXPECT_LT(answer->status, 500) << answer->body;
    const json error = json::parse(answer->body);
    EXPECT_EQ(error.at("field"), r.field);
    EXPECT_NE(error.at("error").get<std::string>().find(r.text), std::string::npos) << answer->body;
  }
  // The OpenAPI document derives the field from the option table.
  const json doc = json::parse(seamcl::server::openapi_json());
  EXPECT_NE(doc.dump().find("displacement_map"), std::string::npos);

  // Without an asset directory no map is reachable.
  seamcl::server::ServerOptions bare;
  bare.threads = 1;
  LiveServer plain(bare);
  httplib::Client plain_client("127.0.0.1", plain.port());
  const auto answer = plain_client.Post(
      "/v1/render", json{{"scene", "displaced"}, {"displacement_method", "fixed"}, {"displacement_map", "rand_lo.ptx"}}.dump(),
      "application/json");
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->status, 400) << answer->body;
  EXPECT_EQ(json::parse(answer->body).at("field"), "displacement_map");
}
