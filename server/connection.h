// The service's connection layer: cpp-httplib's request parsing and routing, under a keep-alive
// loop of our own that bounds what one client can hold.
//
// httplib 0.11's own loop gives every connection a pool thread for as long as the client keeps
// trickling bytes (its read timeout restarts with every byte), reads chunked bodies without a
// size limit, and answers a request it refused without reading its body, so the body is parsed as
// the next request. Here:
//   - every connection gets a thread of its own (threads are cheap while they wait), up to
//     max_connections; one more is answered 503 at once and closed;
//   - a request's line, headers and body must all arrive within request_read_timeout of its first
//     byte, however they trickle, and at most max_request_bytes are read for it, in any encoding;
//   - an error answer (4xx/5xx) ends the connection, so an unread body is never read as a request;
//   - a method httplib does not know is answered 405 here (httplib would say 400);
//   - the listening socket is not shared (no SO_REUSEPORT): a second server on the port fails;
//   - its backlog is listen_backlog, not httplib's compiled-in 5 (a burst of clients is held, not
//     dropped for a SYN retry a second later);
//   - one address holds at most max_connections_per_client connections; one more gets 503;
//   - every request head is checked before httplib parses it (server/request_head.h): framing
//     two parsers could read differently is refused at once, and the connection closed;
//   - the socket is closed whatever happens while serving, an exception included.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <map>
#include <mutex>
#include <string>

#include <httplib.h>

namespace seamcl::server {

struct ConnectionLimits {
  int max_connections = 256;                                // served at once; more: 503 and close
  std::chrono::milliseconds request_read_timeout{10'000};   // line + headers + body, from the first byte
  std::chrono::milliseconds idle_timeout{2'000};            // keep-alive wait for the next request
  std::chrono::milliseconds write_timeout{10'000};          // one whole response
  size_t max_request_bytes = (size_t{2} << 20) + (64 << 10);  // line + headers + body (any encoding)
  int max_requests_per_connection = 100;
  size_t max_body_bytes = size_t{1} << 20;                  // a Content-Length over it: 413 before the body is read
  int max_connections_per_client = 64;                      // open at once from one address; more: 503; 0: no cap
  int listen_backlog = 1024;                                // connections the kernel holds until accepted
};

class GuardedHttpServer : public httplib::Server {
 public:
  explicit GuardedHttpServer(ConnectionLimits limits);
  ~GuardedHttpServer() override;

  const ConnectionLimits& limits() const { return limits_; }
  // After httplib's stop(): connections end after the request they are serving (keep-alive
  // stops), and a server that has not started listening never will.
  void begin_shutdown();
  int open_connections() const { return open_connections_.load(); }
  // After a bind: the listening socket's backlog raised to limits().listen_backlog.
  void widen_backlog();
  long long connections_refused() const { return refused_.load(); }

  // On a thread that is serving a request: whether its client has hung up (for long handlers,
  // which can then stop working for nobody). False on any other thread.
  static bool client_gone();
  // On a thread that is serving a request: whether the request was cut off because it reached
  // max_request_bytes (httplib then answers 400; the error handler can say 413).
  static bool request_over_byte_limit();

 private:
  bool process_and_close_socket(socket_t sock) override;

  ConnectionLimits limits_;
  std::atomic<int> open_connections_{0};
  std::atomic<long long> refused_{0};
  std::atomic<bool> shutting_down_{false};
  std::mutex clients_mutex_;
  std::map<std::string, int> clients_;  // open connections by remote address
};

}  // namespace seamcl::server
