// POST /v1/reference: the image compare measures against, over HTTP, byte for byte what the
// library makes (reference_image, then the same PNG encoding), and its refusals.
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <string>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include <seamcl/eval/reference.h>
#include <seamcl/io/image_io.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "server_support.h"

using namespace seamcl;
using nlohmann::json;

namespace {

TEST(ReferenceEndpoint, AnswersTheLibrarysReferenceAndRefusesWhatCompareRefuses) {
  std::signal(SIGPIPE, SIG_IGN);
  const std::string cache = (std::filesystem::temp_directory_path() / ("seamcl-test-reference-" + std::to_string(::getpid()))).string();
  server::ServerOptions options;
  options.cache_dir = cache;
  seamcl_tests::LiveServer server(options);
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(120, 0);

  const auto res = client.Post("/v1/reference", R"({"scene": "quad2", "size": "40x24", "frame": 3, "frames": 12})", "application/json");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "image/png");
  EXPECT_EQ(res->get_header_value("X-Seamcl-Reference-Method"), default_reference_method());
  const json made = json::parse(res->get_header_value("X-Seamcl-Reference"));
  EXPECT_EQ(made.at("scale"), kReferenceScale);
  EXPECT_FALSE(made.contains("cache_path"));

  // The library's reference of the same frame, encoded the same way.
  const Scene scene = generate_scene("quad2", {});
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  const RenderOptions frame = parse_render_options({{"scene", "quad2"}, {"size", "40x24"}, {"frame", 3}, {"frames", 12}});
  ReferenceSettings settings;
  settings.use_cache = false;
  const ReferenceImage reference = reference_image(renderer, orbit_camera(scene, 3, 12), frame, settings);
  EXPECT_EQ(res->body, encode_image(ImageFormat::Png, reference.width, reference.height, reference.pixels));

  // The box reference: the library's box downsample of the same 8x render, not the paper's (the
  // scene's own camera: frame 3 of 12 sees no face, and both downsamples of an empty frame agree).
  const auto box = client.Post("/v1/reference", R"({"scene": "quad2", "size": "40x24", "reference": "box"})", "application/json");
  ASSERT_TRUE(box);
  ASSERT_EQ(box->status, 200) << box->body;
  const RenderOptions own_camera = parse_render_options({{"scene", "quad2"}, {"size", "40x24"}});
  const ReferenceImage paper_reference = reference_image(renderer, scene.camera, own_camera, settings);
  settings.kind = ReferenceKind::Box;
  const ReferenceImage box_reference = reference_image(renderer, scene.camera, own_camera, settings);
  EXPECT_EQ(box->body, encode_image(ImageFormat::Png, box_reference.width, box_reference.height, box_reference.pixels));
  EXPECT_NE(box->body, encode_image(ImageFormat::Png, paper_reference.width, paper_reference.height, paper_reference.pixels));
  EXPECT_EQ(json::parse(box->get_header_value("X-Seamcl-Reference")).at("name"), "box");
  for (const char* refused : {R"("analytic")", R"("seamless")", R"("sharp")", "3"}) {
    const auto answer = client.Post("/v1/reference", std::string(R"({"scene": "quad2", "size": "40x24", "reference": )") + refused + "}",
                                    "application/json");
    ASSERT_TRUE(answer);
    EXPECT_EQ(answer->status, 400) << refused;
    EXPECT_EQ(json::parse(answer->body).at("field"), "reference") << refused << ": " << answer->body;
  }

  // Refusals name their field.
  const auto methods = client.Post("/v1/reference", R"({"scene": "quad2", "methods": "discard"})", "application/json");
  ASSERT_TRUE(methods);
  EXPECT_EQ(methods->status, 400);
  EXPECT_EQ(json::parse(methods->body).at("field"), "methods");
  const auto big = client.Post("/v1/reference", R"({"scene": "quad2", "size": "512x512"})", "application/json");
  ASSERT_TRUE(big);
  EXPECT_EQ(big->status, 413);
  EXPECT_EQ(json::parse(big->body).at("field"), "size");
  const auto get = client.Get("/v1/reference");
  ASSERT_TRUE(get);
  EXPECT_EQ(get->status, 405);
  std::error_code ec;
  std::filesystem::remove_all(cache, ec);
}

}  // namespace
