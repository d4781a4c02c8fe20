// The OpenAPI document (server/openapi.json) checked against what the server really accepts: the
// option tables and bounds of the shared parser (host/options/render_options), the compare limits
// of ServerOptions, the built-in scenes, and the scene forms of the scene parser (host/scene). A
// client generated from the document (or a fuzzer such as schemathesis) then sends what the
// parser takes, and every value the document rules out is one the parser refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/reference.h>
#include <seamcl/io/image_encoding.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/environment.h>
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>
#include "http_server.h"
#include "openapi_document.h"

using nlohmann::json;
using namespace seamcl;

namespace {

const json& document() { return seamcl_tests::openapi_document(); }

json resolve(const json& node) { return seamcl_tests::resolve_schema(node); }

const json& schema(const std::string& name) { return document().at("components").at("schemas").at(name); }

json query_parameter(const std::string& name) {
  for (const json& p : document().at("paths").at("/v1/render").at("get").at("parameters")) {
    const json parameter = resolve(p);
    if (parameter.at("name") == name && parameter.at("in") == "query") return resolve(parameter.at("schema"));
  }
  ADD_FAILURE() << "GET /v1/render has no query parameter " << name;
  return json::object();
}

// Every place the document describes render option `key`: the POST body of /v1/render, the GET
// query of /v1/render and (except method and format) the body of /v1/compare.
std::vector<std::pair<std::string, json>> option_schemas(const std::string& key) {
  std::vector<std::pair<std::string, json>> out;
  out.emplace_back("RenderRequest." + key, resolve(schema("RenderRequest").at("properties").value(key, json::object())));
  out.emplace_back("GET /v1/render ?" + key, query_parameter(key));
  if (key != "method" && key != "format" && key != "msaa") {
    out.emplace_back("CompareRequest." + key, resolve(schema("CompareRequest").at("properties").value(key, json::object())));
  }
  return out;
}

bool parses(const json& request) {
  try {
    parse_render_options(request);
    return true;
  } catch (const InputError&) {
    return false;
  }
}

TEST(OpenApi, EnumsAreTheParsersNames) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> tables = {
      {"method", method_names()},           {"filter", filter_names()},
      {"shading", shading_mode_names()},    {"texels", texel_format_names()},
      {"zero_coverage", zero_coverage_names()}, {"cube_method", cube_method_names()}};
  for (const auto& [key, names] : tables) {
    for (const auto& [where, option] : option_schemas(key)) {
      EXPECT_EQ(option.value("type", ""), "string") << where;
      ASSERT_TRUE(option.contains("enum")) << where << " has no enum";
      EXPECT_EQ(option.at("enum").get<std::vector<std::string>>(), names) << where;
      EXPECT_EQ(option.at("default"), to_json(RenderOptions{}).at(key)) << where;
    }
  }
  // displacement_method has no default (absent: no displacement), in every place it is described.
  for (const auto& [where, option] : option_schemas("displacement_method")) {
    ASSERT_TRUE(option.contains("enum")) << where << " has no enum";
    EXPECT_EQ(option.at("enum").get<std::vector<std::string>>(), displacement_method_names()) << where;
    EXPECT_FALSE(option.contains("default")) << where;
  }
  // format is the server's own option: exactly the names parse_image_encoding takes.
  for (const auto& [where, option] : option_schemas("format")) {
    ASSERT_TRUE(option.contains("enum")) << where;
    EXPECT_EQ(option.at("enum").get<std::vector<std::string>>(), image_encoding_names()) << where;
    EXPECT_EQ(option.at("enum").get<std::vector<std::string>>(), (std::vector<std::string>{"png", "exr", "f32"})) << where;
    for (const json& name : option.at("enum")) EXPECT_TRUE(parse_image_encoding(name.get<std::string>())) << where;
  }
  // compare's reference method is a method name too.
  const json reference_method = schema("CompareRequest").at("properties").at("reference_method");
  EXPECT_EQ(reference_method.at("enum").get<std::vector<std::string>>(), method_names());
  // /v1/reference's kinds: the reference names that are downsampled renders, each one the parser
  // takes, in its order.
  const json reference = schema("ReferenceRequest").at("properties").at("reference");
  std::vector<std::string> downsampled;
  for (const std::string& name : reference_kind_names()) {
    const ReferenceKind kind = *parse_reference_kind(name);
    if (kind == ReferenceKind::Paper || kind == ReferenceKind::Box) downsampled.push_back(name);
  }
  EXPECT_EQ(reference.at("enum").get<std::vector<std::string>>(), downsampled);
  EXPECT_EQ(reference.at("default"), to_string(ReferenceSettings{}.kind));
}

