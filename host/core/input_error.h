// Two kinds of failure: bad input from a user (exit code 2, HTTP 4xx), which names the field at
// fault, and everything else (exit code 1, HTTP 5xx).
#pragma once
#include <cstddef>
#include <stdexcept>
#include <string>

namespace seamcl {

// A message longer than kMaxInputErrorMessage keeps its first and last kMaxInputErrorMessage / 4
// bytes (or up to 3 fewer, to cut between UTF-8 sequences): some carry a piece of the input (the
// JSON parser's messages quote a whole number, however many digits a hostile file gives it). Both
// ends stay, so a quoted value keeps its closing quote (the service cuts quoted values further,
// server/request_hygiene.cpp); what is kept is half the bound, so that a message wrapped again in
// another InputError's (a path or a field put before it) is not cut a second time.
inline constexpr size_t kMaxInputErrorMessage = 2048;

class InputError : public std::runtime_error {
 public:
  InputError(std::string field, const std::string& message)
      : std::runtime_error(field + ": " + bounded(message)), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  static std::string bounded(const std::string& message) {
    if (message.size() <= kMaxInputErrorMessage) return message;
    // Cut between UTF-8 sequences, never inside one (a continuation byte is 10xxxxxx; a sequence
    // has at most 3 of them, and invalid text moves a cut no further).
    const auto continues = [&](size_t i) { return (static_cast<unsigned char>(message[i]) & 0xC0u) == 0x80u; };
    size_t head = kMaxInputErrorMessage / 4, tail = message.size() - kMaxInputErrorMessage / 4;
    for (int step = 0; step < 3 && continues(head); ++step) --head;
    for (int step = 0; step < 3 && tail < message.size() && continues(tail); ++step) ++tail;
    return message.substr(0, head) + " [" + std::to_string(tail - head) + " bytes cut] " + message.substr(tail);
  }

  std::string field_;
};

}  // namespace seamcl
