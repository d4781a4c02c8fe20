// Readiness (server/http_server.cpp, GET /ready): a load balancer's health check. /health is 200
// from the moment the port listens; /ready is 503 (Retry-After, status "starting" or "failed")
// until every render slot is warm, then 200 for good. scripts/replicas points HAProxy at it.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "http_server.h"
#include "server_support.h"

using namespace seamcl;
using nlohmann::json;
using seamcl_tests::LiveServer;

namespace {

TEST(Readiness, ReadyIs503UntilEverySlotIsWarmThen200) {
  server::ServerOptions options;
  options.threads = 2;
  LiveServer server(options, false);
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(30, 0);

  // Liveness does not wait for the warm-up.
  const auto health = client.Get("/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);

  int answers = 0, not_ready = 0;
  bool seen_ready = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    const bool ready_before = server.http->ready();
    const auto res = client.Get("/ready");
    const bool ready_after = server.http->ready();
    ASSERT_TRUE(res);
    ++answers;
    const json body = json::parse(res->body);
    ASSERT_TRUE(body.contains("ready") && body.contains("status") && body.contains("warming")) << res->body;
    EXPECT_EQ(body.at("ready").get<bool>(), res->status == 200) << res->body;
    // Readiness only ever goes from false to true, so the server's own state around the request
    // decides the answer: ready before it means 200, not ready after it means 503.
    if (ready_before) EXPECT_EQ(res->status, 200) << res->body;
    if (!ready_after) EXPECT_EQ(res->status, 503) << res->body;
    if (res->status == 503) {
      EXPECT_FALSE(seen_ready) << "ready, then not ready again";
      EXPECT_EQ(res->get_header_value("Retry-After"), "1");
      const std::string status = body.at("status");
      EXPECT_TRUE(status == "starting" || status == "failed") << res->body;
      ++not_ready;
    } else {
      ASSERT_EQ(res->status, 200) << res->body;
      EXPECT_EQ(body.at("status"), "ready");
      EXPECT_EQ(body.at("warming").at("slots_ready"), 2);
      if (seen_ready) break;  // twice in a row: it stays ready
      seen_ready = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(not_ready > 0 ? 5 : 0));
  }
  EXPECT_TRUE(seen_ready) << "not ready within 120 s after " << answers << " answers";
  EXPECT_TRUE(server.http->ready());
  const auto again = client.Get("/health");
  ASSERT_TRUE(again);
  EXPECT_EQ(json::parse(again->body).at("status"), "ready");
  std::printf("readiness: %d answers, %d of them 503 while warming\n", answers, not_ready);
}

TEST(Readiness, OpenApiDocumentsBothAnswers) {
  const json doc = json::parse(server::openapi_json());
  const json& responses = doc.at("paths").at("/ready").at("get").at("responses");
  EXPECT_TRUE(responses.contains("200"));
  EXPECT_TRUE(responses.contains("503"));
  EXPECT_TRUE(responses.at("503").at("headers").contains("Retry-After"));
  const json& schema = doc.at("components").at("schemas").at("Ready");
  for (const char* key : {"ready", "status", "warming", "uptime_s"}) {
    EXPECT_TRUE(schema.at("properties").contains(key)) << key;
  }
}

}  // namespace
