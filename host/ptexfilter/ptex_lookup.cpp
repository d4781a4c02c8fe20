#include <seamcl/ptexfilter/ptex_lookup.h>

#include <cmath>
#include <stdexcept>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/core/input_error.h>
#include <seamcl/core/json_document.h>

#include "pipeline/stages/ptex_filter_launcher.h"
#include "pipeline/stages/ptex_filter_twin.h"
#include "ptexfilter/ptex_filter_texture.h"

namespace seamcl {
namespace {

using nlohmann::json;

// Far beyond any face (u, v are face coordinates, 0..1) yet small enough that no float step of
// the filters overflows.
constexpr double kMaxCoordinate = 1e6;

int filter_code(const std::string& name, float& sharpness) {
  const std::string base = name.rfind("ptex-", 0) == 0 ? name.substr(5) : name;
  if (base == "point") return SEAMCL_PTEX_POINT;
  if (base == "bilinear") return SEAMCL_PTEX_BILINEAR;
  if (base == "box") return SEAMCL_PTEX_BOX;
  if (base == "gaussian") return SEAMCL_PTEX_GAUSSIAN;
  if (base == "bspline") { sharpness = 0.0f; return SEAMCL_PTEX_BICUBIC; }
  if (base == "catmullrom") { sharpness = 1.0f; return SEAMCL_PTEX_BICUBIC; }
  if (base == "mitchell") { sharpness = 2.0f / 3.0f; return SEAMCL_PTEX_BICUBIC; }
  if (base == "bicubic") return SEAMCL_PTEX_BICUBIC;
  throw InputError("filter", "unknown Ptex filter '" + name + "'");
}

PtexFilterQuery query_of(const PtexLookup& l) {
  PtexFilterQuery q{};
  q.face = l.face;
  q.sharpness = l.sharpness;
  q.filter = filter_code(l.filter, q.sharpness);
  q.u = l.u;
  q.v = l.v;
  q.uw = l.uw;
  q.vw = l.vw;
  return q;
}

}  // namespace

const std::vector<std::string>& ptex_filter_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    const char* base[] = {"point", "bilinear", "box", "gaussian", "bicubic", "bspline", "catmullrom", "mitchell"};
    for (const char* b : base) out.push_back(b);
    for (const char* b : base) out.push_back(std::string("ptex-") + b);
    return out;
  }();
  return names;
}

const OptionTable& ptex_lookup_option_table() {
  static const OptionTable table = [] {
    OptionSpec face = make_option("face", OptionType::Integer, "The face to look up in, 0 to the file's faces - 1");
    face.minimum = 0;
    face.maximum = (1 << 20) - 1;
    face.default_value = 0;
    OptionSpec u = make_option("u", OptionType::Number, "The point's u in the face (0..1; beyond, the file's border mode)");
    u.minimum = -kMaxCoordinate;
    u.maximum = kMaxCoordinate;
    u.default_value = 0.5;
    OptionSpec v = u;
    v.key = "v";
    v.help = "The point's v in the face (0..1; beyond, the file's border mode)";
    OptionSpec uw = make_option("uw", OptionType::Number, "The filter's width along u in face units (0: one texel)");
    uw.minimum = 0;
    uw.maximum = kMaxCoordinate;
    uw.default_value = 0.0;
    OptionSpec vw = uw;
    vw.key = "vw";
    vw.help = "The filter's width along v in face units (0: one texel)";
    OptionSpec filter = make_option("filter", OptionType::Choice, "Ptex's filter");
    filter.choices = ptex_filter_names();
    filter.default_value = "bilinear";
    OptionSpec sharpness = make_option("sharpness", OptionType::Number, "bicubic only: 0 B-spline, 1 Catmull-Rom");
    sharpness.minimum = 0;
    sharpness.maximum = 1;
    sharpness.default_value = 0.0;
    return OptionTable{face, u, v, uw, vw, filter, sharpness};
  }();
  return table;
}

PtexLookup parse_ptex_lookup(const json& object, const std::string& field) {
  const std::string prefix = field.empty() ? "" : field + ".";
  if (!object.is_object()) throw InputError(field.empty() ? "query" : field, "must be a JSON object");
  auto value_of = [&](const std::string& key) {
    const OptionSpec& spec = *find_option(ptex_lookup_option_table(), key);
    if (!object.contains(key)) return spec.default_value;
    try {
      return checked_option(spec, object.at(key));
    } catch (const InputError& e) {
      throw InputError(prefix + key, std::string(e.what()).substr(e.field().size() + 2));
    }
  };
  PtexLookup out;
  out.face = value_of("face").get<int>();
  out.u = value_of("u").get<float>();
  out.v = value_of("v").get<float>();
  out.uw = value_of("uw").get<float>();
  out.vw = value_of("vw").get<float>();
  out.filter = value_of("filter").get<std::string>();
  out.sharpness = value_of("sharpness").get<float>();
  return out;
}