TEST(OpenApi, MsaaIsTheAllowedRates) {
  json rates = json::array();
  for (int msaa = -1; msaa <= 64; ++msaa) {
    if (parses({{"msaa", msaa}})) rates.push_back(msaa);
  }
  ASSERT_EQ(rates, json({1, 2, 4, 8, 16}));
  for (const auto& [where, option] : option_schemas("msaa")) {
    EXPECT_EQ(option.value("type", ""), "integer") << where;
    EXPECT_EQ(option.value("enum", json()), rates) << where;
  }
  // compare: the rate list items and the reference's rate.
  const json compare_msaa = schema("CompareRequest").at("properties").at("msaa");
  bool array_form = false;
  for (const json& form : compare_msaa.at("oneOf")) {
    if (form.value("type", "") == "array") {
      array_form = true;
      EXPECT_EQ(form.at("items").value("enum", json()), rates);
    }
    if (form.value("type", "") == "integer") EXPECT_EQ(form.value("enum", json()), rates);
  }
  EXPECT_TRUE(array_form);
  EXPECT_EQ(schema("CompareRequest").at("properties").at("reference_msaa").value("enum", json()), rates);
}

TEST(OpenApi, IntegerOptionsHaveTheParsersBounds) {
  for (const std::string key : {"aniso", "guard_band", "frame", "frames", "tessellation", "displacement_level"}) {
    for (const auto& [where, option] : option_schemas(key)) {
      EXPECT_EQ(option.value("type", ""), "integer") << where;
      ASSERT_TRUE(option.contains("minimum") && option.contains("maximum")) << where << ": " << option.dump();
      const long long lo = option.at("minimum"), hi = option.at("maximum");
      // frame must also be below frames: probe with the most frames there can be.
      auto request = [&](long long value) {
        json r = {{key, value}};
        if (key == "frame") r["frames"] = 1000000;
        return r;
      };
      EXPECT_TRUE(parses(request(lo))) << where << " minimum " << lo;
      EXPECT_TRUE(parses(request(hi))) << where << " maximum " << hi;
      EXPECT_FALSE(parses(request(lo - 1))) << where << " below the minimum";
      EXPECT_FALSE(parses(request(hi + 1))) << where << " above the maximum";
      if (key == "frame") EXPECT_FALSE(parses({{"frame", hi + 1}, {"frames", hi + 1}})) << "frame is below frames";
    }
  }
  // compare's repeat: the server's limit.
  const json repeat = schema("CompareRequest").at("properties").at("repeat");
  EXPECT_EQ(repeat.at("minimum"), 1);
  EXPECT_EQ(repeat.at("maximum"), server::ServerOptions{}.max_compare_repeat);
}

TEST(OpenApi, SizeHasThePatternTheParserTakes) {
  const std::vector<std::string> samples = {
      "1x1",      "480x540",     "16384x16384", "1x16384",  "16384x1",  "00064x064", "9999x10000", "16383x16379",
      "16385x1",  "1x16385",     "16390x5",     "17000x1",  "99999x99999", "0x5",     "5x0",        "00x5",
      "64",       "64x",         "x64",         "-1x5",     "+5x5",     "64x64x64",  " 64x64",     "64x64 ",
      "64X64",    "6.4x64",      "",            "x",        "1e3x5",    "0x0",       "20000x1",    "100000000000x1"};
  for (const auto& [where, option] : option_schemas("size")) {
    EXPECT_EQ(option.value("type", ""), "string") << where;
    ASSERT_TRUE(option.contains("pattern")) << where << " has no pattern";
    const std::regex pattern(option.at("pattern").get<std::string>(), std::regex::ECMAScript);
    for (const std::string& text : samples) {
      EXPECT_EQ(std::regex_search(text, pattern), parses({{"size", text}})) << where << ": '" << text << "'";
    }
  }
}

