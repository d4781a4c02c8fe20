// A request that needs more memory than its budget: bad input in the sense of InputError (the
// request, not the program, is at fault; exit code 2, and an HTTP service answers 413), with
// the bytes needed and the limit for the message and the status.
#pragma once
#include <cstddef>
#include <string>
#include <utility>

#include <seamcl/core/input_error.h>

namespace seamcl {

class OverBudget : public InputError {
 public:
  OverBudget(std::string field, const std::string& what, size_t needed_bytes, size_t limit_bytes)
      : InputError(std::move(field), what + " needs " + std::to_string(needed_bytes) + " bytes, over the limit of " +
                                         std::to_string(limit_bytes)),
        needed_bytes_(needed_bytes),
        limit_bytes_(limit_bytes) {}
  size_t needed_bytes() const { return needed_bytes_; }
  size_t limit_bytes() const { return limit_bytes_; }

 private:
  size_t needed_bytes_;
  size_t limit_bytes_;
};

}  // namespace seamcl
