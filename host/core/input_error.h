// Two kinds of failure: bad input from a user (exit code 2, HTTP 4xx), which names the field at
// fault, and everything else (exit code 1, HTTP 5xx).
#pragma once
#include <cstddef>
#include <stdexcept>
#include <string>

namespace seamcl {

// A longer message keeps its first and last kMaxInputErrorMessage / 2 bytes (or fewer, to cut
// between UTF-8 sequences): some carry a piece of the input (the JSON parser's messages quote a
// whole number, however many digits a hostile file gives it). Both ends stay, so a quoted value
// keeps its closing quote (the service cuts quoted values further, server/request_hygiene.cpp).
inline constexpr size_t kMaxInputErrorMessage = 1024;

class InputError : public std::runtime_error {
 public:
  InputError(std::string field, const std::string& message)
      : std::runtime_error(field + ": " + bounded(message)), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  static std::string bounded(const std::string& message) {
    if (message.size() <= kMaxInputErrorMessage) return message;
    // Cut between UTF-8 sequences, never inside one (a continuation byte is 10xxxxxx).
    const auto continues = [&](size_t i) { return (static_cast<unsigned char>(message[i]) & 0xC0u) == 0x80u; };
    size_t head = kMaxInputErrorMessage / 2, tail = message.size() - kMaxInputErrorMessage / 2;
    while (head > 0 && continues(head)) --head;
    while (tail < message.size() && continues(tail)) ++tail;
    return message.substr(0, head) + " [" + std::to_string(tail - head) + " bytes cut] " + message.substr(tail);
  }

  std::string field_;
};

}  // namespace seamcl
