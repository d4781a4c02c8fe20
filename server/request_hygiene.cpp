#include "request_hygiene.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <map>
#include <set>
#include <stdexcept>
#include <vector>

#include <seamcl/core/json_document.h>

#include "connection.h"

namespace seamcl::server {
namespace {

using nlohmann::json;

constexpr size_t kMaxErrorChars = 300;  // a whole message: fixed text and its echoes
constexpr std::string_view kReplacementCharacter = "\xEF\xBF\xBD";  // U+FFFD
constexpr std::string_view kEllipsis = "\xE2\x80\xA6";               // U+2026

// The length of the well-formed UTF-8 sequence at text[at] (Unicode table 3-7: no overlong forms,
// no surrogates, nothing above U+10FFFF), or 0 when the byte there starts none.
size_t utf8_sequence_length(std::string_view text, size_t at) {
  const auto byte = [&](size_t k) { return static_cast<unsigned char>(text[at + k]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return 1;
  size_t length = 0;
  unsigned char second_lo = 0x80, second_hi = 0xBF;
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) second_lo = 0xA0;  // overlong
    if (lead == 0xED) second_hi = 0x9F;  // surrogates
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) second_lo = 0x90;  // overlong
    if (lead == 0xF4) second_hi = 0x8F;  // above U+10FFFF
  } else {
    return 0;  // a continuation byte, C0/C1 (overlong) or F5..FF
  }
  if (at + length > text.size()) return 0;
  for (size_t k = 1; k < length; ++k) {
    const unsigned char lo = k == 1 ? second_lo : 0x80, hi = k == 1 ? second_hi : 0xBF;
    if (byte(k) < lo || byte(k) > hi) return 0;
  }
  return length;
}

// A whole error message, whoever wrote it (the library's parsers quote the values they echo):
// every quoted run ('...' or "...") is echoed, then the message as a whole.
std::string bounded_message(std::string_view message) {
  std::string out;
  for (size_t i = 0; i < message.size();) {
    const char c = message[i];
    const size_t close = c == '\'' || c == '"' ? message.find(c, i + 1) : std::string_view::npos;
    if (close == std::string_view::npos) {
      out += c;
      ++i;
      continue;
    }
    out += c;
    out += echo(message.substr(i + 1, close - i - 1));
    out += c;
    i = close + 1;
  }
  return echo(out, kMaxErrorChars);
}

// Whether a request carries a body that cpp-httplib reads only when the request is routed: a
// refusal before routing leaves it on the connection, where it would be parsed as the next request.
bool carries_body(const httplib::Request& req) {
  return req.has_header("Transfer-Encoding") ||
         (req.has_header("Content-Length") && req.get_header_value("Content-Length") != "0");
}

// The media type of a Content-Type value: before any parameter, without surrounding spaces, in
// lower case (RFC 9110 8.3.1: type and subtype are case-insensitive).
std::string media_type(std::string_view content_type) {
  std::string_view type = content_type.substr(0, content_type.find(';'));
  while (!type.empty() && (type.front() == ' ' || type.front() == '\t')) type.remove_prefix(1);
  while (!type.empty() && (type.back() == ' ' || type.back() == '\t')) type.remove_suffix(1);
  std::string lower(type);
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

bool is_json_media_type(std::string_view content_type) { return media_type(content_type) == "application/json"; }

// The paths the server answers and the methods each allows (others: 405).
const std::map<std::string, std::vector<std::string>>& known_paths() {
  static const std::map<std::string, std::vector<std::string>> paths = {
      {"/", {"GET"}},           {"/health", {"GET"}},          {"/v1/scenes", {"GET"}}, {"/v1/assets", {"GET"}},
      {"/v1/methods", {"GET"}}, {"/v1/render", {"GET", "POST"}}, {"/v1/compare", {"POST"}}, {"/v1/inspect", {"POST"}}, {"/v1/overlays", {"POST"}}, {"/v1/reference", {"POST"}},
      {"/openapi.json", {"GET"}}, {"/ready", {"GET"}}, {"/v1/progress", {"GET"}}};
  return paths;
}

// 405 for `method` on a known path that does not route it, with the Allow header listing what does.
void send_method_not_allowed(httplib::Response& res, const std::string& method, const std::string& path,
                             const std::vector<std::string>& allowed) {
  std::string allow;
  for (const std::string& m : allowed) allow += (allow.empty() ? "" : ", ") + m;
  res.set_header("Allow", allow);
  send_error(res, 405, "method", echo(method) + " is not allowed on " + echo(path) + " (allowed: " + allow + ")");
}

}  // namespace

bool is_valid_utf8(std::string_view text) {
  for (size_t i = 0; i < text.size();) {
    const size_t length = utf8_sequence_length(text, i);
    if (length == 0) return false;
    i += length;
  }
  return true;
}

std::string echo(std::string_view text, size_t max_chars) {
  std::string out;
  size_t chars = 0;
  size_t cut = 0;  // out's size after max_chars - 1 characters: where an ellipsis goes
  for (size_t i = 0; i < text.size();) {
    if (chars == max_chars - 1) cut = out.size();
    if (chars == max_chars) {
      out.resize(cut);
      out += kEllipsis;
      return out;
    }
    const size_t length = utf8_sequence_length(text, i);
    if (length == 0) {
      out += kReplacementCharacter;
      i += 1;
    } else {
      out.append(text.substr(i, length));
      i += length;
    }
    ++chars;
  }
  return out;
}

std::string json_text(const json& value) { return value.dump(-1, ' ', false, json::error_handler_t::replace); }

void send_error(httplib::Response& res, int status, std::string_view field, std::string_view message) {
  res.status = status;
  res.set_content(json_text(json{{"error", bounded_message(message)}, {"field", echo(field)}}), "application/json");
}

std::string input_error_message(const InputError& e) {
  const std::string_view what = e.what();
  const size_t prefix = e.field().size() + 2;
  if (what.size() < prefix) return "refused (the message was cut at a NUL byte)";
  return std::string(what.substr(prefix));
}

json parse_json_body(const httplib::Request& req, int max_depth) {
  const std::string type = req.get_header_value("Content-Type");
  if (!is_json_media_type(type)) {
    throw HttpError{415, "Content-Type", "must be application/json, got '" + echo(type) + "'"};
  }
  // Parse with a depth limit (the library's error messages print values, recursively), and
  // without a key given twice or a NUL byte (either would pass unseen).
  try {
    return parse_json_document(req.body, max_depth);
  } catch (const json::exception& e) {
    // The parser's message quotes what it last read: bounded_message cuts it (send_error).
    throw HttpError{400, "body", std::string("not valid JSON: ") + e.what()};
  } catch (const std::invalid_argument& e) {
    throw HttpError{400, "body", e.what()};
  }
}

json query_to_json(const httplib::Params& params) {
  json out = json::object();
  for (const auto& [key, value] : params) {
    // %XX decodes to any byte: refused here, naming the key, before anything echoes it.
    if (!is_valid_utf8(key)) throw InputError(echo(key), "this query key is not valid UTF-8");
    if (!is_valid_utf8(value)) throw InputError(key, "not valid UTF-8: '" + echo(value) + "'");
    if (out.contains(key)) throw InputError(key, "given more than once");
    long long number = 0;
    const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), number);
    if (!value.empty() && error == std::errc() && end == value.data() + value.size()) {
      out[key] = number;
    } else if (value == "true" || value == "false") {
      out[key] = value == "true";
    } else {
      out[key] = value;
    }
  }
  return out;
}