// compare's comma lists (methods, msaa): the string form's pattern takes what compare's own list
// parsers (split_list, parse_int_list) and the option parser take together.
TEST(OpenApi, CompareListPatternsAreTheListParsers) {
  auto string_form = [](const char* key) {
    for (const json& form : schema("CompareRequest").at("properties").at(key).at("oneOf")) {
      if (form.value("type", "") == "string") return form;
    }
    ADD_FAILURE() << key << " has no string form";
    return json::object();
  };
  auto methods_accepted = [](const std::string& text) {
    try {
      for (const std::string& name : split_list(text, "methods")) {
        if (!parse_method(name)) return false;
      }
      return true;
    } catch (const InputError&) {
      return false;
    }
  };
  auto rates_accepted = [](const std::string& text) {
    try {
      for (int rate : parse_int_list(text, "msaa")) {
        if (!parses({{"msaa", rate}})) return false;
      }
      return true;
    } catch (const InputError&) {
      return false;
    }
  };
  const std::regex methods(string_form("methods").value("pattern", "^$"), std::regex::ECMAScript);
  for (const std::string text : {"discard", "discard,clamp", " discard , traverse\t", "clamp,clamp", "guardband,black",
                                 "", ",", "discard,", ",discard", "discard,,clamp", "Discard", "nearest", "discard clamp",
                                 "discard;clamp", "discard,nope", " ", "\tclamp"}) {
    EXPECT_EQ(std::regex_search(text, methods), methods_accepted(text)) << "methods '" << text << "'";
  }
  const std::regex rates(string_form("msaa").value("pattern", "^$"), std::regex::ECMAScript);
  for (const std::string text : {"1", "1,4", "1,2,4,8,16", " 4 , 8", "+4", "004", "016", "3", "0", "32", "1,3", "",
                                 "1,", ",1", "4.0", "0x4", "-4", "1 4", "4a", "16,16", "\t2\t"}) {
    EXPECT_EQ(std::regex_search(text, rates), rates_accepted(text)) << "msaa '" << text << "'";
  }
}

// ---- The scene forms against the scene parser (parse_scene_json). docs/scene-format.md's field
// tables are generated from these schemas (scripts/http-reference --tables, checked by
// Docs.HttpReferenceMatchesOpenApi), so what holds here holds for the page too.

// The schema of a path ("faces[i].texture.width") inside `form`, with the object that holds it
// (for its required list); null when the schema has no such property.
std::pair<json, json> schema_at(const json& form, const std::string& path) {
  json node = resolve(form), parent;
  std::stringstream parts(path);
  for (std::string part; std::getline(parts, part, '.');) {
    const bool element = part.ends_with("[i]");
    if (element) part = part.substr(0, part.size() - 3);
    if (!node.contains("properties") || !node.at("properties").contains(part)) return {json(), json()};
    parent = node;
    node = resolve(node.at("properties").at(part));
    if (element) {
      if (!node.contains("items")) return {json(), json()};
      node = resolve(node.at("items"));
    }
  }
  return {node, parent};
}

// The scene forms of the document: the branches of RenderRequest.scene that are objects.
std::vector<json> scene_object_forms(const json& scene) {
  std::vector<json> out;
  for (const char* combinator : {"oneOf", "anyOf"}) {
    if (!scene.contains(combinator)) continue;
    for (const json& branch : scene.at(combinator)) {
      const json form = resolve(branch);
      if (form.value("type", "") == "object") out.push_back(form);
    }
  }
  return out;
}

// One field of a scene form at any depth ("faces[i].texture.width"), its schema (references
// followed) and whether the object that holds it requires it.
struct SchemaField {
  std::string path;
  json schema;
  bool required;
};

void collect_fields(const json& object, const std::string& prefix, std::vector<SchemaField>& out) {
  const json required = object.value("required", json::array());
  const json properties = object.value("properties", json::object());
  for (const auto& [key, child] : properties.items()) {
    const json node = resolve(child);
    out.push_back({prefix + key, node, std::find(required.begin(), required.end(), key) != required.end()});
    if (node.value("type", "") == "object") collect_fields(node, prefix + key + ".", out);
    if (node.value("type", "") == "array" && resolve(node.value("items", json::object())).value("type", "") == "object")
      collect_fields(resolve(node.at("items")), prefix + key + "[i].", out);
  }
}

