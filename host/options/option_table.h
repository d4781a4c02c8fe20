// An option declared once: its key, type, bounds, default and help. Every front end derives from
// these declarations: the command line's flags and --help (cli/option_flags.h), the JSON parser and
// writer of each request (render_options.h, the jobs), the methods document and the OpenAPI
// document the service serves, the viewer's controls (built from the methods document) and the
// Python keywords. A new option is one entry in a table, not a change in each of them.
#pragma once
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace seamcl {

enum class OptionType {
  Integer,  // a JSON integer (4.0 is taken as 4) within [minimum, maximum], or one of `integers`
  Number,   // a finite JSON number within [minimum, maximum]
  Boolean,  // true or false; a flag on the command line
  String,   // a non-empty string
  Choice,   // one of `choices`
  Size,     // "WIDTHxHEIGHT", each side within [minimum, maximum]
  List,     // a comma list ("a,b") or a JSON array of `choices` (or of `integers` when given)
};

struct OptionSpec {
  std::string key;   // the JSON key and HTTP field; the command line's flag is --key with '-' for '_'
  OptionType type = OptionType::String;
  std::string help;  // one sentence: --help, the methods document, the OpenAPI description
  // The value when the option is left out; null where leaving it out means something no value
  // says ("the scene's own camera", "no displacement"): `absent` says what in words.
  nlohmann::json default_value;
  std::string absent;
  double minimum = 0, maximum = 0;    // Integer, Number, Size (each side)
  std::vector<std::string> choices;   // Choice, List
  std::vector<int> integers;          // Integer or List restricted to these values (msaa)
  std::string pattern;                // Size, List: the regular expression of its text form
  std::string noun;                   // Choice: what one value is called in errors; the key if empty
};

using OptionTable = std::vector<OptionSpec>;

// An option of `key` and `type` with its help; the other fields are set after.
OptionSpec make_option(std::string key, OptionType type, std::string help);

// The spec of `key` in `table`, or null.
const OptionSpec* find_option(const OptionTable& table, std::string_view key);

// `value` checked against `spec` and normalised (4.0 -> 4; a List as a JSON array of its items);
// InputError(spec.key) naming what was expected otherwise.
nlohmann::json checked_option(const OptionSpec& spec, const nlohmann::json& value);

// The command line's text of an option as the JSON value the parsers take ("4" -> 4, "-1.5" ->
// -1.5, a List's comma text as is); InputError(spec.key) when it is not of the option's type.
nlohmann::json option_from_text(const OptionSpec& spec, const std::string& text);

// The option as a JSON schema (type, enum, minimum, maximum, pattern, default, description): the
// methods document's and the OpenAPI document's form.
nlohmann::json option_schema(const OptionSpec& spec);
// Every option of the table, key -> option_schema.
nlohmann::json options_schema(const OptionTable& table);

// "--guard-band" for "guard_band".
std::string option_flag(const OptionSpec& spec);
// The --help line: the help sentence, the choices or bounds, and the default in brackets.
std::string option_help_line(const OptionSpec& spec);

// "a, b, c".
std::string joined_names(const std::vector<std::string>& names, const std::string& separator = ", ");

}  // namespace seamcl
