#include "reference_cache_flags.h"

#include "commands.h"

namespace seamcl::cli {

void ReferenceCacheFlags::add_to(CLI::App* command) {
  command->add_option("--cache", dir, "Reference cache directory [$SEAMCL_CACHE_DIR or ~/.cache/seamcl]");
  command->add_option("--cache-max-mib", max_mib,
                      "Bound of the reference cache in MiB: least recently used references are removed after "
                      "each write; 0: unbounded [" + std::to_string(max_mib) + "]");
  command->add_option("--cache-max-entries", max_entries,
                      "Bound of the reference cache in files (least recently used removed); 0: unbounded [0]");
  command->add_flag("--no-cache", no_cache, "Always render references; do not read or write the cache");
}

void ReferenceCacheFlags::apply(ReferenceSettings& settings) const {
  settings.cache_dir = given_value(dir, "cache", "leave out --cache for $SEAMCL_CACHE_DIR or ~/.cache/seamcl");
  settings.use_cache = !no_cache;
  if (settings.use_cache) check_reference_cache_dir(settings.cache_dir, "cache");
  if (max_mib < 0 || max_mib > (1LL << 40))
    throw InputError("cache_max_mib", "must be in 0..2^40 (0: unbounded), got " + std::to_string(max_mib));
  if (max_entries < 0)
    throw InputError("cache_max_entries", "must be at least 0 (0: unbounded), got " + std::to_string(max_entries));
  settings.cache_max_bytes = static_cast<std::uintmax_t>(max_mib) << 20;
  settings.cache_max_entries = static_cast<size_t>(max_entries);
}

}  // namespace seamcl::cli