std::vector<PtexLookup> parse_ptex_lookups(const json& array, const std::string& field) {
  if (!array.is_array()) throw InputError(field, "must be a JSON array of lookups");
  std::vector<PtexLookup> out;
  out.reserve(array.size());
  for (size_t i = 0; i < array.size(); ++i) out.push_back(parse_ptex_lookup(array[i], field + "[" + std::to_string(i) + "]"));
  return out;
}

std::vector<PtexLookup> parse_ptex_lookups_from_text(std::string_view text, const std::string& source) {
  std::vector<PtexLookup> lookups;
  const auto add = [&](json&& element) {
    lookups.push_back(parse_ptex_lookup(element, "queries[" + std::to_string(lookups.size()) + "]"));
  };
  try {
    if (!parse_json_array_elements(text, kMaxPtexLookups, add)) throw InputError("queries", "must be a JSON array of lookups");
  } catch (const json::exception& error) {
    throw InputError("queries", source + ": not valid JSON: " + error.what());
  } catch (const std::length_error&) {
    throw InputError("queries", source + ": more than the limit of " + std::to_string(kMaxPtexLookups) + " lookups");
  } catch (const std::invalid_argument& error) {
    throw InputError("queries", source + ": not valid JSON: " + error.what());
  }
  return lookups;
}

PtexFilterFile::PtexFilterFile(const std::string& path, uint64_t max_bytes) {
  PtexFilterLimits limits;
  limits.max_bytes = max_bytes;
  const PtexStored stored = read_ptex_stored(path);
  try {
    data_ = std::make_shared<const PtexFilterData>(build_ptex_filter_data(stored, limits));
  } catch (const InputError& e) {
    throw InputError(e.field(), path + ": " + std::string(e.what()).substr(e.field().size() + 2));
  }
}

PtexFilterFile::~PtexFilterFile() = default;

int PtexFilterFile::channels() const { return data_->texture.channels; }
int PtexFilterFile::faces() const { return static_cast<int>(data_->faces.size()); }
uint64_t PtexFilterFile::bytes() const {
  return data_->texels.size() + data_->level_offsets.size() * sizeof(cl_uint) + data_->faces.size() * sizeof(PtexFilterFace);
}

void PtexFilterFile::check(const PtexLookup& lookup, const std::string& prefix) const {
  if (lookup.face < 0 || lookup.face >= faces())
    throw InputError(prefix + "face", "face " + std::to_string(lookup.face) + " is out of range: the file has " +
                                          std::to_string(faces()) + " faces (0 to " + std::to_string(faces() - 1) + ")");
  float sharpness = 0.0f;
  try {
    filter_code(lookup.filter, sharpness);
  } catch (const InputError& e) {
    throw InputError(prefix + "filter", std::string(e.what()).substr(e.field().size() + 2));
  }
  const float values[] = {lookup.u, lookup.v, lookup.uw, lookup.vw};
  const char* keys[] = {"u", "v", "uw", "vw"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(values[i]) || std::fabs(values[i]) > kMaxCoordinate)
      throw InputError(prefix + keys[i], "must be a finite number within +-1e6");
    if (i >= 2 && values[i] < 0.0f) throw InputError(prefix + keys[i], "a width must not be negative");
  }
}

std::vector<std::vector<float>> PtexFilterFile::lookup_scalar(const std::vector<PtexLookup>& lookups) const {
  std::vector<std::vector<float>> out;
  out.reserve(lookups.size());
  for (const PtexLookup& l : lookups) {
    check(l);
    const std::array<float, 4> value = ptex_filter_twin(*data_, query_of(l));
    out.emplace_back(value.begin(), value.begin() + channels());
  }
  return out;
}

std::vector<std::vector<float>> PtexFilterFile::lookup_device(ClRuntime& runtime,
                                                                 const std::vector<PtexLookup>& lookups) const {
  std::vector<PtexFilterQuery> queries;
  queries.reserve(lookups.size());
  for (const PtexLookup& l : lookups) {
    check(l);
    queries.push_back(query_of(l));
  }
  PtexFilterLauncher launcher(runtime);
  launcher.load(*data_);
  const std::vector<float> values = launcher.run(queries);
  std::vector<std::vector<float>> out(lookups.size());
  for (size_t i = 0; i < lookups.size(); ++i) out[i].assign(values.begin() + 4 * i, values.begin() + 4 * i + channels());
  return out;
}

}  // namespace seamcl
