// The documents that describe the service to clients: GET /openapi.json and the options part of
// GET /v1/methods. Every option's schema comes from the jobs' option tables
// (host/options/option_table.h), so the documents cannot drift from what the parsers take;
// server/openapi.json holds only what no table says (paths, answers, the scene formats).
#include "api_documents.h"

#include <seamcl/jobs/compare_job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/options/render_options.h>

namespace seamcl::server {
namespace {

using nlohmann::json;

// The answer's image format (/v1/render, /v1/reference): the service's own option.
json format_schema() {
  return {{"type", "string"}, {"enum", {"png", "exr"}}, {"default", "png"}, {"description", "The answer's image format"}};
}

// `table`'s options as the properties of a request body, but `skip`; `scene` keeps the
// document's own schema (a built-in name, or an inline scene object).
void set_options(json& properties, const OptionTable& table, const std::vector<std::string>& skip) {
  for (const OptionSpec& spec : table) {
    if (spec.key == "scene" || std::find(skip.begin(), skip.end(), spec.key) != skip.end()) continue;
    properties[spec.key] = option_schema(spec);
  }
}

json make_openapi() {
  json doc = json::parse(openapi_template());
  json& schemas = doc.at("components").at("schemas");
  const ServerOptions limits;

  json& render = schemas.at("RenderRequest").at("properties");
  set_options(render, render_option_table(), {});
  render["format"] = format_schema();

  json& compare = schemas.at("CompareRequest").at("properties");
  set_options(compare, compare_option_table(), {});
  compare.at("repeat")["maximum"] = limits.max_compare_repeat;
  compare.at("size").erase("default");
  compare.at("size")["description"] =
      "Image size WIDTHxHEIGHT, width*height at most limits.max_compare_pixels (413). Default: the largest size of "
      "the render default's aspect within limits.max_compare_pixels; the answer's size and size_from say which size "
      "was used";

  // The reference is one image of a compare's frame: the frame's options and the reference's own.
  json& reference = schemas.at("ReferenceRequest").at("properties");
  set_options(reference, compare_option_table(), {"methods", "msaa", "repeat", "constant_color", "reference"});
  reference.at("size").erase("default");
  reference["format"] = format_schema();

  // GET /v1/render: the same options as query parameters (scene keeps its own entry).
  json parameters = json::array();
  for (const json& parameter : doc.at("paths").at("/v1/render").at("get").at("parameters"))
    if (parameter.at("name") == "scene") parameters.push_back(parameter);
  for (const OptionSpec& spec : render_option_table()) {
    if (spec.key == "scene") continue;
    json schema = option_schema(spec);
    const std::string description = schema.at("description").get<std::string>();
    schema.erase("description");
    parameters.push_back({{"name", spec.key}, {"in", "query"}, {"schema", schema}, {"description", description}});
  }
  parameters.push_back({{"name", "format"}, {"in", "query"}, {"schema", format_schema()}});
  doc.at("paths").at("/v1/render").at("get")["parameters"] = parameters;

  // GET /v1/methods names every option of each table.
  json& methods = schemas.at("Methods").at("properties");
  auto keys = [](const OptionTable& table, const std::vector<std::string>& extra, const std::string& skip) {
    json out = json::array();
    for (const OptionSpec& spec : table)
      if (spec.key != skip) out.push_back(spec.key);
    for (const std::string& key : extra) out.push_back(key);
    return out;
  };
  methods.at("options")["required"] = keys(render_option_table(), {"format"}, "");
  methods.at("compare_options")["required"] = keys(compare_option_table(), {}, "scene");
  schemas.at("Methods").at("required").push_back("compare_options");
  return doc;
}

}  // namespace

std::string_view openapi_json() {
  static const std::string text = make_openapi().dump(2);
  return text;
}

json options_document(const std::vector<std::string>& scene_names, const ServerOptions& limits) {
  json options = options_schema(render_option_table());
  options.at("scene")["enum"] = scene_names;
  options.at("scene")["description"] = "a built-in scene name, or (POST only) an inline scene object as in docs/scene-format.md";
  options.at("size")["description"] = options.at("size").at("description").get<std::string>() + ", width*height*msaa at most " +
                                      std::to_string(limits.max_samples);
  options["format"] = format_schema();
  return options;
}

json compare_options_document(const ServerOptions& limits) {
  json options = options_schema(compare_option_table());
  options.erase("scene");
  options.at("repeat")["maximum"] = limits.max_compare_repeat;
  options.at("size").erase("default");
  return options;
}

}  // namespace seamcl::server
