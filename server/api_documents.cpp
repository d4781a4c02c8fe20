// The documents that describe the service to clients: GET /openapi.json and GET /v1/methods.
// Every option's schema comes from the jobs' option tables (host/options/option_table.h), so the
// documents cannot drift from what the parsers take;
// server/openapi.json holds only what no table says (paths, answers, the scene formats).
#include "api_documents.h"

#include <seamcl/io/image_encoding.h>
#include <seamcl/jobs/compare_job.h>
#include <seamcl/jobs/inspect_job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/options/option_domains.h>
#include <seamcl/options/render_options.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>

namespace seamcl::server {
namespace {

using nlohmann::json;

// The answer's image format (/v1/render, /v1/reference): the service's own option.
json format_schema() {
  return {{"type", "string"},
          {"enum", image_encoding_names()},
          {"default", to_string(ImageEncoding::Png)},
          {"description",
           "The answer's image format: png (sRGB 8-bit), exr (linear half or float), f32 (linear little-endian float32 "
           "RGBA, rows top first, no header: the size is in X-Seamcl-Width and X-Seamcl-Height)"}};
}

// An image answer's bodies, one per encoding, and the headers that give its size: from the list
// the parser takes, so a new encoding is documented where it is accepted.
void set_image_answer(json& response) {
  json content = json::object();
  for (const std::string& name : image_encoding_names())
    content[media_type(*parse_image_encoding(name))] = {{"schema", {{"type", "string"}, {"format", "binary"}}}};
  response["content"] = content;
  json& headers = response["headers"];
  headers["X-Seamcl-Width"] = {{"description", "the image's width in pixels"}, {"schema", {{"type", "integer"}}}};
  headers["X-Seamcl-Height"] = {{"description", "the image's height in pixels (f32 rows, top first)"}, {"schema", {{"type", "integer"}}}};
}

// `table`'s options as the properties of a request body, but `skip`; `scene` keeps the
// document's own schema (a built-in name, or an inline scene object).
void set_options(json& properties, const OptionTable& table, const std::vector<std::string>& skip) {
  for (const OptionSpec& spec : table) {
    if (spec.key == "scene" || std::find(skip.begin(), skip.end(), spec.key) != skip.end()) continue;
    properties[spec.key] = option_schema(spec);
  }
}

std::string method_description(const std::string& name) {
  if (name == "clamp") return "taps outside the face read the nearest edge texel (seams show)";
  if (name == "black") return "taps outside the face weigh zero, no renormalisation (edges darken)";
  if (name == "discard") return "taps outside the face weigh zero, the rest are renormalised (Toth 2013)";
  if (name == "traverse") {
    return "taps outside the face are fetched from the edge-adjacent faces and, past valence-4 corners, the diagonal "
           "face (McDonald 2013, with Ptex's corners)";
  }
  if (name == "traverse-edges") return "taps outside the face are fetched from the edge-adjacent faces only (McDonald 2013, as the paper compares)";
  if (name == "guardband") return "each mip level carries a band of texels from its neighbours (McDonald and Burley 2011)";
  return "";
}

json make_openapi() {
  json doc = json::parse(openapi_template());
  json& schemas = doc.at("components").at("schemas");
  const ServerOptions limits;

  set_image_answer(doc.at("components").at("responses").at("Image"));
  set_image_answer(doc.at("paths").at("/v1/reference").at("post").at("responses").at("200"));

  json& render = schemas.at("RenderRequest").at("properties");
  set_options(render, render_option_table(), {});
  render["format"] = format_schema();

  // An inspection: the render's options (its answer is JSON: no format) and the pixel's.
  json& inspect = schemas.at("InspectRequest").at("properties");
  set_options(inspect, render_option_table(), {});
  set_options(inspect, inspect_job_option_table(), {});
  json& overlays = schemas.at("OverlaysRequest").at("properties");
  set_options(overlays, render_option_table(), {});
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
  // A list is described by its comma form (the one a form field sends): an OptionSpec has one type.
  for (const OptionSpec& spec : compare_option_table()) {
    if (spec.type != OptionType::List) continue;
    json& option = options.at(spec.key);
    std::string text;
    for (const json& item : spec.default_value) text += (text.empty() ? "" : ",") + (item.is_string() ? item.get<std::string>() : item.dump());
    option = {{"type", "string"},
              {"pattern", option.at("oneOf").at(0).at("pattern")},
              {"default", text},
              {"description", option.at("description").get<std::string>() + " (a comma list, or a JSON array)"}};
  }
  options.erase("scene");
  options.at("repeat")["maximum"] = limits.max_compare_repeat;
  options.at("size").erase("default");
  return options;
}

json methods_document(const Scene& default_scene, const ServerOptions& limits) {
  const RenderOptions defaults;
  json methods = json::array();
  // From the sizes (exactly what pack_scene stores, render_memory.h): nothing is baked or packed.
  const SceneSizes default_sizes = scene_sizes(default_scene);
  for (const std::string& name : method_names()) {
    const Method method = *parse_method(name);
    const PackedTextureMemory packed =
        packed_texture_memory(default_sizes, TexelFormat::Rgba8, method == Method::Guardband ? defaults.guard_band : 0);
    const size_t float_texel_bytes = 4 * sizeof(float);
    methods.push_back({{"name", name},
                       {"description", method_description(name)},
                       {"texture_bytes", {{"rgba8", packed.texture_bytes}, {"rgba32f", packed.texels * float_texel_bytes}}},
                       {"padding_bytes", {{"rgba8", packed.padding_bytes}, {"rgba32f", packed.band_texels * float_texel_bytes}}},
                       {"adjacency_bytes", reads_adjacency(method) ? packed.adjacency_bytes : 0}});
  }
  std::vector<std::string> scene_names;
  for (const GeneratorInfo& g : scene_generators()) scene_names.push_back(g.name);
  return {
      {"scene", defaults.scene},
      {"methods", methods},
      {"options", options_document(scene_names, limits)},
      {"compare_options", compare_options_document(limits)},
      {"domains", render_option_domains()},
      {"limits",
       {{"max_body_bytes", limits.max_body_bytes},
        {"max_samples", limits.max_samples},
        {"max_inline_faces", limits.max_inline_faces},
        {"max_inline_texels", limits.max_inline_texels},
        {"max_compare_pixels", limits.max_compare_pixels},
        {"max_compare_entries", limits.max_compare_entries},
        {"max_compare_repeat", limits.max_compare_repeat},
        {"max_reference_samples", limits.max_reference_samples}}}};
}

}  // namespace seamcl::server