std::vector<SchemaField> schema_fields(const json& form) {
  std::vector<SchemaField> out;
  collect_fields(resolve(form), "", out);
  return out;
}

// Where a schema path is in a document: its JSON pointer and the name the parser's errors give it
// ("faces[1].roughness"), at the first array element that holds the rest of the path.
struct Location {
  json::json_pointer pointer;
  std::string field;
};

std::optional<Location> locate(const json& node, const std::vector<std::string>& parts, size_t k, const Location& at) {
  if (k == parts.size()) return at;
  std::string part = parts[k];
  const bool element = part.ends_with("[i]");
  if (element) part.resize(part.size() - 3);
  if (!node.is_object() || !node.contains(part)) return std::nullopt;
  const Location here{at.pointer / part, at.field.empty() ? part : at.field + "." + part};
  if (!element) return locate(node.at(part), parts, k + 1, here);
  for (size_t i = 0; i < node.at(part).size(); ++i) {
    const Location item{here.pointer / i, here.field + "[" + std::to_string(i) + "]"};
    if (std::optional<Location> found = locate(node.at(part).at(i), parts, k + 1, item)) return found;
  }
  return std::nullopt;
}

std::optional<Location> locate(const json& doc, const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream in(path);
  for (std::string part; std::getline(in, part, '.');) parts.push_back(part);
  return locate(doc, parts, 0, Location{json::json_pointer(), ""});
}

// The parser's refusal of a scene document; nullopt when it takes it. Textures stay deferred, so
// nothing is baked.
std::optional<InputError> refusal(const json& doc) {
  GeneratorOptions options;
  options.defer_textures = true;
  try {
    parse_scene_json(doc, {}, options);
    return std::nullopt;
  } catch (const InputError& error) {
    return error;
  }
}

// What a parsed scene holds, for telling whether a field written as its default changes it.
json scene_state(const json& doc) {
  GeneratorOptions options;
  options.defer_textures = true;
  const Scene s = parse_scene_json(doc, {}, options);
  auto v = [](glm::vec3 x) { return json{x.x, x.y, x.z}; };
  json faces = json::array();
  for (const Face& face : s.faces) faces.push_back({face.roughness, face.texture.width(), face.texture.height()});
  json normals = json::array();
  for (const glm::vec3& n : s.normals) normals.push_back(v(n));
  json state = {{"name", s.name},
                {"texels, light and background", scene_content_hash(s)},
                {"faces", faces},
                {"normals", normals},
                {"camera", {v(s.camera.eye), v(s.camera.target), v(s.camera.up), s.camera.fov_y_degrees}}};
  if (s.orbit) state["orbit"] = {v(s.orbit->center), s.orbit->radius, s.orbit->height, s.orbit->start_degrees};
  if (s.environment) {
    const Environment& e = *s.environment;
    const AnalyticEnvironment& a = e.analytic;
    state["environment"] = {e.cube_size,    e.bake_samples,  e.skybox,    e.constant ? v(*e.constant) : json(),
                            v(a.sun_direction), a.sun_radius, v(a.sun_color), v(a.zenith), v(a.horizon), v(a.ground)};
  }
  return state;
}

