// The option tables (host/options/option_table.h) are the only declaration of each option: the
// parsers, to_json, the command line's flags and --help, the methods document and the OpenAPI
// document must all say what the table says.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/core/input_error.h>
#include <seamcl/jobs/compare_job.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/jobs/scene_domains.h>
#include <seamcl/options/option_domains.h>
#include <seamcl/options/option_table.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene_generators.h>
#include "api_documents.h"
#include "http_server.h"

using nlohmann::json;
using namespace seamcl;

namespace {

std::string field_of(const std::function<void()>& parse) {
  try {
    parse();
  } catch (const InputError& e) {
    return e.field();
  }
  return "";
}

std::string command_output(const std::string& command) {
  std::string out;
  const std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  char buffer[4096];
  while (pipe && std::fgets(buffer, sizeof buffer, pipe.get())) out += buffer;
  return out;
}

}  // namespace

TEST(OptionTable, EveryDefaultParsesAndIsWhatToJsonWrites) {
  const json defaults = to_json(RenderOptions{});
  for (const OptionSpec& spec : render_option_table()) {
    if (spec.default_value.is_null()) continue;
    SCOPED_TRACE(spec.key);
    const RenderOptions parsed = parse_render_options({{spec.key, spec.default_value}});
    EXPECT_EQ(to_json(parsed), defaults) << "the default of " << spec.key << " is not RenderOptions' own";
    if (defaults.contains(spec.key)) EXPECT_EQ(defaults.at(spec.key), spec.default_value);
  }
}

TEST(OptionTable, EveryKeyOfToJsonIsInTheTable) {
  RenderOptions options;
  options.frame = 3;
  options.displacement = DisplacementMethod::Zipper;
  options.texture = "t.ptx";
  const json written = to_json(options);
  for (const auto& [key, value] : written.items()) {
    EXPECT_NE(find_option(render_option_table(), key), nullptr) << key << " is written but not declared";
  }
  // And what to_json writes parses back to the same options.
  EXPECT_EQ(to_json(parse_render_options(to_json(options))), to_json(options));
}

TEST(OptionTable, BoundsAreEnforcedNamingTheKey) {
  for (const OptionSpec& spec : render_option_table()) {
    if (spec.type != OptionType::Integer && spec.type != OptionType::Number) continue;
    SCOPED_TRACE(spec.key);
    if (!spec.integers.empty()) {
      EXPECT_EQ(field_of([&] { parse_render_options({{spec.key, spec.integers.back() + 1}}); }), spec.key);
      continue;
    }
    EXPECT_EQ(field_of([&] { parse_render_options({{spec.key, spec.maximum + 1}}); }), spec.key);
    EXPECT_EQ(field_of([&] { parse_render_options({{spec.key, spec.minimum - 1}}); }), spec.key);
    EXPECT_EQ(field_of([&] { parse_render_options({{spec.key, "1"}}); }), spec.key);
  }
}

TEST(OptionTable, LodBiasIsANumberWithinFour) {
  const OptionSpec* spec = find_option(render_option_table(), "lod_bias");
  ASSERT_NE(spec, nullptr);
  EXPECT_EQ(spec->type, OptionType::Number);
  EXPECT_EQ(spec->minimum, -4.0);
  EXPECT_EQ(spec->maximum, 4.0);
  EXPECT_EQ(spec->default_value, 0.0);
  EXPECT_FLOAT_EQ(parse_render_options({{"lod_bias", -1.5}}).lod_bias, -1.5f);
  EXPECT_FLOAT_EQ(sampler_params(parse_render_options({{"lod_bias", 2.25}})).lod_bias, 2.25f);
  EXPECT_EQ(field_of([] { parse_render_options({{"lod_bias", 4.5}}); }), "lod_bias");
  EXPECT_EQ(field_of([] { parse_render_options({{"lod_bias", "1"}}); }), "lod_bias");
  EXPECT_EQ(field_of([] { parse_render_options({{"lod_bias", nullptr}}); }), "lod_bias");
  EXPECT_EQ(to_json(parse_render_options({{"lod_bias", 1}})).at("lod_bias"), 1.0);
}

TEST(OptionTable, TextOfTheCommandLineIsTypedByTheTable) {
  const OptionSpec& bias = *find_option(render_option_table(), "lod_bias");
  EXPECT_EQ(option_from_text(bias, "-1.5"), -1.5);
  EXPECT_EQ(field_of([&] { option_from_text(bias, "one"); }), "lod_bias");
  const OptionSpec& msaa = *find_option(render_option_table(), "msaa");
  EXPECT_EQ(option_from_text(msaa, "4"), 4);
  EXPECT_EQ(field_of([&] { option_from_text(msaa, "4x"); }), "msaa");
  // The forms a shell user writes, alike for both kinds; nothing beyond decimal text.
  EXPECT_EQ(option_from_text(bias, ".5"), 0.5);
  EXPECT_EQ(option_from_text(bias, "+1"), 1.0);
  EXPECT_EQ(option_from_text(bias, "-2e-1"), -0.2);
  EXPECT_EQ(option_from_text(msaa, "+4"), 4);
  EXPECT_EQ(option_from_text(msaa, "-4"), -4) << "typed here; the bounds are checked after";
  for (const char* text : {"0x10", "0x1p1", " 4", "4 ", "inf", "nan", "1e999", "", "+-1"}) {
    EXPECT_EQ(field_of([&] { option_from_text(bias, text); }), "lod_bias") << "'" << text << "'";
  }
  for (const char* text : {"+", "+-4", " 4", "0x4", "4.0", ""}) {
    EXPECT_EQ(field_of([&] { option_from_text(msaa, text); }), "msaa") << "'" << text << "'";
  }
}

