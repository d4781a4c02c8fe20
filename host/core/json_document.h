// User-supplied JSON text (scene files, HTTP bodies, bench parts), parsed by nlohmann::json with
// what that parser lets through silently refused: a key given twice in one object (the last value
// would win, unseen) and a NUL byte (the parser stops reading there, so whatever follows would be
// ignored).
#pragma once
#include <string_view>

#include <nlohmann/json.hpp>

namespace seamcl {

// Throws nlohmann::json::exception on a syntax error (as nlohmann::json::parse does), and
// std::invalid_argument naming a repeated key, or the
// offset of a NUL byte. max_depth > 0: deeper nesting throws std::invalid_argument too (the
// parser's own messages print values recursively).
nlohmann::json parse_json_document(std::string_view text, int max_depth = 0);

}  // namespace seamcl