// Documents that between them hold every field of a form, each field once at least.
const json kEveryExplicitField = json::parse(R"({
  "name": "every_field",
  "positions": [[-1, -0.5, 0], [0, -0.5, 0], [1, -0.5, 0], [-1, 0.5, 0], [0, 0.5, 0], [1, 0.5, 0]],
  "normals": [[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 1]],
  "faces": [
    {"vertices": [0, 1, 4, 3], "texture": {"width": 8, "height": 4, "content": "surface", "color": [0.8, 0.7, 0.6]}},
    {"vertices": [1, 2, 5, 4], "roughness": 0.5, "texture": {"width": 4, "height": 4, "content": "constant", "color": [0.2, 0.3, 0.4]}}
  ],
  "camera": {"eye": [0, 0, 2.7], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_degrees": 40},
  "orbit": {"center": [0, 0, 0], "radius": 2.7, "height": 0.5, "start_degrees": 10},
  "light": {"to_light": [0.3, 0.5, 1], "color": [1, 0.9, 0.8], "ambient": 0.3},
  "background": [0.1, 0.1, 0.1],
  "environment": {"cube_size": 8, "bake_samples": 1, "skybox": false, "constant": [0.5, 0.5, 0.5],
                  "sun_direction": [0, 1, 0], "sun_radius": 0.2, "sun_color": [1, 1, 1], "zenith": [0, 0, 1],
                  "horizon": [1, 1, 1], "ground": [0.2, 0.2, 0.2]}
})");
const json kEveryGeneratorField[] = {
    json::parse(R"({"generator": "quad2", "options": {"tint": false}})"),
    json::parse(R"({"generator": "paper", "options": {"tint": true, "constant_color": [0.5, 0.6, 0.7],
                    "content": "detail", "faces": 400, "texture_scale_log2": -1}})"),
    json::parse(R"({"generator": "envmap", "options": {"roughness": [0, 0.5, 1], "environment": {"cube_size": 8,
                    "bake_samples": 1, "skybox": false, "constant": [0.5, 0.5, 0.5], "sun_direction": [0, 1, 0],
                    "sun_radius": 0.2, "sun_color": [1, 1, 1], "zenith": [0, 0, 1], "horizon": [1, 1, 1],
                    "ground": [0.2, 0.2, 0.2]}}})")};

// Fields the schema cannot mark required because another field decides (OpenAPI 3.0 has no
// if/then), each refused when removed from kEveryExplicitField (face 0 is diffuse, face 1
// reflective), naming the field or the one that needs it.
const std::map<std::string, std::string> kRequiredByAnother = {
    {"environment", "faces[1].roughness"}, {"normals", "normals"}, {"faces[i].texture", "faces[0].texture"}};

std::string refusal_text(const std::optional<InputError>& error) { return error ? error->what() : "taken"; }

// The fields a scene file may use and an inline scene may not (it names no files), so the
// document leaves them out: docs/scene-format.md describes them by hand.
const std::map<std::string, std::set<std::string>> kFileOnlyFields = {
    {"environment", {"file", "layout", "faces"}},
    {"options.environment", {"file", "layout", "faces"}},
    {"faces[i].texture", {"image"}}};

// An object of the document at `at` (schema path `path`) with a field its schema lacks is refused
// naming that field, and the fields the refusal lists as known are the schema's and the file-only ones.
void expect_only_the_schemas_fields(const json& doc, const Location& at, const json& object, const std::string& path) {
  json extra = doc;
  extra[at.pointer / "no_such_field"] = 1;
  const std::optional<InputError> error = refusal(extra);
  const std::string field = at.field.empty() ? "no_such_field" : at.field + ".no_such_field";
  ASSERT_TRUE(error && error->field() == field) << field << ": " << refusal_text(error);
  const std::string text = error->what();
  const size_t open = text.find("(known: "), close = text.rfind(')');
  ASSERT_TRUE(open != std::string::npos && close > open) << text;
  std::set<std::string> known;
  std::stringstream names(text.substr(open + 8, close - open - 8));
  for (std::string name; std::getline(names, name, ',');) known.insert(name.substr(name.find_first_not_of(' ')));
  std::set<std::string> documented;
  const json properties = object.value("properties", json::object());
  for (const auto& [key, unused] : properties.items()) documented.insert(key);
  if (const auto file_only = kFileOnlyFields.find(path); file_only != kFileOnlyFields.end())
    documented.insert(file_only->second.begin(), file_only->second.end());
  EXPECT_EQ(known, documented) << (path.empty() ? "the scene" : path) << ": the parser's fields, then the document's";
}