httplib::Server::HandlerResponse refuse_disallowed_method(const httplib::Request& req, httplib::Response& res) {
  const auto found = known_paths().find(req.path);
  if (found != known_paths().end() &&
      std::find(found->second.begin(), found->second.end(), req.method) == found->second.end()) {
    // A body is read first where cpp-httplib reads bodies (POST, PUT, DELETE, PATCH): the
    // fallback routes answer after it has. It never reads one of GET, HEAD, OPTIONS, TRACE or
    // CONNECT, so there the client is told to close the connection instead.
    static const std::set<std::string> body_read = {"POST", "PUT", "DELETE", "PATCH"};
    if (carries_body(req) && body_read.contains(req.method)) return httplib::Server::HandlerResponse::Unhandled;
    if (carries_body(req)) res.set_header("Connection", "close");
    send_method_not_allowed(res, req.method, req.path, found->second);
    return httplib::Server::HandlerResponse::Handled;
  }
  return httplib::Server::HandlerResponse::Unhandled;
}

void answer_not_routed(const httplib::Request& req, httplib::Response& res) {
  const auto found = known_paths().find(req.path);
  if (found != known_paths().end()) {
    send_method_not_allowed(res, req.method, req.path, found->second);
  } else {
    send_error(res, 404, "path", "no such endpoint: " + req.method + " " + echo(req.path));
  }
}

httplib::Server::HandlerResponse answer_httplib_error(const httplib::Request& req, httplib::Response& res) {
  if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
  const auto route = known_paths().find(req.path);
  const bool routes_post = route != known_paths().end() &&
                           std::find(route->second.begin(), route->second.end(), "POST") != route->second.end();
  if (GuardedHttpServer::request_over_byte_limit()) {
    send_error(res, 413, "body", "the request exceeds this server's limit of bytes read per request");
  } else if (res.status == 404) {
    send_error(res, 404, "path", "no such endpoint: " + req.method + " " + echo(req.path));
  } else if (res.status == 400 && req.method == "POST" && routes_post && req.is_multipart_form_data()) {
    // cpp-httplib parses multipart bodies itself and answers 400 when that fails: the body is
    // of a media type these routes do not take, however well formed.
    send_error(res, 415, "Content-Type",
               "Content-Type: must be application/json, got '" + echo(req.get_header_value("Content-Type")) + "'");
  } else if (res.status == 413) {
    send_error(res, 413, "body", "the request body exceeds this server's limit");
  } else if (res.status == 400 && req.has_header("Transfer-Encoding")) {
    // The head was checked (request_head.h): the encoding is chunked, so reading its chunks failed.
    send_error(res, 400, "body",
               "the chunked body could not be read: a chunk size that is not hexadecimal, a chunk that does not "
               "end where its size says, trailer fields (not read) or a body that stopped arriving");
  } else {
    send_error(res, res.status, "request", "the request could not be handled (HTTP " + std::to_string(res.status) + ")");
  }
  return httplib::Server::HandlerResponse::Handled;
}

}  // namespace seamcl::server
