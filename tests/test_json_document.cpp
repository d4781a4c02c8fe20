// parse_json_document: the document nlohmann::json::parse gives, with a repeated key, a NUL byte
// and nesting past a bound refused, in one pass over the text.
#include <gtest/gtest.h>

#include <seamcl/core/json_document.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace {

std::string refusal_of(const std::string& text, int max_depth = 0) {
  try {
    seamcl::parse_json_document(text, max_depth);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(JsonDocument, BuildsWhatTheLibraryParserBuilds) {
  for (const char* text :
       {"null", "true", "-0", "18446744073709551615", "-9223372036854775808", "1.5e300", "\"\\u00e9\\n\"", "[]", "{}",
        R"({"a": [1, {"b": [[], {}], "c": null}, "x"], "d": {"e": {"f": [true, false, 2.5]}}, "g": ""})",
        R"([[[[1]]], {"k": [{"k": [{"k": 0}]}]}, -1, 0.1])"}) {
    // dump() too: == takes -0 for 0.0 and an integer for the equal float.
    EXPECT_EQ(seamcl::parse_json_document(text).dump(), nlohmann::json::parse(text).dump()) << text;
    EXPECT_EQ(seamcl::parse_json_document(text).type(), nlohmann::json::parse(text).type()) << text;
  }
  // An array of many objects (a hostile body's shape): every element kept, in order.
  std::string many = "{\"x\": [";
  for (int i = 0; i < 200000; ++i) many += (i ? ",{\"i\":" : "{\"i\":") + std::to_string(i) + "}";
  many += "]}";
  const nlohmann::json parsed = seamcl::parse_json_document(many);
  ASSERT_EQ(parsed.at("x").size(), 200000u);
  EXPECT_EQ(parsed.at("x").at(123456).at("i"), 123456);
  EXPECT_EQ(parsed.dump(), nlohmann::json::parse(many).dump());
}

TEST(JsonDocument, RefusesARepeatedKeyAtAnyDepthButNotAcrossObjects) {
  EXPECT_EQ(refusal_of(R"({"a": 1, "a": 2})"), "key 'a' is given twice in one object");
  EXPECT_EQ(refusal_of(R"([{"b": {"c": 1, "c": 1}}])"), "key 'c' is given twice in one object");
  EXPECT_EQ(refusal_of(R"({"a": {"a": 1}, "b": [{"a": 1}, {"a": 2}]})"), "") << "the same key in different objects";
  const std::string long_key(5000, 'k');
  const std::string message = refusal_of("{\"" + long_key + "\": 1, \"" + long_key + "\": 2}");
  EXPECT_EQ(message, "key '" + long_key.substr(0, 64) + "...' is given twice in one object");
}

TEST(JsonDocument, RefusesNestingPastTheBoundOnly) {
  EXPECT_EQ(refusal_of(R"({"a": 1})", 1), "");
  EXPECT_EQ(refusal_of("[[]]", 1), "") << "an empty container holds no event deeper than itself";
  EXPECT_EQ(refusal_of(R"({"a": {"b": 1}})", 1), "nested deeper than 1 levels");
  EXPECT_EQ(refusal_of("[[1]]", 1), "nested deeper than 1 levels");
  EXPECT_EQ(refusal_of("[[[1]]]", 3), "");
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  EXPECT_EQ(refusal_of(deep, 32), "nested deeper than 32 levels");
  EXPECT_EQ(seamcl::parse_json_document(deep).size(), 1u) << "no bound: parsed without recursion";
}

TEST(JsonDocument, KeepsTheParsersOwnErrorsAndRefusesANul) {
  EXPECT_THROW(seamcl::parse_json_document(R"({"a": [1, 2)"), nlohmann::json::parse_error);
  EXPECT_THROW(seamcl::parse_json_document("{} {}"), nlohmann::json::parse_error) << "text after the document";
  EXPECT_THROW(seamcl::parse_json_document("1e309"), nlohmann::json::out_of_range);
  EXPECT_THROW(seamcl::parse_json_document(""), nlohmann::json::parse_error);
  EXPECT_EQ(refusal_of(std::string("{}\0{", 4)), "a NUL byte at offset 2 (nothing after it would be read)");
}

TEST(JsonDocument, ArrayElementsAreHandedOverInOrderUpToTheLimit) {
  std::vector<nlohmann::json> seen;
  const auto keep = [&](nlohmann::json&& element) { seen.push_back(std::move(element)); };
  const std::string text = R"([1, {"a": [2, {"b": 3}]}, [], [[4]], "five", null])";
  ASSERT_TRUE(seamcl::parse_json_array_elements(text, 6, keep));
  EXPECT_EQ(nlohmann::json(seen).dump(), nlohmann::json::parse(text).dump());

  seen.clear();
  EXPECT_THROW(seamcl::parse_json_array_elements(text, 5, keep), std::length_error);
  EXPECT_EQ(seen.size(), 5u) << "refused before the element past the limit is read";

  seen.clear();
  EXPECT_FALSE(seamcl::parse_json_array_elements(R"({"a": [1, 2]})", 10, keep));
  EXPECT_FALSE(seamcl::parse_json_array_elements("7", 10, keep));
  EXPECT_FALSE(seamcl::parse_json_array_elements(R"({"a": {"a": 1, "a": 2}})", 10, keep))
      << "not an array: the rest read for its syntax only";
  EXPECT_TRUE(seen.empty());
  // A text that is not an array and not valid JSON either is the parser's error, as before.
  EXPECT_THROW(seamcl::parse_json_array_elements(R"({"face": 1)", 10, keep), nlohmann::json::parse_error);
  EXPECT_THROW(seamcl::parse_json_array_elements("5 5", 10, keep), nlohmann::json::parse_error);
  EXPECT_THROW(seamcl::parse_json_array_elements(R"({"a": 1} [)", 10, keep), nlohmann::json::parse_error);
  EXPECT_TRUE(seamcl::parse_json_array_elements("[]", 0, keep));

  // The checks of parse_json_document hold inside elements, and an element the caller refuses
  // stops the read there.
  EXPECT_THROW(seamcl::parse_json_array_elements(R"([{"a": 1, "a": 2}])", 10, keep), std::invalid_argument);
  EXPECT_THROW(seamcl::parse_json_array_elements("[[[1]]]", 10, keep, 2), std::invalid_argument);
  EXPECT_THROW(seamcl::parse_json_array_elements("[1, 2", 10, keep), nlohmann::json::parse_error);
  int handed = 0;
  const auto refuse_second = [&](nlohmann::json&&) {
    if (++handed == 2) throw std::runtime_error("second");
  };
  EXPECT_THROW(seamcl::parse_json_array_elements("[1, 2, 3]", 10, refuse_second), std::runtime_error);
  EXPECT_EQ(handed, 2);
}

}  // namespace
