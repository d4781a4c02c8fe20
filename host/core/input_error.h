// Two kinds of failure: bad input from a user (exit code 2, HTTP 4xx), which names the field at
// fault, and everything else (exit code 1, HTTP 5xx).
#pragma once
#include <cstddef>
#include <stdexcept>
#include <string>

namespace seamcl {

// The message is cut to kMaxInputErrorMessage characters: some come with a piece of the input
// (the JSON parser's quote a whole number, however many digits a hostile file gives it).
inline constexpr size_t kMaxInputErrorMessage = 1024;

class InputError : public std::runtime_error {
 public:
  InputError(std::string field, const std::string& message)
      : std::runtime_error(field + ": " + bounded(message)), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  static std::string bounded(const std::string& message) {
    if (message.size() <= kMaxInputErrorMessage) return message;
    return message.substr(0, kMaxInputErrorMessage) + "... (" + std::to_string(message.size() - kMaxInputErrorMessage) +
           " characters more)";
  }

  std::string field_;
};

}  // namespace seamcl
