#include <seamcl/core/json_document.h>

#include <functional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace seamcl {
namespace {

using nlohmann::json;

// Builds the document from the parser's events (nlohmann::json::sax_parse), refusing a key given
// twice in one object and nesting past max_depth. Not nlohmann's callback parser: in 3.11 it
// scans an array's elements each time an object inside it ends, so a 1 MiB body of `{}`s took
// 46 s; this builder does constant work per event. With a sink, the root must be an array and
// each of its elements is handed over when read instead of kept.
class CheckedDocumentBuilder {
 public:
  using Sink = std::function<void(json&&)>;
  CheckedDocumentBuilder(json& root, int max_depth, const Sink* sink = nullptr, size_t max_elements = 0)
      : root_(root), max_depth_(max_depth), sink_(sink), max_elements_(max_elements) {}

  bool null() { return add(nullptr); }
  bool boolean(bool value) { return add(value); }
  bool number_integer(json::number_integer_t value) { return add(value); }
  bool number_unsigned(json::number_unsigned_t value) { return add(value); }
  bool number_float(json::number_float_t value, const json::string_t&) { return add(value); }
  bool string(json::string_t& value) { return add(std::move(value)); }
  bool binary(json::binary_t& value) { return add(json::binary(std::move(value))); }

  bool start_object(std::size_t) {
    if (root_not_array_) return true;
    if (!open(json::object())) return false;
    if (!root_not_array_) keys_.emplace_back();
    return true;
  }
  bool key(json::string_t& key) {
    if (root_not_array_) return true;
    if (too_deep()) return false;
    if (!keys_.back().insert(key).second) {
      constexpr size_t kShown = 64;  // a hostile key does not make the message long
      refused_ = "key '" + key.substr(0, kShown) + (key.size() > kShown ? "..." : "") + "' is given twice in one object";
      return false;
    }
    pending_key_ = std::move(key);
    return true;
  }
  bool end_object() {
    if (root_not_array_) return true;
    keys_.pop_back();
    open_.pop_back();
    return element_done();
  }
  bool start_array(std::size_t) { return root_not_array_ || open(json::array()); }
  bool end_array() {
    if (root_not_array_) return true;
    open_.pop_back();
    return element_done();
  }

  // The parser's own exception, thrown with its type (parse_error, out_of_range), as parse() does.
  template <class Exception>
  bool parse_error(std::size_t, const std::string&, const Exception& error) {
    throw error;
  }

  const std::string& refused() const { return refused_; }
  bool root_not_array() const { return root_not_array_; }
  bool too_many_elements() const { return too_many_elements_; }

 private:
  // As the callback parser counted depth: an event inside more than max_depth containers.
  bool too_deep() {
    if (max_depth_ <= 0 || open_.size() <= static_cast<size_t>(max_depth_)) return false;
    refused_ = "nested deeper than " + std::to_string(max_depth_) + " levels";
    return true;
  }

  // The value's place: the root, the end of the open array, or the open object's pending key.
  // Pointers to open containers stay valid: an array grows only after its open child closes.
  // nullptr: the value is not kept. With a sink, a root that is not an array starts the rest of
  // the text being read for its syntax alone (a syntax error is still the parser's to report), and
  // an element past max_elements is refused.
  json* place(json&& value) {
    if (open_.empty()) {
      if (sink_ != nullptr && !value.is_array()) {
        root_not_array_ = true;
        return nullptr;
      }
      root_ = std::move(value);
      return &root_;
    }
    if (sink_ != nullptr && open_.size() == 1 && elements_ == max_elements_) {
      too_many_elements_ = true;
      return nullptr;
    }
    json& parent = *open_.back();
    if (parent.is_array()) {
      parent.push_back(std::move(value));
      return &parent.back();
    }
    json& slot = parent[pending_key_];
    slot = std::move(value);
    return &slot;
  }

  bool add(json&& value) {
    if (root_not_array_) return true;
    if (too_deep()) return false;
    if (place(std::move(value)) == nullptr) return root_not_array_;
    return element_done();
  }

  bool open(json&& container) {
    if (too_deep()) return false;
    json* placed = place(std::move(container));
    if (placed == nullptr) return root_not_array_;
    open_.push_back(placed);
    return true;
  }

  // With a sink, a value just completed directly in the root array is handed over and dropped.
  bool element_done() {
    if (sink_ == nullptr || open_.size() != 1) return true;
    json::array_t& elements = root_.get_ref<json::array_t&>();
    json element = std::move(elements.back());
    elements.pop_back();
    ++elements_;
    (*sink_)(std::move(element));
    return true;
  }

  json& root_;
  int max_depth_;
  const Sink* sink_;
  size_t max_elements_;
  size_t elements_ = 0;
  bool root_not_array_ = false;
  bool too_many_elements_ = false;
  std::vector<json*> open_;                  // the containers being read, innermost last
  std::vector<std::set<std::string>> keys_;  // the keys of each open object, innermost last
  std::string pending_key_;
  std::string refused_;
};

// Runs the parser's events into builder; whether it read the whole text.
bool run_parser(std::string_view text, CheckedDocumentBuilder& builder) {
  const size_t nul = text.find('\0');
  if (nul != std::string_view::npos)
    throw std::invalid_argument("a NUL byte at offset " + std::to_string(nul) + " (nothing after it would be read)");
  return json::sax_parse(text, &builder);
}

}  // namespace

nlohmann::json parse_json_document(std::string_view text, int max_depth) {
  json document;
  CheckedDocumentBuilder builder(document, max_depth);
  const bool whole = run_parser(text, builder);
  if (!builder.refused().empty()) throw std::invalid_argument(builder.refused());
  if (!whole) throw std::logic_error("parse_json_document: the parser stopped without a reason");
  return document;
}

bool parse_json_array_elements(std::string_view text, size_t max_elements,
                               const std::function<void(nlohmann::json&&)>& element, int max_depth) {
  json root;
  CheckedDocumentBuilder builder(root, max_depth, &element, max_elements);
  const bool whole = run_parser(text, builder);
  if (builder.too_many_elements()) throw std::length_error("more than " + std::to_string(max_elements) + " elements");
  if (!builder.refused().empty()) throw std::invalid_argument(builder.refused());
  if (!whole) throw std::logic_error("parse_json_array_elements: the parser stopped without a reason");
  return !builder.root_not_array();
}

}  // namespace seamcl