// Every field of `form`, in the documents that hold it: the documents are taken; a field of the
// wrong type, or outside the schema's bounds or enum, is refused naming it; a field removed is
// refused naming it when the schema requires it, and taken otherwise; a field set to the schema's
// default leaves the scene as without it; and every object refuses a field the schema lacks.
void expect_parser_takes_the_schema(const json& form, const std::vector<json>& documents) {
  for (const json& doc : documents) EXPECT_EQ(refusal_text(refusal(doc)), "taken") << doc.dump();
  const auto refuses_naming = [](const json& doc, const std::string& field) {
    const std::optional<InputError> error = refusal(doc);
    return error && error->field() == field;
  };
  for (const SchemaField& field : schema_fields(form)) {
    const json* doc = nullptr;
    std::optional<Location> at;
    for (const json& candidate : documents) {
      if (!doc && (at = locate(candidate, field.path))) doc = &candidate;
    }
    if (!doc) {
      ADD_FAILURE() << field.path << ": no test document holds it";
      continue;
    }
    const json& schema = field.schema;
    const std::string type = schema.value("type", "");
    // Removed.
    json removed = *doc;
    removed.at(at->pointer.parent_pointer()).erase(at->pointer.back());
    const auto required_by = kRequiredByAnother.find(field.path);
    if (field.required || required_by != kRequiredByAnother.end()) {
      const std::string named = field.required ? at->field : required_by->second;
      EXPECT_TRUE(refuses_naming(removed, named)) << at->field << " removed: " << refusal_text(refusal(removed));
    } else {
      EXPECT_EQ(refusal_text(refusal(removed)), "taken") << at->field << " removed";
    }
    // The wrong type.
    json wrong = *doc;
    wrong[at->pointer] = type == "string" ? json(7) : json("text");
    EXPECT_TRUE(refuses_naming(wrong, at->field)) << at->field << " as " << wrong[at->pointer].dump() << ": "
                                                  << refusal_text(refusal(wrong));
    // Its default, written out.
    if (schema.contains("default")) {
      json written = *doc;
      written[at->pointer] = schema.at("default");
      const json difference = json::diff(scene_state(removed), scene_state(written));
      EXPECT_TRUE(difference.empty()) << at->field << " = " << schema.at("default").dump() << " changes the scene at "
                                      << difference.front().value("path", "") << " (absent, then written)";
    }
    // Its bounds and enum: for a scalar, and for an array's numbers (as the array's first element).
    const bool array = type == "array";
    const json bounded = array ? resolve(schema.value("items", json::object())) : schema;
    const std::string bounded_field = array ? at->field + "[0]" : at->field;
    const json::json_pointer bounded_pointer = array ? at->pointer / 0 : at->pointer;
    const bool integer = bounded.value("type", "") == "integer";
    for (const char* side : {"minimum", "maximum"}) {
      if (!bounded.contains(side) || !bounded.at(side).is_number()) continue;
      const double bound = bounded.at(side).get<double>();
      if (std::abs(bound) >= 1e38) continue;  // a float's range: the finite checks
      const bool low = std::string(side) == "minimum";
      const bool exclusive = bounded.value(low ? "exclusiveMinimum" : "exclusiveMaximum", false);
      const double step = integer ? 1.0 : 1e-3 * std::max(1.0, std::abs(bound));
      json at_bound = *doc, beyond = *doc;
      at_bound[bounded_pointer] = integer ? json(static_cast<long long>(bound)) : json(bound);
      beyond[bounded_pointer] = integer ? json(static_cast<long long>(low ? bound - step : bound + step))
                                        : json(exclusive ? bound : low ? bound - step : bound + step);
      if (!exclusive && !bounded.contains("enum")) {
        EXPECT_EQ(refusal_text(refusal(at_bound)), "taken") << bounded_field << " = " << at_bound[bounded_pointer];
      }
      EXPECT_TRUE(refuses_naming(beyond, bounded_field))
          << bounded_field << " = " << beyond[bounded_pointer] << ": " << refusal_text(refusal(beyond));
    }
    if (bounded.contains("enum")) {
      for (const json& value : bounded.at("enum")) {
        json member = *doc;
        member[bounded_pointer] = value;
        EXPECT_EQ(refusal_text(refusal(member)), "taken") << bounded_field << " = " << value;
      }
      json outsider = *doc;
      outsider[bounded_pointer] = integer ? json(bounded.at("enum").back().get<long long>() - 1) : json("no-such-value");
      EXPECT_TRUE(refuses_naming(outsider, bounded_field))
          << bounded_field << " = " << outsider[bounded_pointer] << ": " << refusal_text(refusal(outsider));
    }
    // A field the schema lacks, in an object: refused, and the fields the refusal lists as known
    // are the schema's (and those only scene files may use).
    if (type == "object") expect_only_the_schemas_fields(*doc, *at, schema, field.path);
  }
  expect_only_the_schemas_fields(documents.front(), Location{json::json_pointer(), ""}, resolve(form), "");
}

