// What every answer of the service goes through, whatever the route: a client can send any bytes
// of any length (invalid UTF-8 decoded from %XX in the path or query, a header byte, a 1 MiB
// name), so an error body echoes them valid and short; bodies are JSON of a bounded depth; a
// query is read as the JSON object a body would be; a method a known path does not take is a
// 405 and an unknown path a 404, both with the JSON error body.
//
// Everything here that answers runs inside cpp-httplib's error and exception handlers too,
// where an exception terminates the process: none of it throws on the client's bytes.
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include <httplib.h>

#include <seamcl/core/input_error.h>

namespace seamcl::server {

// A refusal: status, the field at fault and a message, answered as {"error", "field"}.
struct HttpError {
  int status;
  std::string field;
  std::string message;
  int retry_after_s = 0;  // > 0: a Retry-After header (503)
};

constexpr size_t kMaxEchoChars = 100;  // one echoed value, in characters

bool is_valid_utf8(std::string_view text);
// `text` as it may appear in an error body: valid UTF-8 (each byte that starts no well-formed
// sequence becomes U+FFFD) and at most `max_chars` characters, cut on a character boundary and
// ending in an ellipsis when cut. Reads at most max_chars + 1 characters of `text`.
std::string echo(std::string_view text, size_t max_chars = kMaxEchoChars);
// Every JSON answer is dumped with this: it cannot throw (invalid UTF-8 that got past echo()
// becomes U+FFFD rather than an exception inside cpp-httplib).
std::string json_text(const nlohmann::json& value);
// {"error", "field"} with its status; the message is bounded whoever wrote it.
void send_error(httplib::Response& res, int status, std::string_view field, std::string_view message);
// An InputError's message without its "<field>: " prefix (cut short at a NUL byte a client sent).
std::string input_error_message(const InputError& e);

// The request's JSON body: 415 unless it is application/json, 400 when it is not valid JSON,
// nests deeper than `max_depth`, gives a key twice or holds a NUL byte.
nlohmann::json parse_json_body(const httplib::Request& req, int max_depth);
// A query string as the JSON object the shared parser reads: integers and true/false become
// JSON numbers and booleans, everything else stays a string (the parser then names the field
// whose type is wrong). Throws InputError for a key given twice or bytes that are not UTF-8.
nlohmann::json query_to_json(const httplib::Params& params);

// The routing table's edges, for the handlers cpp-httplib calls around routing:
// before routing, a method a known path does not take (405 with Allow), unless cpp-httplib must
// read the request's body first (then the fallback routes answer it);
httplib::Server::HandlerResponse refuse_disallowed_method(const httplib::Request& req, httplib::Response& res);
// the fallback routes, registered last: 405 on a known path, 404 elsewhere;
void answer_not_routed(const httplib::Request& req, httplib::Response& res);
// statuses cpp-httplib sets itself (404, 413, 400 for a malformed request), given the JSON body.
httplib::Server::HandlerResponse answer_httplib_error(const httplib::Request& req, httplib::Response& res);

}  // namespace seamcl::server
