#include <seamcl/options/option_table.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

using nlohmann::json;

// A client's value quoted in an error message, cut so that a huge value cannot make a huge answer.
std::string quoted(const json& value) {
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > 80) text = text.substr(0, 77) + "...";
  return text;
}

std::string number_text(double value) {
  std::ostringstream out;
  out << std::setprecision(15) << value;
  return out.str();
}

std::string range_text(const OptionSpec& spec) {
  return number_text(spec.minimum) + ".." + number_text(spec.maximum);
}

// "1, 2, 4, 8 or 16".
std::string integers_text(const std::vector<int>& values) {
  std::string out;
  for (size_t i = 0; i < values.size(); ++i)
    out += (i == 0 ? "" : i + 1 == values.size() ? " or " : ", ") + std::to_string(values[i]);
  return out;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  for (const std::string& n : names)
    if (n == name) return true;
  return false;
}

bool contains(const std::vector<int>& values, long long value) {
  for (int v : values)
    if (v == value) return true;
  return false;
}

// An integer from a JSON number: 4 and 4.0 but not 4.5, NaN or a string (a JSON client may send
// any number form).
bool integer_of(const json& value, long long& out) {
  if (value.is_number_integer()) {
    out = value.get<long long>();
    return true;
  }
  if (value.is_number_float()) {
    const double d = value.get<double>();
    if (std::isfinite(d) && d == std::floor(d) && std::fabs(d) < 9.0e15) {
      out = static_cast<long long>(d);
      return true;
    }
  }
  return false;
}

json checked_integer(const OptionSpec& spec, const json& value) {
  long long v = 0;
  if (!spec.integers.empty()) {
    if (!integer_of(value, v) || !contains(spec.integers, v))
      throw InputError(spec.key, "must be the integer " + integers_text(spec.integers) + ", got " + quoted(value));
    return v;
  }
  if (!integer_of(value, v))
    throw InputError(spec.key, "must be an integer in " + range_text(spec) + ", got " + quoted(value));
  if (static_cast<double>(v) < spec.minimum || static_cast<double>(v) > spec.maximum)
    throw InputError(spec.key, "must be in " + range_text(spec) + ", got " + quoted(value));
  return v;
}

json checked_number(const OptionSpec& spec, const json& value) {
  if (!value.is_number() || !std::isfinite(value.get<double>()))
    throw InputError(spec.key, "must be a number in " + range_text(spec) + ", got " + quoted(value));
  const double v = value.get<double>();
  if (v < spec.minimum || v > spec.maximum) throw InputError(spec.key, "must be in " + range_text(spec) + ", got " + quoted(value));
  return v;
}

std::string checked_string(const OptionSpec& spec, const json& value) {
  if (!value.is_string()) throw InputError(spec.key, "must be a string, got " + quoted(value));
  const std::string text = value.get<std::string>();
  if (text.empty()) throw InputError(spec.key, "must not be empty");
  return text;
}

json checked_size(const OptionSpec& spec, const json& value) {
  const std::string text = checked_string(spec, value);
  const size_t x = text.find('x');
  auto side = [&](std::string_view part) {
    long long v = 0;
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (part.empty() || error != std::errc() || end != part.data() + part.size() || static_cast<double>(v) < spec.minimum ||
        static_cast<double>(v) > spec.maximum)
      throw InputError(spec.key, "must be WIDTHxHEIGHT with each side in " + range_text(spec) + ", got " + quoted(value));
    return v;
  };
  if (x == std::string::npos) side("");
  const std::string_view view(text);
  return std::to_string(side(view.substr(0, x))) + "x" + std::to_string(side(view.substr(x + 1)));
}

// A comma list's items, each trimmed; empty items refused.
std::vector<std::string> list_items(const OptionSpec& spec, const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const size_t a = item.find_first_not_of(" \t"), b = item.find_last_not_of(" \t");
    if (a == std::string::npos) throw InputError(spec.key, "empty item in list '" + text + "'");
    items.push_back(item.substr(a, b - a + 1));
  }
  if (items.empty() || text.back() == ',') throw InputError(spec.key, "must be a comma list, got '" + text + "'");
  return items;
}

