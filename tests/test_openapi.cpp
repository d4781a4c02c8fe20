// The OpenAPI document (server/openapi.json) checked against what the server really accepts: the
// option tables and bounds of the shared parser (host/options/render_options), the compare limits
// of ServerOptions, the built-in scenes, and the inline scene format of docs/scene-format.md. A
// client generated from the document (or a fuzzer such as schemathesis) then sends what the
// parser takes, and every value the document rules out is one the parser refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <functional>
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
#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include "http_server.h"

using nlohmann::json;
using namespace seamcl;

namespace {

const json& document() {
  static const json doc = json::parse(server::openapi_json());
  return doc;
}

json resolve(const json& node) {
  if (node.is_object() && node.contains("$ref"))
    return resolve(document().at(json::json_pointer(node.at("$ref").get<std::string>().substr(1))));
  return node;
}

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

// ---- The inline scene: the document's schema against docs/scene-format.md's field tables.

// One row of a field table: its path (faces[i].texture.width), type text and whether required.
struct DocumentedField {
  std::string path;
  std::string type;
  bool required;
};

// The field tables of docs/scene-format.md: section 1 (the generator form) and section 2 (an
// explicit scene). A cell may name several fields ("`camera.eye`, `camera.target`") or abbreviate
// a sibling ("`faces[i].texture.width`, `.height`").
std::vector<std::vector<DocumentedField>> documented_scene_forms() {
  std::ifstream in(std::string(SEAMCL_EXAMPLES_DIR) + "/../docs/scene-format.md");
  EXPECT_TRUE(in) << "docs/scene-format.md not found";
  std::vector<std::vector<DocumentedField>> forms;
  std::string line;
  while (std::getline(in, line)) {
    if (line.starts_with("## 1.") || line.starts_with("## 2.")) forms.emplace_back();
    if (line.starts_with("## Errors") || line.starts_with("### ")) {
      if (!forms.empty() && forms.size() == 2) break;
    }
    if (forms.empty() || !line.starts_with("| `")) continue;
    std::vector<std::string> cells;
    std::stringstream row(line.substr(1));
    for (std::string cell; std::getline(row, cell, '|');) cells.push_back(cell);
    if (cells.size() < 3) continue;
    const bool required = cells[2].find("yes") != std::string::npos;
    std::string previous;
    std::stringstream names(cells[0]);
    for (std::string name; std::getline(names, name, ',');) {
      const size_t open = name.find('`'), close = name.rfind('`');
      name = name.substr(open + 1, close - open - 1);
      if (name.starts_with(".")) name = previous.substr(0, previous.rfind('.')) + name;
      forms.back().push_back({name, cells[1], required});
      previous = name;
    }
  }
  return forms;
}

// The schema of a documented path ("faces[i].texture.width") inside `form`, with the object that
// holds it (for its required list); null when the schema has no such property.
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
      parent = json::object();  // the items of an array are not required by name
      node = resolve(node.at("items"));
    }
  }
  return {node, parent};
}

void expect_documented_type(const json& node, const std::string& type, const std::string& path) {
  const std::string t = node.value("type", "");
  auto is_triple = [&](const char* item_type) {
    return t == "array" && node.value("minItems", 0) == 3 && node.value("maxItems", 0) == 3 &&
           resolve(node.at("items")).value("type", "") == item_type;
  };
  if (type.find("array of 4 integers") != std::string::npos) {
    EXPECT_TRUE(t == "array" && node.value("minItems", 0) == 4 && node.value("maxItems", 0) == 4 &&
                resolve(node.at("items")).value("type", "") == "integer")
        << path << ": " << node.dump();
  } else if (type.find("array") != std::string::npos) {
    EXPECT_EQ(t, "array") << path;
  } else if (type.find("[x, y, z]") != std::string::npos || type.find("[r, g, b]") != std::string::npos) {
    EXPECT_TRUE(is_triple("number")) << path << ": " << node.dump();
  } else if (type.find("\"detail\"") != std::string::npos) {
    EXPECT_EQ(node.value("enum", json()), json(texture_content_names())) << path;
  } else if (type.find("\"surface\"") != std::string::npos) {
    EXPECT_EQ(node.value("enum", json()), json({"surface", "constant"})) << path;
  } else {
    for (const char* simple : {"string", "integer", "number", "boolean", "object"}) {
      if (type.find(simple) != std::string::npos) {
        EXPECT_EQ(t, simple) << path << ": " << node.dump();
        return;
      }
    }
    ADD_FAILURE() << path << ": undocumented type text " << type;
  }
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

TEST(OpenApi, SceneIsABuiltInNameOrAnInlineSceneOfTheDocumentedFormat) {
  std::vector<std::string> built_in;
  for (const GeneratorInfo& g : scene_generators()) built_in.push_back(g.name);
  // A name: the built-in scenes, in the GET query and in both bodies.
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
    const std::vector<std::vector<DocumentedField>> documented = documented_scene_forms();
    ASSERT_EQ(forms.size(), 2u) << request << ": the generator form and the explicit form";
    ASSERT_EQ(documented.size(), 2u);
    for (size_t f = 0; f < 2; ++f) {
      // Which schema form is this documented form: the one that has its first field.
      const json* form = nullptr;
      for (const json& candidate : forms) {
        if (schema_at(candidate, documented[f][0].path).first.is_object()) form = &candidate;
      }
      ASSERT_NE(form, nullptr) << request << ": no form with " << documented[f][0].path;
      std::set<std::string> documented_paths;
      for (const DocumentedField& field : documented[f]) {
        documented_paths.insert(field.path);
        const auto [node, parent] = schema_at(*form, field.path);
        ASSERT_TRUE(node.is_object()) << request << ": " << field.path << " is not in the schema";
        expect_documented_type(node, field.type, field.path);
        const json required = parent.value("required", json::array());
        const std::string leaf = field.path.substr(field.path.rfind('.') + 1);
        const bool in_required = std::find(required.begin(), required.end(), leaf) != required.end();
        if (!parent.empty()) EXPECT_EQ(in_required, field.required) << request << ": " << field.path << " required";
      }
      // No more fields than the format has, at every level (unknown fields are errors).
      std::function<void(const json&, const std::string&)> walk = [&](const json& node, const std::string& prefix) {
        if (node.value("type", "") == "array" && node.contains("items")) {
          walk(resolve(node.at("items")), prefix + "[i]");
          return;
        }
        if (node.value("type", "") != "object") return;
        EXPECT_EQ(node.value("additionalProperties", json(true)), json(false)) << request << ": " << prefix;
        const json properties = node.value("properties", json::object());
        for (const auto& [key, child] : properties.items()) {
          const std::string path = prefix.empty() ? key : prefix + "." + key;
          const json resolved = resolve(child);
          const bool documented_here = documented_paths.contains(path);
          bool documented_below = false;
          for (const std::string& p : documented_paths) documented_below |= p.starts_with(path + ".") || p.starts_with(path + "[i].");
          EXPECT_TRUE(documented_here || documented_below) << request << ": " << path << " is not in docs/scene-format.md";
          walk(resolved, path);
        }
      };
      walk(*form, "");
    }
  }
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
