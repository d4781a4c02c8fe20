#include <seamcl/pipeline/render_options.h>

#include <array>
#include <charconv>
#include <cmath>

#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

template <typename Enum, size_t N>
std::optional<Enum> parse_enum(std::string_view name, const std::array<std::pair<Enum, const char*>, N>& table) {
  for (const auto& [value, text] : table) {
    if (name == text) return value;
  }
  return std::nullopt;
}

template <typename Enum, size_t N>
std::string enum_name(Enum value, const std::array<std::pair<Enum, const char*>, N>& table) {
  for (const auto& [v, text] : table) {
    if (v == value) return text;
  }
  return "?";
}

template <typename Enum, size_t N>
std::vector<std::string> enum_names(const std::array<std::pair<Enum, const char*>, N>& table) {
  std::vector<std::string> out;
  for (const auto& entry : table) out.emplace_back(entry.second);
  return out;
}

constexpr std::array<std::pair<Method, const char*>, 6> kMethods{{{Method::Clamp, "clamp"},
                                                                  {Method::Black, "black"},
                                                                  {Method::Discard, "discard"},
                                                                  {Method::Traverse, "traverse"},
                                                                  {Method::TraverseEdges, "traverse-edges"},
                                                                  {Method::Guardband, "guardband"}}};
constexpr std::array<std::pair<Filter, const char*>, 4> kFilters{
    {{Filter::Bilinear, "bilinear"}, {Filter::Trilinear, "trilinear"}, {Filter::Aniso, "aniso"}, {Filter::Ewa, "ewa"}}};
constexpr std::array<std::pair<ZeroCoverage, const char*>, 2> kZeroCoverage{
    {{ZeroCoverage::Clamp, "clamp"}, {ZeroCoverage::Nan, "nan"}}};
constexpr std::array<std::pair<TexelFormat, const char*>, 2> kTexelFormats{
    {{TexelFormat::Rgba8, "rgba8"}, {TexelFormat::Rgba32f, "rgba32f"}}};
constexpr std::array<std::pair<ShadingMode, const char*>, 3> kShadingModes{
    {{ShadingMode::Pixel, "pixel"}, {ShadingMode::Centroid, "centroid"}, {ShadingMode::Sample, "sample"}}};
constexpr std::array<std::pair<CubeMethod, const char*>, 6> kCubeMethods{
    {{CubeMethod::Clamp, "cube-clamp"},
     {CubeMethod::Seamless, "cube-seamless"},
     {CubeMethod::Stretch, "cube-stretch"},
     {CubeMethod::Warp, "cube-warp"},
     {CubeMethod::Fixup, "cube-fixup"},
     {CubeMethod::Discard, "cube-discard"}}};
constexpr std::array<std::pair<ImageFormat, const char*>, 2> kFormats{{{ImageFormat::Png, "png"}, {ImageFormat::Exr, "exr"}}};

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

int int_field(const nlohmann::json& value, const std::string& field, int lo, int hi) {
  if (!value.is_number_integer()) {
    // Accept 4.0 but not 4.5, NaN or a string: a JSON client may send any number form.
    if (value.is_number_float()) {
      const double d = value.get<double>();
      if (std::isfinite(d) && d == std::floor(d) && d >= lo && d <= hi) return static_cast<int>(d);
    }
    throw InputError(field, "must be an integer in " + std::to_string(lo) + ".." + std::to_string(hi) +
                                ", got " + value.dump());
  }
  const long long v = value.get<long long>();
  if (v < lo || v > hi) {
    throw InputError(field, "must be in " + std::to_string(lo) + ".." + std::to_string(hi) + ", got " + value.dump());
  }
  return static_cast<int>(v);
}

std::string string_field(const nlohmann::json& value, const std::string& field) {
  if (!value.is_string()) throw InputError(field, "must be a string, got " + value.dump());
  return value.get<std::string>();
}

template <typename Enum, size_t N>
Enum enum_field(const nlohmann::json& value, const std::string& field, const char* what,
                const std::array<std::pair<Enum, const char*>, N>& table) {
  const std::string name = string_field(value, field);
  const auto parsed = parse_enum(name, table);
  if (!parsed) throw InputError(field, std::string("unknown ") + what + " '" + name + "' (known: " + joined(enum_names(table)) + ")");
  return *parsed;
}

