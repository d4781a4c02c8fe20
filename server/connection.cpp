#include "connection.h"
#include "request_head.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <deque>
#include <optional>
#include <thread>

#include <nlohmann/json.hpp>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

namespace seamcl::server {
namespace {

using Clock = std::chrono::steady_clock;

// A thread for every task (connection) up to `max_threads`; beyond that tasks wait for one to
// finish. shutdown() waits for every task, so no thread outlives the server.
class ThreadPerConnection : public httplib::TaskQueue {
 public:
  explicit ThreadPerConnection(size_t max_threads) : max_threads_(max_threads) {}
  ~ThreadPerConnection() override { shutdown(); }

  void enqueue(std::function<void()> fn) override {
    std::lock_guard lock(mutex_);
    if (threads_ >= max_threads_) {
      waiting_.push_back(std::move(fn));
      return;
    }
    ++threads_;
    std::thread([this, first = std::move(fn)]() mutable { run(std::move(first)); }).detach();
  }

  void shutdown() override {
    std::unique_lock lock(mutex_);
    all_done_.wait(lock, [&] { return threads_ == 0 && waiting_.empty(); });
  }

 private:
  void run(std::function<void()> task) {
    for (;;) {
      try {
        task();
      } catch (...) {
        // One connection's failure (bad_alloc, say) must not end the process: it is dropped.
      }
      std::lock_guard lock(mutex_);
      if (waiting_.empty()) {
        --threads_;
        // Notified under the lock: shutdown() cannot return (and the queue be destroyed) before
        // this thread has released it, and after that it touches nothing of the queue's.
        all_done_.notify_all();
        return;
      }
      task = std::move(waiting_.front());
      waiting_.pop_front();
    }
  }

  const size_t max_threads_;
  std::mutex mutex_;
  std::condition_variable all_done_;
  size_t threads_ = 0;
  std::deque<std::function<void()>> waiting_;
};

int milliseconds_until(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<long long>(left, 0, 1 << 30));
}

// poll() for `events` until `deadline`, retrying on EINTR. >0 ready, 0 timed out, <0 error.
int poll_until(int fd, short events, Clock::time_point deadline) {
  for (;;) {
    // A deadline that has passed is a timeout, not a zero-wait poll that may still say "ready".
    if (Clock::now() >= deadline) return 0;
    pollfd p{fd, events, 0};
    const int ready = ::poll(&p, 1, milliseconds_until(deadline));
    if (ready < 0 && errno == EINTR) continue;
    if (ready > 0 && (p.revents & (POLLERR | POLLNVAL))) return -1;
    return ready;
  }
}

// The socket as httplib reads and writes it, with the deadlines and the byte budget of the
// request being served. Reads are buffered (httplib reads request lines a byte at a time).
class GuardedStream : public httplib::Stream {
 public:
  GuardedStream(int fd, const ConnectionLimits& limits) : fd_(fd), limits_(limits) {}

  // Waits for the first byte of the next request (or for buffered bytes of a pipelined one).
  bool wait_for_request(std::chrono::milliseconds timeout) {
    if (available() > 0) return true;
    return poll_until(fd_, POLLIN, Clock::now() + timeout) > 0 && fill() > 0;
  }

  void begin_request() {
    read_deadline_ = Clock::now() + limits_.request_read_timeout;
    write_deadline_ = Clock::time_point::max();
    request_bytes_ = 0;
    over_byte_limit_ = false;
    response_head_.clear();
  }

  // The request's method token, read ahead (bounded) without consuming it; empty when the line
  // does not arrive in time.
  std::string peek_method() {
    for (;;) {
      const char* begin = buffer_.data() + begin_;
      const char* end = buffer_.data() + end_;
      const char* space = std::find(begin, end, ' ');
      if (space != end || available() >= kMaxMethodBytes) {
        return std::string(begin, std::min<size_t>(static_cast<size_t>(space - begin), kMaxMethodBytes));
      }
      if (end_ == buffer_.size()) compact();
      if (fill() <= 0) return {};
    }
  }

  // The whole request head (request line to the blank line), read ahead without consuming it.
  // Empty with `too_large` false when it does not arrive in time; `too_large` when it does not
  // fit the buffer.
  std::string_view peek_head(bool& too_large) {
    too_large = false;
    for (;;) {
      const std::string_view ahead(buffer_.data() + begin_, available());
      // The head ends at its first empty line (CRLF, or a bare LF, which the check refuses).
      for (size_t newline = ahead.find('\n'); newline != std::string_view::npos; newline = ahead.find('\n', newline + 1)) {
        const std::string_view after = ahead.substr(newline + 1);
        if (after.starts_with("\n")) return ahead.substr(0, newline + 2);
        if (after.starts_with("\r\n")) return ahead.substr(0, newline + 3);
      }
      if (available() == buffer_.size()) {
        too_large = true;
        return {};
      }
      if (end_ == buffer_.size()) compact();
      if (fill() <= 0) return {};
    }
  }

