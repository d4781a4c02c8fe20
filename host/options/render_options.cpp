#include <seamcl/options/render_options.h>

#include <seamcl/options/option_domains.h>

#include <array>
#include <charconv>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <tuple>
#include <utility>

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
constexpr std::array<std::pair<Filter, const char*>, 12> kFilters{{{Filter::Bilinear, "bilinear"},
                                                                   {Filter::Trilinear, "trilinear"},
                                                                   {Filter::Aniso, "aniso"},
                                                                   {Filter::Ewa, "ewa"},
                                                                   {Filter::PtexPoint, "ptex-point"},
                                                                   {Filter::PtexBilinear, "ptex-bilinear"},
                                                                   {Filter::PtexBox, "ptex-box"},
                                                                   {Filter::PtexGaussian, "ptex-gaussian"},
                                                                   {Filter::PtexBicubic, "ptex-bicubic"},
                                                                   {Filter::PtexBspline, "ptex-bspline"},
                                                                   {Filter::PtexCatmullrom, "ptex-catmullrom"},
                                                                   {Filter::PtexMitchell, "ptex-mitchell"}}};
constexpr std::array<std::pair<ZeroCoverage, const char*>, 2> kZeroCoverage{
    {{ZeroCoverage::Clamp, "clamp"}, {ZeroCoverage::Nan, "nan"}}};
constexpr std::array<std::pair<TexelFormat, const char*>, 2> kTexelFormats{
    {{TexelFormat::Rgba8, "rgba8"}, {TexelFormat::Rgba32f, "rgba32f"}}};
constexpr std::array<std::pair<ShadingMode, const char*>, 3> kShadingModes{
    {{ShadingMode::Pixel, "pixel"}, {ShadingMode::Centroid, "centroid"}, {ShadingMode::Sample, "sample"}}};
constexpr std::array<std::pair<DisplacementNormals, const char*>, 2> kDisplacementNormals{
    {{DisplacementNormals::Displaced, "displaced"}, {DisplacementNormals::Face, "face"}}};
constexpr std::array<std::pair<CubeMethod, const char*>, 10> kCubeMethods{
    {{CubeMethod::Clamp, "cube-clamp"},
     {CubeMethod::Seamless, "cube-seamless"},
     {CubeMethod::Stretch, "cube-stretch"},
     {CubeMethod::Warp, "cube-warp"},
     {CubeMethod::Fixup, "cube-fixup"},
     {CubeMethod::Discard, "cube-discard"},
     {CubeMethod::FixupLevel, "cube-fixup-level"},
     {CubeMethod::Fov, "cube-fov"},
     {CubeMethod::Average, "cube-average"},
     {CubeMethod::Border, "cube-border"}}};
constexpr std::array<std::pair<ImageFormat, const char*>, 2> kFormats{{{ImageFormat::Png, "png"}, {ImageFormat::Exr, "exr"}}};

}  // namespace

std::optional<Method> parse_method(std::string_view name) { return parse_enum(name, kMethods); }
std::string to_string(Method method) { return enum_name(method, kMethods); }
std::vector<std::string> method_names() { return enum_names(kMethods); }
std::optional<ShadingMode> parse_shading_mode(std::string_view name) { return parse_enum(name, kShadingModes); }
std::string to_string(ShadingMode mode) { return enum_name(mode, kShadingModes); }
std::vector<std::string> shading_mode_names() { return enum_names(kShadingModes); }
std::optional<DisplacementNormals> parse_displacement_normals(std::string_view name) {
  return parse_enum(name, kDisplacementNormals);
}
std::string to_string(DisplacementNormals normals) { return enum_name(normals, kDisplacementNormals); }
std::vector<std::string> displacement_normals_names() { return enum_names(kDisplacementNormals); }
std::optional<ImageFormat> parse_image_format(std::string_view name) { return parse_enum(name, kFormats); }
std::string to_string(ImageFormat format) { return enum_name(format, kFormats); }