bool bool_field(const nlohmann::json& value, const std::string& field) {
  if (!value.is_boolean()) throw InputError(field, "must be true or false, got " + value.dump());
  return value.get<bool>();
}

}  // namespace

std::optional<Method> parse_method(std::string_view name) { return parse_enum(name, kMethods); }
std::string to_string(Method method) { return enum_name(method, kMethods); }
std::vector<std::string> method_names() { return enum_names(kMethods); }
std::optional<ShadingMode> parse_shading_mode(std::string_view name) { return parse_enum(name, kShadingModes); }
std::string to_string(ShadingMode mode) { return enum_name(mode, kShadingModes); }
std::vector<std::string> shading_mode_names() { return enum_names(kShadingModes); }
std::optional<ImageFormat> parse_image_format(std::string_view name) { return parse_enum(name, kFormats); }
std::string to_string(ImageFormat format) { return enum_name(format, kFormats); }

std::optional<Filter> parse_filter(std::string_view name) { return parse_enum(name, kFilters); }
std::string to_string(Filter filter) { return enum_name(filter, kFilters); }
std::vector<std::string> filter_names() { return enum_names(kFilters); }
std::optional<ZeroCoverage> parse_zero_coverage(std::string_view name) { return parse_enum(name, kZeroCoverage); }
std::string to_string(ZeroCoverage mode) { return enum_name(mode, kZeroCoverage); }
std::vector<std::string> zero_coverage_names() { return enum_names(kZeroCoverage); }
std::optional<TexelFormat> parse_texel_format(std::string_view name) { return parse_enum(name, kTexelFormats); }
std::string to_string(TexelFormat format) { return enum_name(format, kTexelFormats); }
std::vector<std::string> texel_format_names() { return enum_names(kTexelFormats); }
std::optional<CubeMethod> parse_cube_method(std::string_view name) { return parse_enum(name, kCubeMethods); }
std::string to_string(CubeMethod method) { return enum_name(method, kCubeMethods); }
std::vector<std::string> cube_method_names() { return enum_names(kCubeMethods); }

bool reads_adjacency(Method method) { return method == Method::Traverse || method == Method::TraverseEdges; }
bool needs_adjacency(Method method) { return reads_adjacency(method) || method == Method::Guardband; }

SamplerParams sampler_params(Method method, Filter filter, int max_aniso, ZeroCoverage zero_coverage, int guard_band) {
  SamplerParams p{};
  p.filter = filter == Filter::Bilinear    ? SEAMCL_FILTER_BILINEAR
             : filter == Filter::Trilinear ? SEAMCL_FILTER_TRILINEAR
             : filter == Filter::Aniso     ? SEAMCL_FILTER_ANISO
                                           : SEAMCL_FILTER_EWA;
  p.address = method == Method::Clamp || method == Method::Guardband ? SEAMCL_ADDRESS_CLAMP : SEAMCL_ADDRESS_BORDER;
  p.guard_band = method == Method::Guardband ? guard_band : 0;
  p.renormalize = method == Method::Discard || reads_adjacency(method) ? 1 : 0;
  p.traverse = method == Method::Traverse        ? SEAMCL_TRAVERSE_CORNERS
               : method == Method::TraverseEdges ? SEAMCL_TRAVERSE_EDGES
                                                 : SEAMCL_TRAVERSE_NONE;
  p.max_aniso = max_aniso;
  p.zero_coverage = zero_coverage == ZeroCoverage::Clamp ? SEAMCL_ZERO_COVERAGE_CLAMP : SEAMCL_ZERO_COVERAGE_NAN;
  return p;
}

std::pair<int, int> parse_size(const std::string& text, const std::string& field) {
  const size_t x = text.find('x');
  auto parse_side = [&](std::string_view part) -> int {
    int value = 0;
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (part.empty() || error != std::errc() || end != part.data() + part.size() || value < 1 || value > kMaxImageSide) {
      throw InputError(field, "must be WIDTHxHEIGHT with each side in 1.." + std::to_string(kMaxImageSide) +
                                  ", got '" + text + "'");
    }
    return value;
  };
  if (x == std::string::npos) parse_side("");
  const std::string_view view(text);
  return {parse_side(view.substr(0, x)), parse_side(view.substr(x + 1))};
}

