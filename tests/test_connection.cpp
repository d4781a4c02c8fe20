// The service's connection layer (server/connection.h) against hostile and slow clients, over
// raw loopback sockets: trickled requests, slowloris, chunked floods, request desync, the
// connection limit, a port in use, start-up state and the render deadline. Each case first
// reproduced the defect it guards (issue 9: items 3, 5, 6, 7, 8, 9).
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <thread>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "http_server.h"
#include "server_support.h"
#include "test_support.h"

using namespace seamcl;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
using seamcl_tests::LiveServer;
using seamcl_tests::RawConnection;
using seamcl_tests::seconds_since;
using seamcl_tests::count_responses;
using seamcl_tests::first_status;

namespace {

class Connection : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { std::signal(SIGPIPE, SIG_IGN); }
};

// A request that trickles one byte at a time is cut off at the read deadline, counted from its
// first byte: every byte arriving in time does not extend it.
TEST_F(Connection, TrickledRequestIsCutOffAtTheReadDeadline) {
  server::ServerOptions options;
  options.request_read_timeout_ms = 1000;
  LiveServer server(options);
  RawConnection slow(server.port());
  ASSERT_TRUE(slow.connected());
  const std::string request = "GET /health HTTP/1.1\r\nHost: x\r\nX-Padding: aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\r\n\r\n";
  const Clock::time_point start = Clock::now();
  bool closed_early = false;
  for (char c : request) {
    if (!slow.send(std::string(1, c))) {
      closed_early = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (seconds_since(start) > 4) break;
  }
  bool closed = false;
  const std::string answer = slow.read_until_closed(std::chrono::milliseconds(3000), &closed);
  EXPECT_TRUE(closed_early || closed) << "the trickling connection was still open after " << seconds_since(start) << " s";
  EXPECT_EQ(answer.find("200 OK"), std::string::npos) << "a request that took ~" << request.size() / 10.0
                                                      << " s to arrive was served: " << answer.substr(0, 200);
  EXPECT_LT(seconds_since(start), 6.0);
}

// Slowloris: many connections trickling headers do not stop the service for everyone else.
TEST_F(Connection, SlowClientsDoNotBlockOthers) {
  server::ServerOptions options;
  options.threads = 2;
  options.queue = 8;
  options.request_read_timeout_ms = 20'000;
  LiveServer server(options);
  // httplib's old pool had threads + queue + 4 = 14 threads; twice that many slow clients.
  std::vector<std::unique_ptr<RawConnection>> slow;
  for (int i = 0; i < 28; ++i) {
    slow.push_back(std::make_unique<RawConnection>(server.port()));
    ASSERT_TRUE(slow.back()->connected());
    ASSERT_TRUE(slow.back()->send("GET /health HTTP/1.1\r\nHost: x\r\n"));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  for (int round = 0; round < 5; ++round) {
    for (auto& connection : slow) connection->send("X");
    const auto [status, seconds] = server.health();
    EXPECT_EQ(status, 200);
    EXPECT_LT(seconds, 2.0) << "GET /health behind 28 slow clients";
  }
}

// The connection limit is answered at once with 503 (not after a pool thread frees up).
TEST_F(Connection, ConnectionsOverTheLimitGetAnImmediate503) {
  server::ServerOptions options;
  options.max_connections = 4;
  LiveServer server(options);
  std::vector<std::unique_ptr<RawConnection>> held;
  for (int i = 0; i < 4; ++i) {
    held.push_back(std::make_unique<RawConnection>(server.port()));
    ASSERT_TRUE(held.back()->send("GET /health HTTP/1.1\r\nHost: x\r\n"));  // unfinished: held open
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  RawConnection extra(server.port());
  ASSERT_TRUE(extra.connected());
  const Clock::time_point start = Clock::now();
  bool closed = false;
  const std::string answer = extra.read_until_closed(std::chrono::milliseconds(5000), &closed);
  EXPECT_EQ(first_status(answer), 503) << answer;
  EXPECT_NE(answer.find("Retry-After: 1"), std::string::npos) << answer;
  EXPECT_NE(answer.find("\"field\":\"connections\""), std::string::npos) << answer;
  EXPECT_TRUE(closed);
  EXPECT_LT(seconds_since(start), 2.0);
  held.clear();
  // Once the held connections are gone, service resumes.
  for (int i = 0; i < 50 && server.http->requests_served() < 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(server.health().first, 200);
}

// Request desync: a refused request's body is never read as the next request on the connection.
TEST_F(Connection, RefusedRequestsBodyIsNeverParsedAsARequest) {
  server::ServerOptions options;
  LiveServer server(options);
  const std::string smuggled = "GET /health HTTP/1.1\r\nHost: x\r\n\r\n";
  const std::string length = std::to_string(smuggled.size());
  for (const std::string& head :
       {"FROB /v1/render HTTP/1.1\r\nHost: x\r\nContent-Length: " + length + "\r\n\r\n",
        "POST /v1/render HTTP/1.1\r\nHost: x\r\nContent-Type: text/plain\r\nContent-Length: " + length + "\r\n\r\n",
        "PUT /v1/render HTTP/1.1\r\nHost: x\r\nContent-Length: " + length + "\r\n\r\n",
        "POST /no/such/path HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: " + length + "\r\n\r\n"}) {
    RawConnection connection(server.port());
    ASSERT_TRUE(connection.send(head + smuggled));
    bool closed = false;
    const std::string answer = connection.read_until_closed(std::chrono::milliseconds(5000), &closed);
    EXPECT_EQ(count_responses(answer), 1) << head << "\n---\n" << answer;
    EXPECT_GE(first_status(answer), 400) << answer;
    EXPECT_TRUE(closed) << head;
  }
  // With "Expect: 100-continue" the interim answer comes first; the refusal still ends the
  // connection, so the body is not answered as a request either.
  {
    RawConnection connection(server.port());
    // (cpp-httplib never reads a GET's body.)
    ASSERT_TRUE(connection.send("GET /v1/render?size=0x0 HTTP/1.1\r\nHost: x\r\nExpect: 100-continue\r\n"
                                "Content-Length: " + length + "\r\n\r\n" + smuggled));
    bool closed = false;
    const std::string answer = connection.read_until_closed(std::chrono::milliseconds(5000), &closed);
    EXPECT_EQ(answer.find("200 OK"), std::string::npos) << answer;
    EXPECT_NE(answer.find("HTTP/1.1 400"), std::string::npos) << answer;
    EXPECT_TRUE(closed);
  }
  // A method httplib does not know is 405 with Allow, not 400.
  RawConnection connection(server.port());
  ASSERT_TRUE(connection.send("FROB /health HTTP/1.1\r\nHost: x\r\n\r\n"));
  const std::string answer = connection.read_until_closed(std::chrono::milliseconds(5000));
  EXPECT_EQ(first_status(answer), 405) << answer;
  EXPECT_NE(answer.find("Allow: GET, POST"), std::string::npos) << answer;
  EXPECT_NE(answer.find("\"field\":\"method\""), std::string::npos) << answer;
}

// A chunked body is held to the same byte budget as a body with a Content-Length: a 64 MiB
// chunked body is cut off early, not read and parsed.
TEST_F(Connection, ChunkedBodyOverTheLimitIsCutOff) {
  server::ServerOptions options;
  LiveServer server(options);
  RawConnection connection(server.port());
  ASSERT_TRUE(connection.send(
      "POST /v1/render HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n"));
  const std::string chunk_data(64 * 1024, ' ');
  char size_line[32];
  std::snprintf(size_line, sizeof size_line, "%zx\r\n", chunk_data.size());
  const std::string chunk = std::string(size_line) + chunk_data + "\r\n";
  size_t sent = 0;
  const Clock::time_point start = Clock::now();
  for (int i = 0; i < 1024 && connection.send(chunk); ++i) sent += chunk_data.size();
  EXPECT_LT(sent, size_t{8} << 20) << "the server kept reading a chunked body past its budget";
  bool closed = false;
  const std::string answer = connection.read_until_closed(std::chrono::milliseconds(5000), &closed);
  EXPECT_TRUE(closed);
  if (!answer.empty()) {
    EXPECT_EQ(first_status(answer), 413) << answer.substr(0, 300);
    EXPECT_NE(answer.find("\"field\":\"body\""), std::string::npos) << answer.substr(0, 300);
  }
  EXPECT_LT(seconds_since(start), 20.0);
  EXPECT_EQ(server.health().first, 200);
}

// A second server on a port in use fails to bind instead of sharing it (SO_REUSEPORT).
TEST_F(Connection, PortInUseIsRefused) {
  server::ServerOptions options;
  LiveServer first(options, false);
  server::ServerOptions second_options;
  second_options.host = "127.0.0.1";
  second_options.port = first.port();
  second_options.warm_all_methods = false;
  second_options.log = [](const std::string&) {};
  server::HttpServer second(seamcl_tests::shared_runtime(), second_options);
  EXPECT_EQ(second.bind(), -1);
}

// The server answers at once, says "starting" while it warms its kernels, then "ready".
TEST_F(Connection, HealthSaysStartingThenReady) {
  server::ServerOptions options;
  LiveServer server(options, false);
  httplib::Client client("127.0.0.1", server.port());
  const auto first = client.Get("/health");
  ASSERT_TRUE(first);
  EXPECT_EQ(first->status, 200);
  const std::string first_status_text = json::parse(first->body).at("status");
  EXPECT_TRUE(first_status_text == "starting" || first_status_text == "ready") << first->body;
  ASSERT_TRUE(server.http->wait_ready(std::chrono::seconds(120)));
  const json ready = json::parse(client.Get("/health")->body);
  EXPECT_EQ(ready.at("status"), "ready");
  EXPECT_EQ(ready.at("warming").at("slots_ready"), 2);
  // A render sent right at start waits for a warm slot rather than failing.
  const auto render = client.Get("/v1/render?scene=quad2&size=32x32");
  ASSERT_TRUE(render);
  EXPECT_EQ(render->status, 200);
  bool logged_warming = false;
  for (const std::string& line : server.log_lines()) logged_warming |= line.rfind("warming: slot 1/2", 0) == 0;
  EXPECT_TRUE(logged_warming);
}

// A request that cannot get a render slot within the deadline is answered 503 "deadline".
TEST_F(Connection, RequestWaitingPastTheDeadlineGets503) {
  server::ServerOptions options;
  options.threads = 1;
  options.queue = 4;
  options.deadline_ms = 200;
  LiveServer server(options);
  // Hold the one slot with a large render on its own thread.
  std::thread big([&] {
    httplib::Client client("127.0.0.1", server.port());
    client.set_read_timeout(120, 0);
    client.Get("/v1/render?scene=paper&size=2048x2048&msaa=4&filter=ewa");
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(120, 0);
  const auto res = client.Get("/v1/render?scene=quad2&size=32x32");
  big.join();
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 503) << res->body;
  EXPECT_EQ(json::parse(res->body).at("field"), "deadline") << res->body;
  EXPECT_EQ(res->get_header_value("Retry-After"), "1");
}

}  // namespace

namespace {

// Memory budgets: a small request that asks for gigabytes (thin faces, wide guard bands, float
// texels) is refused before anything is built, naming the field that drives it.
TEST_F(Connection, RequestsOverTheMemoryBudgetAre413) {
  server::ServerOptions options;
  options.max_request_device_bytes = size_t{256} << 20;
  options.max_request_host_bytes = size_t{256} << 20;
  LiveServer server(options);
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(60, 0);
  // The issue's case: 1024 faces of 2048x1 texels, guardband 16, rgba32f (3.6 GB before).
  json faces = json::array();
  json positions = json::array();
  for (int i = 0; i < 1024; ++i) {
    const float x = static_cast<float>(i);
    positions.push_back({x, 0, 0});
    positions.push_back({x + 1, 0, 0});
    positions.push_back({x + 1, 1, 0});
    positions.push_back({x, 1, 0});
    faces.push_back({{"vertices", {4 * i, 4 * i + 1, 4 * i + 2, 4 * i + 3}}, {"texture", {{"width", 2048}, {"height", 1}}}});
  }
  const json camera = {{"eye", {512, 0.5, 900}}, {"target", {512, 0.5, 0}}};
  const json body = {{"scene", {{"name", "thin"}, {"positions", positions}, {"faces", faces}, {"camera", camera}}},
                     {"method", "guardband"}, {"guard_band", 16}, {"texels", "rgba32f"}, {"size", "64x64"}};
  const Clock::time_point start = Clock::now();
  const auto res = client.Post("/v1/render", body.dump(), "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 413) << res->body;
  const json error = json::parse(res->body);
  EXPECT_EQ(error.at("field"), "scene") << res->body;
  EXPECT_NE(error.at("error").get<std::string>().find("over this server's limit of 256.0 MiB"), std::string::npos) << res->body;
  EXPECT_LT(seconds_since(start), 10.0);
  // The same scene as rgba8 without bands fits.
  json small = body;
  small["method"] = "discard";
  small.erase("guard_band");
  small["texels"] = "rgba8";
  const auto fits = client.Post("/v1/render", small.dump(), "application/json");
  ASSERT_TRUE(fits);
  EXPECT_EQ(fits->status, 200) << fits->body.substr(0, 300);
  // A built-in scene whose frame drives the estimate names `size` while one sample per pixel, the
  // image and the tiles outweigh the samples beyond it (at 4x, 16 + 4 MiB against 12 MiB: 1x would
  // not fit either), and `msaa` once those extra samples do (16x: 60 MiB).
  server::ServerOptions tight = options;
  tight.max_request_device_bytes = size_t{8} << 20;
  LiveServer small_server(tight);
  httplib::Client small_client("127.0.0.1", small_server.port());
  for (const auto& [query, field] : {std::pair<std::string, std::string>{"size=1024x1024&msaa=1", "size"},
                                     {"size=1024x1024&msaa=4", "size"},
                                     {"size=1024x1024&msaa=16", "msaa"}}) {
    const auto big_frame = small_client.Get("/v1/render?scene=quad2&" + query);
    ASSERT_TRUE(big_frame);
    EXPECT_EQ(big_frame->status, 413) << big_frame->body;
    EXPECT_EQ(json::parse(big_frame->body).at("field"), field) << big_frame->body;
  }
  const auto big_compare = small_client.Post("/v1/compare", R"({"scene": "quad2", "size": "256x256", "msaa": [1]})", "application/json");
  ASSERT_TRUE(big_compare);
  EXPECT_EQ(big_compare->status, 413) << big_compare->body;
  EXPECT_EQ(json::parse(big_compare->body).at("field"), "size") << big_compare->body;
}

}  // namespace
