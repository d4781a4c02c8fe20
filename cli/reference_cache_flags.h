// Where the command line keeps its references (host/eval/reference.h's cache): the user's
// environment rather than a job's option, so these flags are the command line's own (the service
// has a cache of its own, configured at start).
#pragma once
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include <seamcl/eval/reference.h>

namespace seamcl::cli {

struct ReferenceCacheFlags {
  std::optional<std::string> dir;  // empty is refused, not taken for the default
  long long max_mib = static_cast<long long>(kDefaultReferenceCacheBytes >> 20);
  long long max_entries = 0;
  bool no_cache = false;

  void add_to(CLI::App* command);
  // Sets settings' cache fields; InputError("cache" / "cache_max_mib" / "cache_max_entries").
  void apply(ReferenceSettings& settings) const;
};

}  // namespace seamcl::cli