std::optional<Filter> parse_filter(std::string_view name) { return parse_enum(name, kFilters); }
std::string to_string(Filter filter) { return enum_name(filter, kFilters); }
std::vector<std::string> filter_names() { return enum_names(kFilters); }
bool is_ptex_filter(Filter filter) { return filter >= Filter::PtexPoint; }

int ptex_filter_code(Filter filter, float& sharpness) {
  sharpness = 0.0f;
  switch (filter) {
    case Filter::PtexPoint: return SEAMCL_PTEX_POINT;
    case Filter::PtexBilinear: return SEAMCL_PTEX_BILINEAR;
    case Filter::PtexBox: return SEAMCL_PTEX_BOX;
    case Filter::PtexGaussian: return SEAMCL_PTEX_GAUSSIAN;
    case Filter::PtexBicubic:
    case Filter::PtexBspline: return SEAMCL_PTEX_BICUBIC;
    case Filter::PtexCatmullrom: sharpness = 1.0f; return SEAMCL_PTEX_BICUBIC;
    case Filter::PtexMitchell: sharpness = 2.0f / 3.0f; return SEAMCL_PTEX_BICUBIC;
    default: throw std::logic_error("ptex_filter_code: " + to_string(filter) + " is not a Ptex filter");
  }
}

int ptex_seam_rule(Method method) {
  switch (method) {
    case Method::Traverse: return SEAMCL_PTEX_SEAMS_PTEX;
    case Method::Clamp: return SEAMCL_PTEX_SEAMS_CLAMP;
    case Method::Black: return SEAMCL_PTEX_SEAMS_BLACK;
    case Method::Discard: return SEAMCL_PTEX_SEAMS_DISCARD;
    case Method::TraverseEdges:
      throw InputError("method", "traverse-edges leaves out the corners, which Ptex's filters always read: use traverse "
                                 "(the Ptex library's own rules), or clamp, black or discard (no neighbour read)");
    case Method::Guardband:
      throw InputError("method", "guardband fills bands of the packed texture, which Ptex's filters do not read: use "
                                 "traverse (the Ptex library's own rules), or clamp, black or discard (no neighbour read)");
  }
  throw std::logic_error("ptex_seam_rule: unknown method");
}
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