json checked_list(const OptionSpec& spec, const json& value) {
  const bool integers = !spec.integers.empty();
  const std::string expected = integers ? "a comma list string (\"1,4\"), an integer or an array of integers"
                                        : "a comma list string (\"discard,traverse\") or an array of strings";
  json items = json::array();
  if (value.is_string()) {
    for (const std::string& item : list_items(spec, value.get<std::string>())) {
      if (!integers) {
        items.push_back(item);
        continue;
      }
      // "+4" and "004" are 4, as a shell user or a C parser reads them.
      const std::string_view digits = item[0] == '+' ? std::string_view(item).substr(1) : std::string_view(item);
      long long v = 0;
      const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
      if (digits.empty() || error != std::errc() || end != digits.data() + digits.size())
        throw InputError(spec.key, "not an integer: '" + item + "'");
      items.push_back(v);
    }
  } else if (integers && value.is_number_integer()) {
    items.push_back(value);
  } else if (value.is_array() && !value.empty()) {
    for (const json& item : value) {
      if (integers ? !item.is_number_integer() : !item.is_string())
        throw InputError(spec.key, "must be " + expected + ", got the item " + quoted(item));
      items.push_back(item);
    }
  } else {
    throw InputError(spec.key, "must be " + expected + ", got " + quoted(value));
  }
  for (const json& item : items) {
    if (integers && !contains(spec.integers, item.get<long long>()))
      throw InputError(spec.key, "each item must be " + integers_text(spec.integers) + ", got " + quoted(item));
    if (!integers && !spec.choices.empty() && !contains(spec.choices, item.get<std::string>()))
      throw InputError(spec.key, "unknown item '" + item.get<std::string>() + "' (known: " + joined_names(spec.choices) + ")");
  }
  return items;
}

}  // namespace

std::string joined_names(const std::vector<std::string>& names, const std::string& separator) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : separator) + n;
  return out;
}

OptionSpec make_option(std::string key, OptionType type, std::string help) {
  OptionSpec spec;
  spec.key = std::move(key);
  spec.type = type;
  spec.help = std::move(help);
  return spec;
}

const OptionSpec* find_option(const OptionTable& table, std::string_view key) {
  for (const OptionSpec& spec : table)
    if (spec.key == key) return &spec;
  return nullptr;
}

json checked_option(const OptionSpec& spec, const json& value) {
  switch (spec.type) {
    case OptionType::Integer: return checked_integer(spec, value);
    case OptionType::Number: return checked_number(spec, value);
    case OptionType::Boolean:
      if (!value.is_boolean()) throw InputError(spec.key, "must be true or false, got " + quoted(value));
      return value;
    case OptionType::String: return checked_string(spec, value);
    case OptionType::Choice: {
      const std::string name = checked_string(spec, value);
      if (!contains(spec.choices, name))
        throw InputError(spec.key, "unknown " + (spec.noun.empty() ? spec.key : spec.noun) + " '" + name + "' (known: " + joined_names(spec.choices) + ")");
      return name;
    }
    case OptionType::Size: return checked_size(spec, value);
    case OptionType::List: return checked_list(spec, value);
  }
  throw std::logic_error("option type not handled");
}

json option_from_text(const OptionSpec& spec, const std::string& text) {
  switch (spec.type) {
    case OptionType::Integer: {
      // A plus sign as a number may carry one; from_chars takes none.
      const std::string_view digits =
          text.size() > 1 && text[0] == '+' && text[1] != '-' ? std::string_view(text).substr(1) : std::string_view(text);
      long long v = 0;
      const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
      if (text.empty() || error != std::errc() || end != digits.data() + digits.size())
        throw InputError(spec.key, "must be an integer, got '" + text + "'");
      return v;
    }
    case OptionType::Number: {
      // strtod rather than from_chars: Debian's libstdc++ 12 parses floats with both, but strtod
      // also takes the forms a shell user writes (".5", "+1"); decimal forms only (strtod would
      // also read hexadecimal floats and skip leading blanks).
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v) ||
          text.find_first_not_of("0123456789+-.eE") != std::string::npos)
        throw InputError(spec.key, "must be a number, got '" + text + "'");
      return v;
    }
    case OptionType::Boolean:
      if (text == "true") return true;
      if (text == "false") return false;
      throw InputError(spec.key, "must be true or false, got '" + text + "'");
    default: return text;
  }
}

