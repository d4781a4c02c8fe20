// Two kinds of failure: bad input from a user (exit code 2, HTTP 4xx), which names the field at
// fault, and everything else (exit code 1, HTTP 5xx).
#pragma once
#include <stdexcept>
#include <string>

namespace seamcl {

class InputError : public std::runtime_error {
 public:
  InputError(std::string field, const std::string& message)
      : std::runtime_error(field + ": " + message), field_(std::move(field)) {}
  const std::string& field() const { return field_; }

 private:
  std::string field_;
};

}  // namespace seamcl
