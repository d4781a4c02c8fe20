// The framing of a request head, checked before cpp-httplib parses it. cpp-httplib 0.11 (built
// as a shared library, so not configurable here) is lenient where a proxy in front may not be:
// it takes the first of two Content-Length headers, keeps a connection that sent Content-Length
// with chunked, accepts header lines without a colon and folded lines, waits for the body of a
// Content-Length it cannot parse and answers a Range of thousands of parts with one multipart
// body each. A request that two parsers could frame differently is a smuggling vector, so here
// it is refused at once (and its connection closed) instead:
//   - a header line that is folded (starts with a space or tab), has no colon, has an empty or
//     invalid name, whitespace before the colon, or a bare CR or NUL byte: 400 "headers";
//   - Content-Length that is not 1*DIGIT, given twice (even with the same value) or together
//     with Transfer-Encoding: 400 "Content-Length"; one over the body limit: 413 "body";
//   - Transfer-Encoding other than exactly one "chunked": 400 "Transfer-Encoding";
//   - a body with a Content-Encoding other than identity (a list of codings, any of them not
//     identity): 415 "Content-Encoding", with Accept-Encoding: identity (cpp-httplib, built
//     without zlib here, would answer a compressed body with a 400 that names nothing);
//   - a Range with more than one range: 400 "Range" (one range of a generated answer is cheap,
//     thousands are an amplification);
//   - a head that does not fit the read buffer: 431 "headers".
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace seamcl::server {

struct HeadRefusal {
  int status;
  const char* reason;   // the status line's reason phrase
  std::string field;    // the header (or "headers", "body") at fault
  std::string message;  // fixed text: nothing the client sent is echoed
  std::string extra_headers = "";  // whole header lines, each ending in CRLF
};

// `head`: the request line and header lines, up to and including the blank line.
std::optional<HeadRefusal> check_request_head(std::string_view head, size_t max_body_bytes);

}  // namespace seamcl::server