SamplerParams sampler_params(Method method, Filter filter, int max_aniso, ZeroCoverage zero_coverage, int guard_band,
                             float lod_bias) {
  SamplerParams p{};
  if (is_ptex_filter(filter)) {
    // One program variant for every Ptex filter and method: the filter, its sharpness and the seam
    // rule are run-time settings of the lookup (PtexShading), the packed texture is never sampled.
    p.filter = SEAMCL_FILTER_PTEX;
    p.address = SEAMCL_ADDRESS_BORDER;
    p.max_aniso = max_aniso;
    p.zero_coverage = SEAMCL_ZERO_COVERAGE_CLAMP;
    p.lod_bias = lod_bias;
    return p;
  }
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
  p.lod_bias = lod_bias;
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

namespace {

using nlohmann::json;

// One row of the table: the option's spec and how it reads from and writes to RenderOptions.
// `write` takes a value checked_option has already checked; `read` gives the value to_json writes,
// null where to_json leaves the key out (an option not in effect). `domain`: see option_domains.h.
struct RenderField {
  RenderField(OptionSpec spec_, std::function<void(RenderOptions&, const json&)> write_,
              std::function<json(const RenderOptions&)> read_, std::string domain_ = "")
      : spec(std::move(spec_)), write(std::move(write_)), read(std::move(read_)), domain(std::move(domain_)) {}
  OptionSpec spec;
  std::function<void(RenderOptions&, const json&)> write;
  std::function<json(const RenderOptions&)> read;
  std::string domain;
};

template <typename Enum, size_t N>
Enum enum_value(const json& value, const std::array<std::pair<Enum, const char*>, N>& table) {
  return *parse_enum(value.get<std::string>(), table);
}

OptionSpec choice(std::string key, std::vector<std::string> names, std::string help, std::string noun = "") {
  OptionSpec spec = make_option(std::move(key), OptionType::Choice, std::move(help));
  spec.choices = std::move(names);
  spec.noun = std::move(noun);
  return spec;
}

OptionSpec integer(std::string key, int lo, int hi, std::string help) {
  OptionSpec spec = make_option(std::move(key), OptionType::Integer, std::move(help));
  spec.minimum = lo;
  spec.maximum = hi;
  return spec;
}

OptionSpec of_type(std::string key, OptionType type, std::string help) { return make_option(std::move(key), type, std::move(help)); }

OptionSpec absent_means(OptionSpec spec, std::string absent) {
  spec.absent = std::move(absent);
  return spec;
}

// The text form of "size": each side 1..16384, leading zeros read too.
constexpr const char* kSizePattern =
    "^0*(?:[1-9][0-9]{0,3}|1[0-5][0-9]{3}|16[0-2][0-9]{2}|163[0-7][0-9]|1638[0-4])"
    "x0*(?:[1-9][0-9]{0,3}|1[0-5][0-9]{3}|16[0-2][0-9]{2}|163[0-7][0-9]|1638[0-4])$";
static_assert(kMaxImageSide == 16384, "kSizePattern spells out the largest side");

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

const std::vector<RenderField>& render_fields() {
  static const std::vector<RenderField> fields = [] {
    OptionSpec size = of_type("size", OptionType::Size, "Image size WIDTHxHEIGHT");
    size.minimum = 1;
    size.maximum = kMaxImageSide;
    size.pattern = kSizePattern;
    OptionSpec msaa = of_type("msaa", OptionType::Integer, "Samples per pixel");
    msaa.integers = {1, 2, 4, 8, 16};
    OptionSpec lod_bias = of_type("lod_bias", OptionType::Number,
                                  "Added to every texture lookup's mip level (positive: blurrier)");
    lod_bias.minimum = -kMaxLodBias;
    lod_bias.maximum = kMaxLodBias;
    OptionSpec tessellation_pixels = absent_means(
        of_type("tessellation_pixels", OptionType::Number,
                "Displacement: screen-space adaptive factors, each patch edge's from its projected length "
                "over this many pixels a segment, clamped to 1..tessellation"),
        "uniform: every edge at tessellation");
    tessellation_pixels.minimum = kMinTessellationPixels;
    tessellation_pixels.maximum = kMaxTessellationPixels;
    auto displaced_only = [](json value) {
      return [value](const RenderOptions& o) { return o.displacement ? value : json(); };
    };
    std::vector<RenderField> rows = {
        {of_type("scene", OptionType::String,
                 "Built-in scene name, a scene JSON file, an .obj mesh or a .ptx that holds its mesh"),
         [](RenderOptions& o, const json& v) { o.scene = v.get<std::string>(); },
         [](const RenderOptions& o) { return json(o.scene); }},
        {absent_means(of_type("texture", OptionType::String,
                              "A .ptx file of per-face textures for an .obj scene (face i of the mesh takes face i of the file)"),
                      "none"),
         [](RenderOptions& o, const json& v) { o.texture = v.get<std::string>(); },
         [](const RenderOptions& o) { return o.texture.empty() ? json() : json(o.texture); }},
        {absent_means(of_type("displacement_map", OptionType::String,
                              "Displacement: a 1-channel .ptx whose faces displace the mesh's (face i takes face i), "
                              "in place of the scene's own maps; needs displacement_method"),
                      "the scene's own maps"),
         [](RenderOptions& o, const json& v) { o.displacement_map = v.get<std::string>(); },
         [](const RenderOptions& o) { return o.displacement_map.empty() ? json() : json(o.displacement_map); },
         kDisplacementDomain},
        {choice("method", method_names(), "Seam method"),
         [](RenderOptions& o, const json& v) { o.method = enum_value(v, kMethods); },
         [](const RenderOptions& o) { return json(to_string(o.method)); }},
        {choice("filter", filter_names(), "Texture filter"),
         [](RenderOptions& o, const json& v) { o.filter = enum_value(v, kFilters); },
         [](const RenderOptions& o) { return json(to_string(o.filter)); }},
        {choice("zero_coverage", zero_coverage_names(),
                "discard with every tap outside the face: a clamped lookup, or the raw 0/0", "zero_coverage mode"),
         [](RenderOptions& o, const json& v) { o.zero_coverage = enum_value(v, kZeroCoverage); },
         [](const RenderOptions& o) { return json(to_string(o.zero_coverage)); }},
        {choice("texels", texel_format_names(), "Texel storage", "texel format"),
         [](RenderOptions& o, const json& v) { o.texels = enum_value(v, kTexelFormats); },
         [](const RenderOptions& o) { return json(to_string(o.texels)); }},
        {msaa, [](RenderOptions& o, const json& v) { o.msaa = v.get<int>(); },
         [](const RenderOptions& o) { return json(o.msaa); }},
        {integer("aniso", 1, SEAMCL_MAX_PROBES, "Maximum anisotropy"),
         [](RenderOptions& o, const json& v) { o.aniso = v.get<int>(); },
         [](const RenderOptions& o) { return json(o.aniso); }},
        {integer("guard_band", 1, kMaxBandTexels, "guardband: band texels per side of every level"),
         [](RenderOptions& o, const json& v) { o.guard_band = v.get<int>(); },
         [](const RenderOptions& o) { return json(o.guard_band); }},
        {lod_bias, [](RenderOptions& o, const json& v) { o.lod_bias = v.get<float>(); },
         [](const RenderOptions& o) { return json(o.lod_bias); }},
        {size,
         [](RenderOptions& o, const json& v) { std::tie(o.width, o.height) = parse_size(v.get<std::string>(), "size"); },
         [](const RenderOptions& o) { return json(size_text(o.width, o.height)); }},
        {choice("shading", shading_mode_names(), "Where to shade: the pixel centre, the covered samples' centroid, every sample", "shading mode"),
         [](RenderOptions& o, const json& v) { o.shading = enum_value(v, kShadingModes); },
         [](const RenderOptions& o) { return json(to_string(o.shading)); }},
        {of_type("centroid", OptionType::Boolean, "Shade at the centroid of the covered samples (same as shading=centroid)"),
         [](RenderOptions&, const json&) {},  // applied after every key: see parse_render_options
         [](const RenderOptions&) { return json(); }},
        {absent_means(integer("frame", 0, kMaxFrames - 1, "Orbit frame K (0-based) of frames"), "the scene's own camera"),
         [](RenderOptions& o, const json& v) { o.frame = v.get<int>(); },
         [](const RenderOptions& o) { return o.frame ? json(*o.frame) : json(); }},
        {integer("frames", 1, kMaxFrames, "Frames in the orbit"),
         [](RenderOptions& o, const json& v) { o.frames = v.get<int>(); },
         [](const RenderOptions& o) { return o.frame ? json(o.frames) : json(); }},
        {of_type("tint", OptionType::Boolean, "Built-in scenes: tint each face a different base colour"),
         [](RenderOptions& o, const json& v) { o.tint = v.get<bool>(); },
         [](const RenderOptions& o) { return json(o.tint); }},
        {choice("cube_method", cube_method_names(), "Cube-map seam method of scenes with an environment (envmap)", "cube method"),
         [](RenderOptions& o, const json& v) { o.cube_method = enum_value(v, kCubeMethods); },
         [](const RenderOptions& o) { return json(to_string(o.cube_method)); }, kCubeDomain},
        {absent_means(choice("displacement_method", displacement_method_names(),
                             "Tessellate every patch and displace it by the scene's maps with this seam method", "displacement method"),
                      "no displacement"),
         [](RenderOptions& o, const json& v) { o.displacement = parse_displacement_method(v.get<std::string>()); },
         [](const RenderOptions& o) { return o.displacement ? json(to_string(*o.displacement)) : json(); }, kDisplacementDomain},
        {integer("tessellation", 1, SEAMCL_MAX_TESSELLATION, "Displacement: each patch a (T+1)^2 grid"),
         [](RenderOptions& o, const json& v) { o.tessellation = v.get<int>(); }, displaced_only(json()), kDisplacementDomain},
        {tessellation_pixels,
         [](RenderOptions& o, const json& v) { o.tessellation_pixels = v.get<float>(); },
         [](const RenderOptions& o) { return o.displacement && o.tessellation_pixels ? json(*o.tessellation_pixels) : json(); },
         kDisplacementDomain},
        {integer("displacement_level", 0, kMaxDisplacementLevel, "Displacement: the maps' level every patch samples"),
         [](RenderOptions& o, const json& v) { o.displacement_level = v.get<int>(); }, displaced_only(json()), kDisplacementDomain},
        {choice("displacement_normals", displacement_normals_names(),
                "Displacement: light with the displaced surface's normals, computed alike on both sides of every "
                "edge and interpolated across each micro-triangle, or with each patch's flat face normal",
                "displacement normals"),
         [](RenderOptions& o, const json& v) { o.displacement_normals = enum_value(v, kDisplacementNormals); },
         [](const RenderOptions& o) { return o.displacement ? json(to_string(o.displacement_normals)) : json(); },
         kDisplacementDomain},
    };
    // Defaults are RenderOptions' own initialisers, read through the same accessors; the two
    // displacement settings are written only with a method, so their defaults are read directly.
    const RenderOptions defaults;
    for (RenderField& row : rows) {
      if (row.spec.type == OptionType::Boolean) {
        row.spec.default_value = false;
      } else if (row.spec.key == "tessellation") {
        row.spec.default_value = defaults.tessellation;
      } else if (row.spec.key == "displacement_level") {
        row.spec.default_value = defaults.displacement_level;
      } else if (row.spec.key == "displacement_normals") {
        row.spec.default_value = to_string(defaults.displacement_normals);
      } else if (row.spec.key == "frames") {
        row.spec.default_value = defaults.frames;
      } else {
        row.spec.default_value = row.read(defaults);
      }
    }
    for (RenderField& row : rows) {
      if (row.spec.key == "tessellation" || row.spec.key == "displacement_level") {
        const std::string key = row.spec.key;
        row.read = [key](const RenderOptions& o) {
          if (!o.displacement) return json();
          return key == "tessellation" ? json(o.tessellation) : json(o.displacement_level);
        };
      }
    }
    return rows;
  }();
  return fields;
}

}  // namespace

const OptionTable& render_option_table() {
  static const OptionTable table = [] {
    OptionTable specs;
    for (const RenderField& field : render_fields()) specs.push_back(field.spec);
    return specs;
  }();
  return table;
}

const std::map<std::string, std::vector<std::string>>& render_option_domains() {
  static const std::map<std::string, std::vector<std::string>> domains = [] {
    std::map<std::string, std::vector<std::string>> out;
    for (const RenderField& field : render_fields())
      if (!field.domain.empty()) out[field.domain].push_back(field.spec.key);
    return out;
  }();
  return domains;
}

RenderOptions parse_render_options(const nlohmann::json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  RenderOptions options;
  bool centroid = false;
  for (const auto& [key, value] : request.items()) {
    const RenderField* field = nullptr;
    for (const RenderField& f : render_fields())
      if (f.spec.key == key) field = &f;
    if (!field) throw InputError(key, "unknown option");
    const json checked = checked_option(field->spec, value);
    field->write(options, checked);
    if (key == "centroid") centroid = checked.get<bool>();
  }
  if (centroid) {
    if (options.shading == ShadingMode::Sample) throw InputError("centroid", "cannot be combined with shading=sample");
    options.shading = ShadingMode::Centroid;
  }
  if (!options.displacement_map.empty() && !options.displacement) {
    throw InputError("displacement_map", "displaces only a render with displacement_method");
  }
  if (options.tessellation_pixels && !options.displacement) {
    throw InputError("tessellation_pixels", "tessellates only a render with displacement_method");
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
  json out = json::object();
  for (const RenderField& field : render_fields()) {
    json value = field.read(options);
    if (!value.is_null()) out[field.spec.key] = std::move(value);
  }
  return out;
}

}  // namespace seamcl
