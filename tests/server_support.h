// A live `seamcl serve` on a thread and raw sockets to it, for the service's tests.
#pragma once
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <httplib.h>

#include "http_server.h"
#include "test_support.h"

namespace seamcl_tests {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// A raw TCP connection to the server, for what httplib::Client will not send.
class RawConnection {
 public:
  // `source`: the loopback address to connect from (any of 127/8), as another client would.
  explicit RawConnection(int port, const char* source = nullptr) {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    if (source) {
      sockaddr_in local{};
      local.sin_family = AF_INET;
      ::inet_pton(AF_INET, source, &local.sin_addr);
      if (::bind(fd_, reinterpret_cast<sockaddr*>(&local), sizeof local) != 0) {
        ::close(fd_);
        fd_ = -1;
        return;
      }
    }
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(static_cast<uint16_t>(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      ::close(fd_);
      fd_ = -1;
    }
  }
  ~RawConnection() {
    if (fd_ >= 0) ::close(fd_);
  }
  RawConnection(const RawConnection&) = delete;
  RawConnection& operator=(const RawConnection&) = delete;

  bool connected() const { return fd_ >= 0; }
  // False once the server has closed the connection (or the write failed).
  bool send(const std::string& bytes) {
    size_t sent = 0;
    while (sent < bytes.size()) {
      const ssize_t n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
      if (n <= 0) return false;
      sent += static_cast<size_t>(n);
    }
    return true;
  }
  // Everything the server sends until it closes the connection or `timeout` passes.
  std::string read_until_closed(std::chrono::milliseconds timeout, bool* closed = nullptr) {
    std::string out;
    const Clock::time_point deadline = Clock::now() + timeout;
    if (closed) *closed = false;
    for (;;) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
      if (left <= 0) return out;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, static_cast<int>(left)) <= 0) return out;
      char buffer[65536];
      const ssize_t n = ::recv(fd_, buffer, sizeof buffer, 0);
      if (n <= 0) {
        if (closed) *closed = true;
        return out;
      }
      out.append(buffer, static_cast<size_t>(n));
    }
  }

 private:
  int fd_ = -1;
};

inline int count_responses(const std::string& bytes) {
  int count = 0;
  for (size_t at = bytes.find("HTTP/1.1 "); at != std::string::npos; at = bytes.find("HTTP/1.1 ", at + 1)) ++count;
  return count;
}

inline int first_status(const std::string& bytes) { return bytes.size() >= 12 ? std::atoi(bytes.c_str() + 9) : 0; }

// A server on an ephemeral loopback port, listening on its own thread, its log kept.
struct LiveServer {
  std::unique_ptr<seamcl::server::HttpServer> http;
  std::thread thread;
  std::mutex log_mutex;
  std::vector<std::string> log;

  // `tap`: also called with every log line, on the thread that logs it (after it is kept).
  explicit LiveServer(seamcl::server::ServerOptions options, bool wait_until_ready = true,
                      std::function<void(const std::string&)> tap = {}) {
    options.host = "127.0.0.1";
    options.port = 0;  // an ephemeral port: tests run side by side
    options.warm_all_methods = false;
    options.log = [this, tap = std::move(tap)](const std::string& line) {
      {
        std::lock_guard lock(log_mutex);
        log.push_back(line);
      }
      if (tap) tap(line);
    };
    http = std::make_unique<seamcl::server::HttpServer>(shared_runtime(), options);
    if (http->bind() <= 0) throw std::runtime_error("cannot bind");
    thread = std::thread([this] { http->listen_after_bind(); });
    for (int i = 0; i < 500 && !http->is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    if (wait_until_ready && !http->wait_ready(std::chrono::seconds(120))) throw std::runtime_error("not ready");
  }
  ~LiveServer() {
    http->stop();
    if (thread.joinable()) thread.join();
    // Now, while the log is alive: the server's warm-up thread may still write to it.
    http.reset();
  }
  int port() const { return http->port(); }
  std::vector<std::string> log_lines() {
    std::lock_guard lock(log_mutex);
    return log;
  }
  // GET /health on a fresh connection: status and seconds taken.
  std::pair<int, double> health() const {
    httplib::Client client("127.0.0.1", http->port());
    client.set_connection_timeout(10, 0);
    client.set_read_timeout(10, 0);
    const Clock::time_point start = Clock::now();
    const auto res = client.Get("/health");
    return {res ? res->status : 0, seconds_since(start)};
  }
};

}  // namespace seamcl_tests
