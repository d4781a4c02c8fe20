// Two kinds of failure: bad input from a user (exit code 2, HTTP 4xx), which names the field at
// fault, and everything else (exit code 1, HTTP 5xx).
#pragma once
#include <cstddef>
#include <stdexcept>
#include <string>

namespace seamcl {

// A longer message keeps its first and last kMaxInputErrorMessage / 2 characters: some carry a
// piece of the input (the JSON parser's messages quote a whole number, however many digits a
// hostile file gives it). Both ends stay, so a quoted value keeps its closing quote (the service
// cuts quoted values further, server/request_hygiene.cpp).
inline constexpr size_t kMaxInputErrorMessage = 1024;

class InputError : public std::runtime_error {
 public:
  InputError(std::string field, const std::string& message)
      : std::runtime_error(field + ": " + bounded(message)), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  static std::string bounded(const std::string& message) {
    if (message.size() <= kMaxInputErrorMessage) return message;
    constexpr size_t kEnd = kMaxInputErrorMessage / 2;
    return message.substr(0, kEnd) + " [" + std::to_string(message.size() - 2 * kEnd) + " characters cut] " +
           message.substr(message.size() - kEnd);
  }

  std::string field_;
};

}  // namespace seamcl
