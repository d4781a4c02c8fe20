// What `compare` and `bench` share on the command line: one frame's render options (the names
// `render` uses), the method and MSAA lists, and where the reference comes from.
#pragma once
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/eval/reference.h>

namespace seamcl::cli {

struct MeasureArgs {
  std::optional<std::string> scene, texture, filter, zero_coverage, texels, size, shading, cube_method;
  std::optional<int> aniso, guard_band;
  std::optional<std::string> displacement_method;
  std::optional<int> tessellation, displacement_level;
  std::string methods;
  std::string msaa = "1,2,4,8";
  bool tint = false;
  bool centroid = false;
  std::optional<std::string> reference_method;  // empty is refused, not taken for the default
  int reference_msaa = 0;
  std::optional<std::string> cache_dir;  // empty is refused, not taken for the default
  long long cache_max_mib = static_cast<long long>(kDefaultReferenceCacheBytes >> 20);
  long long cache_max_entries = 0;
  bool no_cache = false;
  bool json_out = false;
};

// Adds the shared options to `command`; `methods` starts as default_methods.
void add_measure_options(CLI::App* command, MeasureArgs& args, const std::string& default_methods);

// The frame's render options given on the command line, as parse_render_options reads them.
nlohmann::json measure_request(const MeasureArgs& args);

// InputError("reference_method" / "cache") for an empty value, ("cache_max_mib" /
// "cache_max_entries") for a bound out of range.
ReferenceSettings reference_settings(const MeasureArgs& args);

}  // namespace seamcl::cli
