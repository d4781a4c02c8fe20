// Long work (a compare, a bench, a reference) stopped on request: the caller's should_stop hook
// said so. Not a failure of the work or of its input, so neither an InputError nor a plain
// runtime_error: the HTTP service answers it with its own status and the CLI never sees one.
#pragma once
#include <functional>
#include <stdexcept>
#include <string>

namespace seamcl {

class Cancelled : public std::runtime_error {
 public:
  explicit Cancelled(const std::string& where) : std::runtime_error("cancelled " + where) {}
};

// Asked between units of work (renders, entries, repeats); true means stop now. Empty: never.
using ShouldStop = std::function<bool()>;

// Throws Cancelled("where") when should_stop is set and returns true.
inline void throw_if_stopped(const ShouldStop& should_stop, const std::string& where) {
  if (should_stop && should_stop()) throw Cancelled(where);
}

}  // namespace seamcl
