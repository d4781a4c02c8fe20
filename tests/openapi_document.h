// The service's OpenAPI document (GET /openapi.json) as the server tests read it: parsed once, and
// a schema with its references followed.
#pragma once
#include <string>

#include <nlohmann/json.hpp>

#include "http_server.h"

namespace seamcl_tests {

inline const nlohmann::json& openapi_document() {
  static const nlohmann::json doc = nlohmann::json::parse(seamcl::server::openapi_json());
  return doc;
}

// `node` with its $ref followed. A field with its own description or default wraps its type as
// allOf: [{$ref}] (OpenAPI 3.0 ignores a $ref's siblings): that is the type with those merged in.
inline nlohmann::json resolve_schema(const nlohmann::json& node) {
  if (!node.is_object()) return node;
  if (node.contains("$ref")) {
    const std::string ref = node.at("$ref").get<std::string>();
    return resolve_schema(openapi_document().at(nlohmann::json::json_pointer(ref.substr(1))));
  }
  if (node.contains("allOf") && node.at("allOf").size() == 1) {
    nlohmann::json merged = resolve_schema(node.at("allOf")[0]);
    for (const auto& [key, value] : node.items()) {
      if (key != "allOf") merged[key] = value;
    }
    return merged;
  }
  return node;
}

}  // namespace seamcl_tests
