#include "request_head.h"

#include <algorithm>
#include <cctype>

namespace seamcl::server {
namespace {

// RFC 9110 5.6.2: a header name is a token.
bool is_token_char(unsigned char c) {
  if (std::isalnum(c)) return true;
  return std::string_view("!#$%&'*+-.^_`|~").find(static_cast<char>(c)) != std::string_view::npos;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool equals_ignoring_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

// A Content-Encoding value other than identity: a list of codings, any of them not "identity".
bool names_a_coding(std::string_view value) {
  for (size_t at = 0; at <= value.size();) {
    const size_t comma = std::min(value.find(',', at), value.size());
    const std::string_view coding = trim(value.substr(at, comma - at));
    if (!coding.empty() && !equals_ignoring_case(coding, "identity")) return true;
    at = comma + 1;
  }
  return false;
}

// A 400 whose message starts with its field, as every error body of the service does.
HeadRefusal bad(const std::string& field, const std::string& message) { return {400, "Bad Request", field, field + ": " + message}; }

}  // namespace

std::optional<HeadRefusal> check_request_head(std::string_view head, size_t max_body_bytes) {
  int content_lengths = 0, transfer_encodings = 0;
  std::string_view content_length, transfer_encoding;
  bool coded_body = false;
  bool first_line = true;
  for (size_t at = 0; at < head.size();) {
    const size_t newline = head.find('\n', at);
    if (newline == std::string_view::npos) return bad("headers", "the request head does not end in an empty line");
    std::string_view line = head.substr(at, newline - at);
    at = newline + 1;
    // cpp-httplib skips a line that ends in a bare LF: a proxy may not, so it is refused.
    if (line.empty() || line.back() != '\r') return bad("headers", "every line of the request head must end in CRLF");
    line.remove_suffix(1);
    if (line.find('\r') != std::string_view::npos || line.find('\0') != std::string_view::npos)
      return bad("headers", "a bare CR or a NUL byte in the request head");
    if (first_line) {
      first_line = false;
      continue;  // the request line: cpp-httplib checks its form
    }
    if (line.empty()) break;  // the end of the head
    if (line.front() == ' ' || line.front() == '\t') return bad("headers", "a folded header line (obsolete line folding is refused)");
    const size_t colon = line.find(':');
    if (colon == std::string_view::npos) return bad("headers", "a header line without a colon");
    const std::string_view name = line.substr(0, colon);
    if (name.empty() || !std::all_of(name.begin(), name.end(), [](char c) { return is_token_char(static_cast<unsigned char>(c)); }))
      return bad("headers", "a header name that is empty, holds whitespace before the colon or is not a token");
    const std::string_view value = trim(line.substr(colon + 1));
    if (equals_ignoring_case(name, "Content-Length")) {
      ++content_lengths;
      content_length = value;
    } else if (equals_ignoring_case(name, "Transfer-Encoding")) {
      ++transfer_encodings;
      transfer_encoding = value;
    } else if (equals_ignoring_case(name, "Content-Encoding")) {
      coded_body = coded_body || names_a_coding(value);
    } else if (equals_ignoring_case(name, "Range")) {
      if (value.find(',') != std::string_view::npos)
        return bad("Range", "more than one range is not served (ask for one range at a time)");
    }
  }
  if (content_lengths > 0 && transfer_encodings > 0)
    return bad("Content-Length", "must not come with Transfer-Encoding");
  if (content_lengths > 1) return bad("Content-Length", "given more than once");
  if (transfer_encodings > 1) return bad("Transfer-Encoding", "given more than once");
  if (transfer_encodings == 1 && !equals_ignoring_case(transfer_encoding, "chunked"))
    return bad("Transfer-Encoding", "must be chunked, and only chunked");
  if (content_lengths == 1) {
    if (content_length.empty() ||
        !std::all_of(content_length.begin(), content_length.end(), [](char c) { return c >= '0' && c <= '9'; }))
      return bad("Content-Length", "must be a decimal number of bytes");
    // Leading zeros aside, more digits than the limit has is over it; the rest is compared.
    const std::string_view digits = content_length.substr(std::min(content_length.find_first_not_of('0'), content_length.size()));
    bool over = digits.size() > 19;
    if (!over) {
      unsigned long long length = 0;
      for (char c : digits) length = length * 10 + static_cast<unsigned>(c - '0');
      over = length > max_body_bytes;
    }
    if (over) return HeadRefusal{413, "Payload Too Large", "body", "body: the request body exceeds this server's limit"};
  }
  // Only a body is decoded: a coding named on a request without one (no Transfer-Encoding, no
  // Content-Length or one of 0, valid by here) is ignored, as cpp-httplib ignores it.
  const bool has_body = transfer_encodings == 1 || content_length.find_first_not_of('0') != std::string_view::npos;
  if (coded_body && has_body)
    return HeadRefusal{415, "Unsupported Media Type", "Content-Encoding",
                       "Content-Encoding: the body must be sent as it is (identity), not compressed",
                       "Accept-Encoding: identity\r\n"};
  return std::nullopt;
}

}  // namespace seamcl::server
