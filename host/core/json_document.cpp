#include <seamcl/core/json_document.h>

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace seamcl {

nlohmann::json parse_json_document(std::string_view text, int max_depth) {
  const size_t nul = text.find('\0');
  if (nul != std::string_view::npos)
    throw std::invalid_argument("a NUL byte at offset " + std::to_string(nul) + " (nothing after it would be read)");
  std::vector<std::set<std::string>> open_objects;  // the keys of each object being read, innermost last
  std::string refused;
  const auto callback = [&](int depth, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    if (!refused.empty()) return false;
    if (max_depth > 0 && depth > max_depth) {
      refused = "nested deeper than " + std::to_string(max_depth) + " levels";
      return false;
    }
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start) {
      open_objects.emplace_back();
    } else if (event == Event::object_end) {
      open_objects.pop_back();
    } else if (event == Event::key && !open_objects.back().insert(parsed.get<std::string>()).second) {
      const std::string key = parsed.get<std::string>();
      constexpr size_t kShown = 64;  // a hostile key does not make the message long
      refused = "key '" + key.substr(0, kShown) + (key.size() > kShown ? "..." : "") + "' is given twice in one object";
      return false;
    }
    return true;
  };
  nlohmann::json document = nlohmann::json::parse(text, callback);
  if (!refused.empty()) throw std::invalid_argument(refused);
  return document;
}

}  // namespace seamcl