TEST(OptionTable, CompareListsTakeCommaTextAndArraysAlike) {
  const OptionSpec& methods = *find_option(compare_option_table(), "methods");
  EXPECT_EQ(checked_option(methods, "discard, traverse-edges"), json({"discard", "traverse-edges"}));
  EXPECT_EQ(checked_option(methods, json({"clamp"})), json({"clamp"}));
  EXPECT_EQ(field_of([&] { checked_option(methods, "discard,,clamp"); }), "methods");
  EXPECT_EQ(field_of([&] { checked_option(methods, "bogus"); }), "methods");
  const OptionSpec& msaa = *find_option(compare_option_table(), "msaa");
  EXPECT_EQ(checked_option(msaa, 8), json({8}));
  EXPECT_EQ(checked_option(msaa, "1,16"), json({1, 16}));
  EXPECT_EQ(field_of([&] { checked_option(msaa, "3"); }), "msaa");
  // A compare takes every render option but method and msaa (a list there).
  for (const OptionSpec& spec : render_option_table()) {
    if (spec.key == "method" || spec.key == "msaa") continue;
    EXPECT_NE(find_option(compare_option_table(), spec.key), nullptr) << spec.key;
  }
  EXPECT_EQ(field_of([] { CompareJob job(json{{"method", "discard"}}); }), "method");
  EXPECT_EQ(field_of([] { CompareJob job(json{{"bogus", 1}}); }), "bogus");
  EXPECT_EQ(CompareJob(json{{"lod_bias", 1}}).entries().front().options.lod_bias, 1.0f);
}

// --help of render and compare: every option of the job's table as a flag, with its default.
TEST(OptionTable, HelpListsEveryOptionWithItsDefault) {
  for (const auto& [command, table] : {std::pair{std::string("render"), &render_job_option_table()},
                                       std::pair{std::string("compare"), &compare_option_table()}}) {
    const std::string help = command_output(std::string(SEAMCL_BINARY) + " " + command + " --help");
    for (const OptionSpec& spec : *table) {
      SCOPED_TRACE(command + " " + spec.key);
      EXPECT_NE(help.find(option_flag(spec)), std::string::npos);
      if (!spec.default_value.is_null() && spec.type != OptionType::Boolean) {
        const std::string line = option_help_line(spec);
        EXPECT_NE(help.find(line.substr(line.rfind('['))), std::string::npos) << "no default in --help for " << spec.key;
      }
    }
  }
}

// GET /v1/methods and the OpenAPI document describe every option as the table does.
TEST(OptionTable, DocumentsAreTheTable) {
  const json options = server::options_document({"paper"}, server::ServerOptions{});
  const json doc = json::parse(server::openapi_json());
  const json& render = doc.at("components").at("schemas").at("RenderRequest").at("properties");
  const json& compare = doc.at("components").at("schemas").at("CompareRequest").at("properties");
  std::set<std::string> query;
  for (const json& p : doc.at("paths").at("/v1/render").at("get").at("parameters")) query.insert(p.at("name"));
  for (const OptionSpec& spec : render_option_table()) {
    SCOPED_TRACE(spec.key);
    ASSERT_TRUE(options.contains(spec.key));
    ASSERT_TRUE(render.contains(spec.key));
    EXPECT_TRUE(query.count(spec.key));
    if (spec.key == "scene") continue;  // its own schema: a built-in name or an inline scene
    EXPECT_EQ(render.at(spec.key), option_schema(spec));
    EXPECT_EQ(options.at(spec.key).value("type", ""), option_schema(spec).at("type"));
    EXPECT_EQ(options.at(spec.key).value("default", json()), spec.default_value);
  }
  for (const OptionSpec& spec : compare_option_table()) {
    if (spec.key == "scene") continue;
    EXPECT_TRUE(compare.contains(spec.key)) << spec.key;
  }
  EXPECT_EQ(render.size(), render_option_table().size() + 1) << "RenderRequest has options the table does not declare";
}

// The option domains are declared in the table's rows: the cube and displacement options, each a
// key of the table, and the methods document lists them as the table does; the built-in scenes
// name the domains that act on them (the viewer shows and sends those options there only).
TEST(OptionTable, DomainsAreTheTablesAndScenesNameTheirs) {
  using Domains = std::map<std::string, std::vector<std::string>>;
  EXPECT_EQ(render_option_domains(),
            (Domains{{"cube", {"cube_method"}}, {"displacement", {"displacement_map", "displacement_method", "tessellation", "tessellation_pixels", "displacement_level", "displacement_normals"}}}));
  for (const auto& [domain, keys] : render_option_domains())
    for (const std::string& key : keys) EXPECT_NE(find_option(render_option_table(), key), nullptr) << key;
  const json methods = server::methods_document(generate_scene("quad2", {}), server::ServerOptions{});
  EXPECT_EQ(methods.at("domains"), json(render_option_domains()));
  EXPECT_EQ(scene_option_domains(generate_scene("envmap", {})), std::vector<std::string>{"cube"});
  EXPECT_EQ(scene_option_domains(generate_scene("displaced", {})), std::vector<std::string>{"displacement"});
  EXPECT_TRUE(scene_option_domains(generate_scene("quad2", {})).empty());
}
