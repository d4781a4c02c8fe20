#include "measure_args.h"

#include "commands.h"

#include <seamcl/core/input_error.h>
#include <seamcl/options/displacement_method.h>
#include <seamcl/options/render_options.h>

namespace seamcl::cli {
void add_measure_options(CLI::App* command, MeasureArgs& a, const std::string& default_methods) {
  a.methods = default_methods;
  command->add_option("--scene", a.scene, "Built-in scene name, a scene JSON file, an .obj mesh or a .ptx that holds its mesh [paper]");
  command->add_option("--texture", a.texture, "A .ptx file of per-face textures for an .obj --scene (face i of the mesh takes face i of the file)");
  command->add_option("--methods", a.methods, "Comma list of seam methods [" + default_methods + "]");
  command->add_option("--msaa", a.msaa, "Comma list of MSAA rates (1, 2, 4, 8, 16) [1,2,4,8]");
  command->add_option("--aniso", a.aniso, "Maximum anisotropy, 1..16 [16]");
  command->add_option("--guard-band", a.guard_band, "guardband: band texels per side of every level, 1..16 [4]");
  command->add_option("--cube-method", a.cube_method,
                      "Cube-map seam method of scenes with an environment (envmap): " + join_names(cube_method_names()) +
                          " [cube-seamless]");
  command->add_option("--filter", a.filter, "Texture filter [aniso]");
  command->add_option("--zero-coverage", a.zero_coverage, "discard with every tap outside: clamp or nan [clamp]");
  command->add_option("--texels", a.texels, "Texel storage: rgba8 or rgba32f [rgba8]");
  command->add_option("--size", a.size, "Image size WIDTHxHEIGHT [480x540]");
  command->add_option("--shading", a.shading, "Where to shade: pixel, centroid or sample [pixel]");
  command->add_flag("--centroid", a.centroid, "Shade at the centroid of the covered samples (same as --shading centroid)");
  command->add_option("--displacement-method", a.displacement_method,
                      "Tessellate and displace with this method: " + join_names(displacement_method_names()) + " [off]");
  command->add_option("--tessellation", a.tessellation, "Displacement: each patch a (T+1)^2 grid, T 1..64 [8]");
  command->add_option("--displacement-level", a.displacement_level, "Displacement: the maps' level sampled, 0..16 [0]");
  command->add_flag("--tint", a.tint, "Built-in scenes: tint each face a different base colour");
  command->add_option("--reference-method", a.reference_method,
                      "Method of the 8x reference render [traverse if available, else discard]");
  command->add_option("--reference-msaa", a.reference_msaa,
                      "Samples per pixel of the 8x reference render [1 for traverse, 16 for discard]");
  command->add_option("--cache", a.cache_dir, "Reference cache directory [$SEAMCL_CACHE_DIR or ~/.cache/seamcl]");
  command->add_option("--cache-max-mib", a.cache_max_mib,
                      "Bound of the reference cache in MiB: least recently used references are removed after "
                      "each write; 0: unbounded [" + std::to_string(a.cache_max_mib) + "]");
  command->add_option("--cache-max-entries", a.cache_max_entries,
                      "Bound of the reference cache in files (least recently used removed); 0: unbounded [0]");
  command->add_flag("--no-cache", a.no_cache, "Always render references; do not read or write the cache");
  command->add_flag("--json", a.json_out, "Print one JSON object");
}

nlohmann::json measure_request(const MeasureArgs& a) {
  nlohmann::json request = nlohmann::json::object();
  if (a.scene) request["scene"] = *a.scene;
  if (a.texture) request["texture"] = *a.texture;
  if (a.filter) request["filter"] = *a.filter;
  if (a.zero_coverage) request["zero_coverage"] = *a.zero_coverage;
  if (a.texels) request["texels"] = *a.texels;
  if (a.aniso) request["aniso"] = *a.aniso;
  if (a.guard_band) request["guard_band"] = *a.guard_band;
  if (a.cube_method) request["cube_method"] = *a.cube_method;
  if (a.centroid) request["centroid"] = true;
  if (a.size) request["size"] = *a.size;
  if (a.shading) request["shading"] = *a.shading;
  if (a.tint) request["tint"] = true;
  if (a.displacement_method) request["displacement_method"] = *a.displacement_method;
  if (a.tessellation) request["tessellation"] = *a.tessellation;
  if (a.displacement_level) request["displacement_level"] = *a.displacement_level;
  return request;
}

ReferenceSettings reference_settings(const MeasureArgs& a) {
  ReferenceSettings settings;
  settings.method = given_value(a.reference_method, "reference_method",
                                "leave out --reference-method for traverse, or discard where traverse is not built in");
  settings.msaa = a.reference_msaa;
  settings.cache_dir = given_value(a.cache_dir, "cache", "leave out --cache for $SEAMCL_CACHE_DIR or ~/.cache/seamcl");
  settings.use_cache = !a.no_cache;
  if (a.cache_max_mib < 0 || a.cache_max_mib > (1LL << 40)) {
    throw InputError("cache_max_mib", "must be in 0..2^40 (0: unbounded), got " + std::to_string(a.cache_max_mib));
  }
  if (a.cache_max_entries < 0) {
    throw InputError("cache_max_entries", "must be at least 0 (0: unbounded), got " + std::to_string(a.cache_max_entries));
  }
  settings.cache_max_bytes = static_cast<std::uintmax_t>(a.cache_max_mib) << 20;
  settings.cache_max_entries = static_cast<size_t>(a.cache_max_entries);
  return settings;
}

}  // namespace seamcl::cli