  int response_status() const {
    // "HTTP/1.1 200 OK": the status is the second token of the first line written.
    if (response_head_.size() < 12) return 0;
    return std::atoi(response_head_.c_str() + 9);
  }
  bool over_byte_limit() const { return over_byte_limit_; }
  std::string_view buffered() const { return {buffer_.data() + begin_, available()}; }

  bool is_readable() const override {
    if (available() > 0) return true;
    return poll_until(fd_, POLLIN, read_deadline_) > 0;
  }
  bool is_writable() const override { return poll_until(fd_, POLLOUT, write_deadline()) > 0; }

  ssize_t read(char* ptr, size_t size) override {
    if (available() == 0) {
      compact();
      if (fill() <= 0) return -1;
    }
    const size_t n = std::min(size, available());
    std::memcpy(ptr, buffer_.data() + begin_, n);
    begin_ += n;
    return static_cast<ssize_t>(n);
  }

  ssize_t write(const char* ptr, size_t size) override {
    // A "100 Continue" goes first when the client asked for it: the status that counts is the
    // final one, written next.
    if (size >= 7 && std::memcmp(ptr, "HTTP/1.", 7) == 0 && response_status() >= 100 && response_status() < 200) {
      response_head_.clear();
    }
    if (response_head_.size() < 16) response_head_.append(ptr, std::min<size_t>(size, 16 - response_head_.size()));
    for (;;) {
      if (!is_writable()) return -1;
      // Never blocks: a client that reads slowly cannot hold the thread past the write deadline.
      const ssize_t n = ::send(fd_, ptr, size, MSG_NOSIGNAL | MSG_DONTWAIT);
      if (n < 0 && (errno == EINTR || errno == EAGAIN || errno == EWOULDBLOCK)) continue;
      return n;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { address(ip, port, true); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address(ip, port, false); }
  socket_t socket() const override { return fd_; }

  // Whether the peer has closed its side: nothing more can come and no one reads the answer.
  bool peer_closed() const {
    pollfd p{fd_, static_cast<short>(POLLIN | POLLRDHUP), 0};
    if (::poll(&p, 1, 0) <= 0) return false;
    if (p.revents & (POLLRDHUP | POLLHUP | POLLERR)) return true;
    char byte;
    return ::recv(fd_, &byte, 1, MSG_PEEK | MSG_DONTWAIT) == 0;
  }

 private:
  static constexpr size_t kMaxMethodBytes = 32;

  size_t available() const { return end_ - begin_; }

  void compact() {
    if (begin_ == 0) return;
    std::memmove(buffer_.data(), buffer_.data() + begin_, available());
    end_ -= begin_;
    begin_ = 0;
  }

  // Reads what has arrived into the buffer, waiting until the request's read deadline. Counts
  // the request's bytes; past the budget the request is cut off (a read error for httplib).
  ssize_t fill() {
    if (end_ == buffer_.size()) return -1;
    if (request_bytes_ >= limits_.max_request_bytes) {
      over_byte_limit_ = true;
      return -1;
    }
    if (poll_until(fd_, POLLIN, read_deadline_) <= 0) return -1;
    const size_t room = std::min(buffer_.size() - end_, limits_.max_request_bytes - request_bytes_);
    ssize_t n;
    do {
      n = ::recv(fd_, buffer_.data() + end_, room, 0);
    } while (n < 0 && errno == EINTR);
    if (n <= 0) return n;
    end_ += static_cast<size_t>(n);
    request_bytes_ += static_cast<size_t>(n);
    return n;
  }

  Clock::time_point write_deadline() const {
    // Set at the first write of a response: the whole answer must go out within write_timeout.
    if (write_deadline_ == Clock::time_point::max()) write_deadline_ = Clock::now() + limits_.write_timeout;
    return write_deadline_;
  }

  void address(std::string& ip, int& port, bool remote) const {
    sockaddr_storage storage{};
    socklen_t length = sizeof storage;
    auto* sa = reinterpret_cast<sockaddr*>(&storage);
    ip.clear();
    port = 0;
    if ((remote ? ::getpeername(fd_, sa, &length) : ::getsockname(fd_, sa, &length)) != 0) return;
    char text[INET6_ADDRSTRLEN] = {};
    if (storage.ss_family == AF_INET) {
      const auto* in = reinterpret_cast<const sockaddr_in*>(&storage);
      ::inet_ntop(AF_INET, &in->sin_addr, text, sizeof text);
      port = ntohs(in->sin_port);
    } else if (storage.ss_family == AF_INET6) {
      const auto* in6 = reinterpret_cast<const sockaddr_in6*>(&storage);
      ::inet_ntop(AF_INET6, &in6->sin6_addr, text, sizeof text);
      port = ntohs(in6->sin6_port);
    }
    ip = text;
  }

  int fd_;
  const ConnectionLimits& limits_;
  std::array<char, 16384> buffer_{};
  size_t begin_ = 0;
  size_t end_ = 0;
  Clock::time_point read_deadline_ = Clock::time_point::max();
  mutable Clock::time_point write_deadline_ = Clock::time_point::max();
  size_t request_bytes_ = 0;
  bool over_byte_limit_ = false;
  std::string response_head_;
};

thread_local GuardedStream* current_stream = nullptr;

// The methods httplib parses; any other is answered here.
bool httplib_knows_method(const std::string& method) {
  static const std::array<const char*, 10> known = {"GET",  "HEAD",    "POST",  "PUT",   "DELETE",
                                                    "CONNECT", "OPTIONS", "TRACE", "PATCH", "PRI"};
  return std::any_of(known.begin(), known.end(), [&](const char* m) { return method == m; });
}

void write_all(int fd, const std::string& text) {
  size_t sent = 0;
  while (sent < text.size()) {
    if (poll_until(fd, POLLOUT, Clock::now() + std::chrono::seconds(1)) <= 0) return;
    const ssize_t n = ::send(fd, text.data() + sent, text.size() - sent, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    sent += static_cast<size_t>(n);
  }
}

// A whole response written by hand, for the cases that never reach httplib.
void write_json_response(int fd, int status, const char* reason, const std::string& body, const std::string& extra_headers) {
  write_all(fd, "HTTP/1.1 " + std::to_string(status) + " " + reason + "\r\nContent-Type: application/json\r\n" +
                    extra_headers + "Content-Length: " + std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" + body);
}

// After an error answer the client may still be sending a body we did not read; closing with
// unread input would reset the connection and could destroy the answer before the client reads
// it. So: end our side, read and drop what comes for a moment (bounded), then close.
void close_socket(int fd, bool drain = false) {
  ::shutdown(fd, drain ? SHUT_WR : SHUT_RDWR);
  if (drain) {
    const Clock::time_point until = Clock::now() + std::chrono::milliseconds(200);
    char sink[16384];
    for (size_t dropped = 0; dropped < (size_t{1} << 20) && poll_until(fd, POLLIN, until) > 0;) {
      const ssize_t n = ::recv(fd, sink, sizeof sink, MSG_DONTWAIT);
      if (n <= 0) break;
      dropped += static_cast<size_t>(n);
    }
  }
  ::close(fd);
}

}  // namespace

GuardedHttpServer::GuardedHttpServer(ConnectionLimits limits) : limits_(limits) {
  const size_t max_threads = static_cast<size_t>(std::max(limits_.max_connections, 1)) + 32;
  new_task_queue = [max_threads] { return new ThreadPerConnection(max_threads); };
  set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);  // restart on a TIME_WAIT port, but never share it
  });
  set_payload_max_length(limits_.max_request_bytes);
  // Any error answer closes the connection (see process_and_close_socket): say so to the client,
  // once. cpp-httplib adds the header itself on a connection's last request and, as it writes the
  // answer, where the request asked to close; a pre-routing refusal may have added it too.
  set_post_routing_handler([](const httplib::Request& req, httplib::Response& res) {
    if (res.status >= 400 && !res.has_header("Connection") && req.get_header_value("Connection") != "close")
      res.set_header("Connection", "close");
  });
}

GuardedHttpServer::~GuardedHttpServer() = default;

void GuardedHttpServer::begin_shutdown() {
  shutting_down_.store(true);
  // Also when listening has not started yet (httplib's stop() then does nothing): the listening
  // socket is closed, so listen_after_bind() returns at once instead of serving.
  const socket_t listening = svr_sock_.exchange(INVALID_SOCKET);
  if (listening != INVALID_SOCKET) {
    ::shutdown(listening, SHUT_RDWR);
    ::close(listening);
  }
}

bool GuardedHttpServer::client_gone() { return current_stream != nullptr && current_stream->peer_closed(); }

bool GuardedHttpServer::request_over_byte_limit() { return current_stream != nullptr && current_stream->over_byte_limit(); }

void GuardedHttpServer::widen_backlog() {
  const socket_t listening = svr_sock_.load();
  // listen() again on a listening socket sets its backlog (httplib's compiled-in one is 5, which
  // drops connections under a burst; the kernel caps it at net.core.somaxconn).
  if (listening != INVALID_SOCKET) ::listen(listening, limits_.listen_backlog);
}

bool GuardedHttpServer::process_and_close_socket(socket_t sock) {
  // Whatever happens while serving (a bad_alloc while answering, say), the socket is closed and
  // the counts given back: an exception must not leave a client waiting on a leaked descriptor.
  struct Closer {
    socket_t sock;
    bool drain = false;
    ~Closer() { close_socket(sock, drain); }
  } closer{sock};
  struct OpenCount {
    std::atomic<int>& open;
    explicit OpenCount(std::atomic<int>& o) : open(o) { open.fetch_add(1); }
    ~OpenCount() { open.fetch_sub(1); }
  } counted(open_connections_);
  if (open_connections_.load() > limits_.max_connections) {
    refused_.fetch_add(1);
    write_json_response(sock, 503, "Service Unavailable",
                        R"json({"error":"connections: this server is serving its limit of open connections; retry later","field":"connections"})json",
                        "Retry-After: 1\r\n");
    return true;
  }
  // One client (one address) holds at most max_connections_per_client of them.
  std::string peer;
  int peer_port = 0;
  GuardedStream stream(sock, limits_);
  stream.get_remote_ip_and_port(peer, peer_port);
  struct ClientCount {
    GuardedHttpServer& server;
    const std::string& peer;
    int count;
    ClientCount(GuardedHttpServer& s, const std::string& p) : server(s), peer(p) {
      std::lock_guard lock(server.clients_mutex_);
      count = ++server.clients_[peer];
    }
    ~ClientCount() {
      std::lock_guard lock(server.clients_mutex_);
      if (--server.clients_[peer] == 0) server.clients_.erase(peer);
    }
  } client(*this, peer);
  if (limits_.max_connections_per_client > 0 && client.count > limits_.max_connections_per_client) {
    refused_.fetch_add(1);
    write_json_response(sock, 503, "Service Unavailable",
                        R"json({"error":"connections: this client has its limit of open connections to this server; retry later","field":"connections"})json",
                        "Retry-After: 1\r\n");
    return true;
  }

  struct CurrentStream {
    explicit CurrentStream(GuardedStream* s) { current_stream = s; }
    ~CurrentStream() { current_stream = nullptr; }
  } current(&stream);
  bool answered_error = false;
  for (int served = 0; served < limits_.max_requests_per_connection && !shutting_down_.load(); ++served) {
    if (!stream.wait_for_request(served == 0 ? limits_.request_read_timeout : limits_.idle_timeout)) break;
    stream.begin_request();
    const std::string method = stream.peek_method();
    if (method.empty()) break;
    if (!httplib_knows_method(method)) {
      answered_error = true;
      write_json_response(sock, 405, "Method Not Allowed",
                          R"json({"error":"method: not a method this server knows (allowed: GET, POST)","field":"method"})json",
                          "Allow: GET, POST\r\n");
      break;
    }
    bool too_large = false;
    const std::string_view head = stream.peek_head(too_large);
    if (too_large) {
      answered_error = true;
      const bool line_too_long = head.find('\n') == std::string_view::npos && stream.buffered().find('\n') == std::string_view::npos;
      if (line_too_long) {
        write_json_response(sock, 414, "URI Too Long",
                            R"json({"error":"path: the request line exceeds this server's limit","field":"path"})json", "");
      } else {
        write_json_response(sock, 431, "Request Header Fields Too Large",
                            R"json({"error":"headers: the request head exceeds this server's limit","field":"headers"})json", "");
      }
      break;
    }
    if (head.empty()) break;
    if (const std::optional<HeadRefusal> refusal = check_request_head(head, limits_.max_body_bytes)) {
      answered_error = true;
      write_json_response(sock, refusal->status, refusal->reason,
                          nlohmann::json{{"error", refusal->message}, {"field", refusal->field}}.dump(),
                          refusal->extra_headers);
      break;
    }
    bool connection_closed = false;
    const bool last = served + 1 == limits_.max_requests_per_connection;
    const bool ok = process_request(stream, last, connection_closed, nullptr);
    // After an error answer the request's body may be unread: never parse it as a request.
    const int status = stream.response_status();
    answered_error = status >= 400;
    if (!ok || connection_closed || status < 200 || status >= 400) break;
  }
  closer.drain = answered_error;
  return true;
}

}  // namespace seamcl::server