// A scene is a built-in name (in the GET query and in both bodies) or one of two object forms.
TEST(OpenApi, SceneIsABuiltInNameOrOneOfTwoObjectForms) {
  std::vector<std::string> built_in;
  for (const GeneratorInfo& g : scene_generators()) built_in.push_back(g.name);
  EXPECT_EQ(query_parameter("scene").value("enum", json()), json(built_in));
  for (const char* request : {"RenderRequest", "CompareRequest"}) {
    const json scene = resolve(schema(request).at("properties").at("scene"));
    bool name_form = false;
    for (const json& branch : scene.value("oneOf", json::array())) {
      const json form = resolve(branch);
      if (form.value("type", "") == "string") {
        name_form = true;
        EXPECT_EQ(form.value("enum", json()), json(built_in)) << request;
      }
    }
    EXPECT_TRUE(name_form) << request << ".scene has no string form";
    const std::vector<json> forms = scene_object_forms(scene);
    ASSERT_EQ(forms.size(), 2u) << request << ": the generator form and the explicit form";
    EXPECT_NE(forms[0], forms[1]);
    for (const json& form : forms) EXPECT_TRUE(form == schema("GeneratorScene") || form == schema("InlineScene"));
  }
}

TEST(OpenApi, InlineSceneIsWhatTheSceneParserTakes) {
  expect_parser_takes_the_schema(schema("InlineScene"), {kEveryExplicitField});
  // The conditionally required fields are optional where their condition does not hold.
  json reflective_without_texture = kEveryExplicitField;
  reflective_without_texture["faces"][1].erase("texture");
  EXPECT_EQ(refusal_text(refusal(reflective_without_texture)), "taken");
  json all_diffuse = kEveryExplicitField;
  all_diffuse["faces"][1].erase("roughness");
  all_diffuse.erase("environment");
  all_diffuse.erase("normals");
  EXPECT_EQ(refusal_text(refusal(all_diffuse)), "taken");
}

TEST(OpenApi, GeneratorSceneIsWhatTheSceneParserTakes) {
  expect_parser_takes_the_schema(schema("GeneratorScene"),
                                 std::vector<json>(std::begin(kEveryGeneratorField), std::end(kEveryGeneratorField)));
}

// The documents that hold every field, mutated at random (a value replaced by another type, an
// extreme number, a non-finite one, a long or deep array; a member removed or added): the parser
// takes each or refuses it with an InputError naming a field, and nothing else escapes.
TEST(OpenApi, MutatedSceneDocumentsAreTakenOrRefusedNamingAField) {
  std::vector<json> documents = {kEveryExplicitField};
  documents.insert(documents.end(), std::begin(kEveryGeneratorField), std::end(kEveryGeneratorField));
  json deep = json::array();
  for (int k = 0; k < 64; ++k) deep = json::array({deep});
  const std::vector<json> replacements = {
      json(nullptr), json(true), json(-1), json(0), json(1e39), json(-1e39), json(1e308), json(2147483648LL),
      json(-9223372036854775807LL - 1), json(0.5), json(std::numeric_limits<double>::quiet_NaN()),
      json(std::numeric_limits<double>::infinity()), json(""), json("\xff\xfe"), json::array(), json::object(),
      json::array({1, 2, 3}), json(std::vector<int>(1000, 7)), deep, json::array({json::array({0, 0, 0})})};
  std::mt19937 rng(2026);
  int taken = 0, refused = 0;
  for (int round = 0; round < 3000; ++round) {
    json doc = documents[rng() % documents.size()];
    for (int edit = 0, edits = 1 + static_cast<int>(rng() % 3); edit < edits; ++edit) {
      const json flat = doc.flatten();
      std::vector<std::string> leaves;
      for (const auto& [pointer, unused] : flat.items()) leaves.push_back(pointer);
      if (leaves.empty()) break;
      std::string at = leaves[rng() % leaves.size()];
      if (at.empty()) break;  // the document itself emptied
      // Sometimes the leaf's parent (an array or an object) instead of the leaf.
      if (rng() % 3 == 0 && at.rfind('/') > 0) at.resize(at.rfind('/'));
      const std::string key = at.substr(at.rfind('/') + 1);
      json& parent = doc[json::json_pointer(at.substr(0, at.rfind('/')))];
      switch (rng() % 3) {
        case 0: doc[json::json_pointer(at)] = replacements[rng() % replacements.size()]; break;
        case 1:
          if (parent.is_object()) parent.erase(key);
          else if (parent.is_array() && !parent.empty()) parent.erase(parent.size() - 1);
          break;
        default:
          if (parent.is_object()) parent["added_" + std::to_string(edit)] = 1;
          else if (parent.is_array() && !parent.empty()) parent.push_back(parent.front());
      }
    }
    try {
      GeneratorOptions options;
      options.defer_textures = true;
      parse_scene_json(doc, {}, options);
      ++taken;
    } catch (const InputError& error) {
      EXPECT_FALSE(error.field().empty()) << error.what() << "\n" << doc.dump();
      ++refused;
    } catch (const std::exception& other) {
      ADD_FAILURE() << "not an InputError: " << other.what() << "\n" << doc.dump();
    }
  }
  // Both outcomes occur, so the mutations neither always break the document nor never do.
  EXPECT_GT(taken, 100);
  EXPECT_GT(refused, 1000);
}

