// User-supplied JSON text (scene files, HTTP bodies, bench parts), parsed by nlohmann::json with
// what that parser lets through silently refused: a key given twice in one object (the last value
// would win, unseen) and a NUL byte (the parser stops reading there, so whatever follows would be
// ignored).
#pragma once
#include <cstddef>
#include <functional>
#include <string_view>

#include <nlohmann/json.hpp>

namespace seamcl {

// Throws nlohmann::json::exception on a syntax error (as nlohmann::json::parse does), and
// std::invalid_argument naming a repeated key, or the
// offset of a NUL byte. max_depth > 0: deeper nesting throws std::invalid_argument too (the
// parser's own messages print values recursively).
nlohmann::json parse_json_document(std::string_view text, int max_depth = 0);

// A document whose root is an array, read element by element: each element is handed to `element`
// as soon as it is read, and dropped, so that one element is held at a time however long the
// array. False, with nothing handed over, when the root is not an array (the rest of such a text
// is read for its syntax only, so a syntax error still throws). Throws as
// parse_json_document, std::length_error before reading an element past max_elements, and
// whatever `element` throws.
bool parse_json_array_elements(std::string_view text, size_t max_elements,
                               const std::function<void(nlohmann::json&&)>& element, int max_depth = 0);

}  // namespace seamcl
