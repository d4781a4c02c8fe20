// Lookups of Ptex's own filters on a .ptx file (`seamcl ptx lookup`): the options of one lookup
// declared once in an option table (the command line's flags and the query file's keys alike),
// the filters by name, and a texture opened for them. Values come from the device
// (kernels/ptex_filter.cl) or from its scalar twin, the same within float rounding.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/options/option_table.h>

namespace seamcl {

// face, u, v, uw, vw, filter, sharpness.
const OptionTable& ptex_lookup_option_table();

// "box", "bilinear", ..., each also with the "ptex-" prefix the renderer's filter family uses.
const std::vector<std::string>& ptex_filter_names();

struct PtexLookup {
  int face = 0;
  float u = 0.5f, v = 0.5f;
  float uw = 0.0f, vw = 0.0f;  // filter widths in face units (Ptex's uw1 and vw2; uw2 = vw1 = 0)
  std::string filter = "bilinear";
  float sharpness = 0.0f;      // bicubic only: 0 B-spline, 1 Catmull-Rom
};

// One lookup from a JSON object of the table's keys (others, such as a golden entry's "value",
// are ignored); InputError(field + "." + key) for a bad value, naming the key.
PtexLookup parse_ptex_lookup(const nlohmann::json& object, const std::string& field = "");
// A JSON array of such objects; fields are named "queries[i].key".
std::vector<PtexLookup> parse_ptex_lookups(const nlohmann::json& array, const std::string& field = "queries");

// The most lookups parse_ptex_lookups_from_text takes from one text.
inline constexpr size_t kMaxPtexLookups = size_t(1) << 22;

// Lookups from JSON text holding an array of such objects (a query file, named `source` in
// messages), each checked as it is read, so that one entry's JSON is held at a time whatever the
// text's length. InputError("queries") for text that is not a JSON array or holds more than
// kMaxPtexLookups entries, InputError("queries[i].key") for a bad value.
std::vector<PtexLookup> parse_ptex_lookups_from_text(std::string_view text, const std::string& source);

struct PtexFilterData;

class PtexFilterFile {
 public:
  // Reads the file (InputError("texture") as read_ptex_file) and builds every resolution the
  // filters read, refusing more than max_bytes.
  explicit PtexFilterFile(const std::string& path, uint64_t max_bytes = uint64_t(1) << 30);
  ~PtexFilterFile();

  int channels() const;
  int faces() const;
  uint64_t bytes() const;  // texels and tables as the device holds them

  // InputError naming the field (prefix + "face") for a face out of range.
  void check(const PtexLookup& lookup, const std::string& prefix = "") const;

  // Values, `channels()` per lookup: the scalar twin, or the device.
  std::vector<std::vector<float>> lookup_scalar(const std::vector<PtexLookup>& lookups) const;
  std::vector<std::vector<float>> lookup_device(ClRuntime& runtime, const std::vector<PtexLookup>& lookups) const;

  const PtexFilterData& data() const { return *data_; }

 private:
  std::shared_ptr<const PtexFilterData> data_;
};

}  // namespace seamcl