TEST(OpenApi, SceneFormConstraintsMatchTheFormat) {
  const json scene = resolve(schema("RenderRequest").at("properties").at("scene"));
  const std::vector<json> forms = scene_object_forms(scene);
  ASSERT_EQ(forms.size(), 2u);
  const json& explicit_form = schema_at(forms[0], "faces").first.is_object() ? forms[0] : forms[1];
  const json& generator_form = schema_at(forms[0], "faces").first.is_object() ? forms[1] : forms[0];
  std::vector<std::string> built_in;
  for (const GeneratorInfo& g : scene_generators()) built_in.push_back(g.name);
  EXPECT_EQ(schema_at(generator_form, "generator").first.value("enum", json()), json(built_in));
  // Texture sides: the powers of two from 1 to 4096.
  json sides = json::array();
  for (int side = 1; side <= 4096; side *= 2) sides.push_back(side);
  EXPECT_EQ(schema_at(explicit_form, "faces[i].texture.width").first.value("enum", json()), sides);
  EXPECT_EQ(schema_at(explicit_form, "faces[i].texture.height").first.value("enum", json()), sides);
  EXPECT_EQ(schema_at(explicit_form, "faces").first.value("minItems", 0), 1);
  EXPECT_EQ(schema_at(explicit_form, "faces[i].vertices").first.at("items").value("minimum", -1), 0);
  const json ambient = schema_at(explicit_form, "light.ambient").first;
  EXPECT_EQ(ambient.value("minimum", -1.0), 0.0);
  EXPECT_EQ(ambient.value("maximum", -1.0), 1.0);
  const json fov = schema_at(explicit_form, "camera.fov_y_degrees").first;
  // OpenAPI 3.0: an exclusive bound is the bound plus exclusiveMinimum/exclusiveMaximum: true.
  EXPECT_EQ(fov.value("minimum", -1.0), 0.0);
  EXPECT_EQ(fov.value("exclusiveMinimum", false), true);
  EXPECT_EQ(fov.value("maximum", -1.0), 180.0);
  EXPECT_EQ(fov.value("exclusiveMaximum", false), true);
  const json radius = schema_at(explicit_form, "orbit.radius").first;
  EXPECT_EQ(radius.value("minimum", -1.0), 0.0);
  EXPECT_EQ(radius.value("exclusiveMinimum", false), true);
  for (const char* colour : {"faces[i].texture.color", "light.color", "background"}) {
    EXPECT_EQ(resolve(schema_at(explicit_form, colour).first.at("items")).value("minimum", -1.0), 0.0) << colour;
    EXPECT_EQ(resolve(schema_at(explicit_form, colour).first.at("items")).value("maximum", -1.0),
              static_cast<double>(kMaxColorMagnitude)) << colour;
  }
}

}  // namespace