RenderOptions parse_render_options(const nlohmann::json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  RenderOptions options;
  bool centroid = false;
  for (const auto& [key, value] : request.items()) {
    if (key == "scene") {
      options.scene = string_field(value, key);
      if (options.scene.empty()) throw InputError(key, "must not be empty");
    } else if (key == "texture") {
      options.texture = string_field(value, key);
      if (options.texture.empty()) throw InputError(key, "must not be empty");
    } else if (key == "method") {
      options.method = enum_field(value, key, "method", kMethods);
    } else if (key == "filter") {
      options.filter = enum_field(value, key, "filter", kFilters);
    } else if (key == "zero_coverage") {
      options.zero_coverage = enum_field(value, key, "zero_coverage mode", kZeroCoverage);
    } else if (key == "texels") {
      options.texels = enum_field(value, key, "texel format", kTexelFormats);
    } else if (key == "msaa") {
      options.msaa = int_field(value, key, 1, 16);
      if ((options.msaa & (options.msaa - 1)) != 0) {
        throw InputError(key, "must be 1, 2, 4, 8 or 16, got " + value.dump());
      }
    } else if (key == "aniso") {
      options.aniso = int_field(value, key, 1, 16);
    } else if (key == "guard_band") {
      options.guard_band = int_field(value, key, 1, 16);
    } else if (key == "size") {
      std::tie(options.width, options.height) = parse_size(string_field(value, key), key);
    } else if (key == "shading") {
      options.shading = enum_field(value, key, "shading mode", kShadingModes);
    } else if (key == "centroid") {
      centroid = bool_field(value, key);
    } else if (key == "frame") {
      options.frame = int_field(value, key, 0, 1000000);
    } else if (key == "frames") {
      options.frames = int_field(value, key, 1, kMaxFrames);
    } else if (key == "tint") {
      options.tint = bool_field(value, key);
    } else if (key == "displacement_method") {
      const std::string name = string_field(value, key);
      options.displacement = parse_displacement_method(name);
      if (!options.displacement) {
        throw InputError(key, "unknown displacement method '" + name + "' (known: " + joined(displacement_method_names()) + ")");
      }
    } else if (key == "tessellation") {
      options.tessellation = int_field(value, key, 1, SEAMCL_MAX_TESSELLATION);
    } else if (key == "displacement_level") {
      options.displacement_level = int_field(value, key, 0, kMaxDisplacementLevel);
    } else if (key == "cube_method") {
      options.cube_method = enum_field(value, key, "cube method", kCubeMethods);
    } else {
      throw InputError(key, "unknown option");
    }
  }
  if (centroid) {
    if (options.shading == ShadingMode::Sample) throw InputError("centroid", "cannot be combined with shading=sample");
    options.shading = ShadingMode::Centroid;
  }
  if (options.frame && *options.frame >= options.frames) {
    throw InputError("frame", "must be less than frames (" + std::to_string(options.frames) + "), got " +
                                  std::to_string(*options.frame));
  }
  if (static_cast<long long>(options.width) * options.height * options.msaa > kMaxSamplesPerImage) {
    throw InputError("size", "width x height x msaa exceeds " + std::to_string(kMaxSamplesPerImage) + " samples");
  }
  return options;
}

nlohmann::json to_json(const RenderOptions& options) {
  nlohmann::json out = {{"scene", options.scene},
                        {"method", to_string(options.method)},
                        {"filter", to_string(options.filter)},
                        {"zero_coverage", to_string(options.zero_coverage)},
                        {"texels", to_string(options.texels)},
                        {"msaa", options.msaa},
                        {"aniso", options.aniso},
                        {"guard_band", options.guard_band},
                        {"size", std::to_string(options.width) + "x" + std::to_string(options.height)},
                        {"shading", to_string(options.shading)},
                        {"tint", options.tint},
                        {"cube_method", to_string(options.cube_method)}};
  if (!options.texture.empty()) out["texture"] = options.texture;
  if (options.displacement) {
    out["displacement_method"] = to_string(*options.displacement);
    out["tessellation"] = options.tessellation;
    out["displacement_level"] = options.displacement_level;
  }
  if (options.frame) {
    out["frame"] = *options.frame;
    out["frames"] = options.frames;
  }
  return out;
}

}  // namespace seamcl