// The text form of a list of `spec`'s items: each item one of its names (longest first, so that
// "traverse-edges" is not read as "traverse"), blanks around commas allowed.
std::string list_pattern(const OptionSpec& spec) {
  std::vector<std::string> names = spec.choices;
  for (int v : spec.integers) names.push_back(std::to_string(v));
  std::stable_sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) { return a.size() > b.size(); });
  // An integer item may carry a plus sign and leading zeros, as the parser reads them.
  std::string item = spec.integers.empty() ? "(?:" : "\\+?0*(?:";
  for (size_t i = 0; i < names.size(); ++i) {
    if (i) item += "|";
    for (char c : names[i]) {
      if (std::string_view(".^$|()[]{}*+?\\").find(c) != std::string_view::npos) item += '\\';
      item += c;
    }
  }
  item += ")";
  const std::string blank = "[ \\t]*";
  return "^" + blank + item + blank + "(?:," + blank + item + blank + ")*$";
}

json option_schema(const OptionSpec& spec) {
  json schema = json::object();
  switch (spec.type) {
    case OptionType::Integer:
      schema["type"] = "integer";
      if (!spec.integers.empty()) {
        schema["enum"] = spec.integers;
      } else {
        schema["minimum"] = static_cast<long long>(spec.minimum);
        schema["maximum"] = static_cast<long long>(spec.maximum);
      }
      break;
    case OptionType::Number:
      schema["type"] = "number";
      schema["minimum"] = spec.minimum;
      schema["maximum"] = spec.maximum;
      break;
    case OptionType::Boolean: schema["type"] = "boolean"; break;
    case OptionType::String:
      schema["type"] = "string";
      schema["minLength"] = 1;
      break;
    case OptionType::Choice:
      schema["type"] = "string";
      schema["enum"] = spec.choices;
      break;
    case OptionType::Size:
      schema["type"] = "string";
      schema["pattern"] = spec.pattern;
      schema["minimum"] = static_cast<long long>(spec.minimum);
      schema["maximum"] = static_cast<long long>(spec.maximum);
      break;
    case OptionType::List: {
      // A comma list string or an array (an integer list also takes one integer).
      json item = spec.integers.empty() ? json{{"type", "string"}} : json{{"type", "integer"}, {"enum", spec.integers}};
      if (!spec.choices.empty()) item["enum"] = spec.choices;
      json forms = json::array({{{"type", "string"}, {"pattern", spec.pattern.empty() ? list_pattern(spec) : spec.pattern}},
                                {{"type", "array"}, {"minItems", 1}, {"items", item}}});
      if (!spec.integers.empty()) forms.push_back(item);
      schema["oneOf"] = forms;
      break;
    }
  }
  if (!spec.default_value.is_null()) schema["default"] = spec.default_value;
  std::string description = spec.help;
  if (!spec.absent.empty()) description += " (absent: " + spec.absent + ")";
  schema["description"] = description;
  return schema;
}

json options_schema(const OptionTable& table) {
  json out = json::object();
  for (const OptionSpec& spec : table) out[spec.key] = option_schema(spec);
  return out;
}

std::string option_flag(const OptionSpec& spec) {
  std::string flag = "--" + spec.key;
  for (char& c : flag)
    if (c == '_') c = '-';
  return flag;
}

std::string option_help_line(const OptionSpec& spec) {
  std::string line = spec.help;
  if (spec.type == OptionType::Choice || (spec.type == OptionType::List && !spec.choices.empty()))
    line += ": " + joined_names(spec.choices);
  else if (!spec.integers.empty())
    line += ": " + integers_text(spec.integers);
  else if (spec.type == OptionType::Integer || spec.type == OptionType::Number)
    line += ", " + range_text(spec);
  if (!spec.default_value.is_null() && spec.type != OptionType::Boolean) {
    const json& d = spec.default_value;
    std::string text = d.is_string() ? d.get<std::string>() : d.dump();
    if (d.is_array()) {
      text.clear();
      for (const json& item : d) text += (text.empty() ? "" : ",") + (item.is_string() ? item.get<std::string>() : item.dump());
    }
    line += " [" + text + "]";
  } else if (!spec.absent.empty()) {
    line += " [" + spec.absent + "]";
  }
  return line;
}

}  // namespace seamcl
