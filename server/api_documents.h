// What the service tells clients about itself: the OpenAPI document and the methods document,
// generated from the jobs' option tables.
#pragma once
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "http_server.h"

namespace seamcl {
struct Scene;
}  // namespace seamcl

namespace seamcl::server {

// server/openapi.json as embedded at build time: paths, answers and scene formats, without the
// options (api_documents.cpp fills those in).
std::string_view openapi_template();

// The options of a render request, key -> JSON schema (type, enum or bounds, default,
// description), with `scene`'s built-in names and this server's sample limit: GET /v1/methods'
// "options", from which the viewer builds its controls.
nlohmann::json options_document(const std::vector<std::string>& scene_names, const ServerOptions& limits);
// The compare request's options but scene, with this server's repeat limit: "compare_options".
nlohmann::json compare_options_document(const ServerOptions& limits);
// GET /v1/methods: each method with its texture memory on `default_scene` as packed for the
// device (rgba8; rgba32f stores the same texels at 16 bytes each), the options documents above
// and this server's limits.
nlohmann::json methods_document(const Scene& default_scene, const ServerOptions& limits);

}  // namespace seamcl::server
