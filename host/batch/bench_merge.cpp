#include <seamcl/batch/bench_merge.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>

#include <seamcl/batch/shard.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/options/render_options.h>

namespace seamcl {

using nlohmann::json;

json bench_timing_stats(std::vector<double> v) {
  if (v.empty()) throw std::invalid_argument("bench_timing_stats: no values");
  std::sort(v.begin(), v.end());
  const double med = median_of(v);
  auto quantile = [&](double q) {
    const double pos = q * static_cast<double>(v.size() - 1);
    const size_t i = static_cast<size_t>(pos);
    const double f = pos - static_cast<double>(i);
    return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
  };
  double mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  return {{"median", med},
          {"min", v.front()},
          {"max", v.back()},
          {"mean", mean},
          {"p10", quantile(0.1)},
          {"p90", quantile(0.9)},
          {"spread", med > 0 ? (v.back() - v.front()) / med : 0.0},
          {"frames", v.size()}};
}

double mean_in_order(const std::vector<double>& values) {
  double s = 0;
  for (double x : values) s += x;
  return values.empty() ? 0.0 : s / static_cast<double>(values.size());
}

namespace {

// A value as an error shows it: its JSON, cut short.
std::string shown(const json& value) {
  const std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  return text.size() > 40 ? text.substr(0, 40) + "..." : text;
}

// Counts (pixels, frames, bytes) are at most 2^53: exact in a double, and sums over the parts
// cannot overflow.
constexpr int64_t kMaxCount = int64_t{1} << 53;

// Reading a part defensively: every missing key, wrong type or value out of range is an
// InputError naming the key's path and the part.
class Reader {
 public:
  explicit Reader(const BenchPart& part) : part_(part) {}

  [[noreturn]] void refuse(const std::string& path, const std::string& why) const {
    throw InputError(path, part_.name + ": " + why);
  }
  const json& at(const json& object, const std::string& key, const std::string& path) const {
    if (!object.is_object()) refuse(path, "expected an object around '" + key + "'");
    const auto it = object.find(key);
    if (it == object.end()) refuse(path, "missing (is this `seamcl bench --shard K/N --json` output?)");
    return *it;
  }
  const json& array(const json& object, const std::string& key, const std::string& path) const {
    const json& a = at(object, key, path);
    if (!a.is_array()) refuse(path, "expected an array");
    return a;
  }
  const json& object_field(const json& object, const std::string& key, const std::string& path) const {
    const json& o = at(object, key, path);
    if (!o.is_object()) refuse(path, "expected an object");
    return o;
  }
  const std::string& string(const json& object, const std::string& key, const std::string& path) const {
    const json& v = at(object, key, path);
    if (!v.is_string()) refuse(path, "expected a string, got " + shown(v));
    return v.get_ref<const std::string&>();
  }
  double number(const json& value, const std::string& path) const {
    if (!value.is_number()) refuse(path, "expected a number");
    const double d = value.get<double>();
    if (!std::isfinite(d)) refuse(path, "expected a finite number");
    return d;
  }
  double number(const json& object, const std::string& key, const std::string& path) const {
    return number(at(object, key, path), path);
  }
  // A measurement (a time, an error distance): a finite number >= 0.
  double measure(const json& value, const std::string& path) const {
    const double d = number(value, path);
    if (d < 0) refuse(path, "expected a number >= 0, got " + shown(value));
    return d;
  }
  double measure(const json& object, const std::string& key, const std::string& path) const {
    return measure(at(object, key, path), path);
  }
  // The one way an integer is read: a JSON integer in lo..hi, never a fraction, a string or a
  // value cut down to fit.
  int64_t integer(const json& value, const std::string& path, int64_t lo, int64_t hi) const {
    const std::string range = std::to_string(lo) + ".." + std::to_string(hi);
    if (!value.is_number_integer()) refuse(path, "expected an integer in " + range + ", got " + shown(value));
    const bool in_range = value.is_number_unsigned()
                              ? hi >= 0 && value.get<uint64_t>() <= static_cast<uint64_t>(hi) &&
                                    static_cast<int64_t>(value.get<uint64_t>()) >= lo
                              : value.get<int64_t>() >= lo && value.get<int64_t>() <= hi;
    if (!in_range) refuse(path, "must be in " + range + ", got " + shown(value));
    return value.is_number_unsigned() ? static_cast<int64_t>(value.get<uint64_t>()) : value.get<int64_t>();
  }
  int64_t integer(const json& object, const std::string& key, const std::string& path, int64_t lo, int64_t hi) const {
    return integer(at(object, key, path), path, lo, hi);
  }
  uint64_t count(const json& value, const std::string& path) const {
    return static_cast<uint64_t>(integer(value, path, 0, kMaxCount));
  }
  uint64_t count(const json& object, const std::string& key, const std::string& path) const {
    return count(at(object, key, path), path);
  }
  // total + n for counts summed over frames or parts, refused (naming this part) past the bound of
  // a count: each is at most 2^53, so a sum of many could pass 2^64 and wrap.
  uint64_t add(uint64_t total, uint64_t n, const std::string& path) const {
    if (total > static_cast<uint64_t>(kMaxCount) || n > static_cast<uint64_t>(kMaxCount) - total)
      refuse(path, "sums past 2^53 with the counts before it");
    return total + n;
  }
  const std::string& name() const { return part_.name; }

  // The part's frames [first, end), once its shard is checked.
  void set_frames(int first, int end) {
    first_ = first;
    end_ = end;
  }
  int first_frame() const { return first_; }
  int end_frame() const { return end_; }
  // A frame index of this part.
  int frame(const json& object, const std::string& key, const std::string& path) const {
    return static_cast<int>(integer(object, key, path, first_, end_ - 1));
  }
  // object[key]: one value per frame of the part, each passed to check(value).
  template <class Check>
  const json& per_frame(const json& object, const std::string& key, const std::string& path, Check check) const {
    const json& a = array(object, key, path);
    if (a.size() != static_cast<size_t>(end_ - first_)) {
      refuse(path, std::to_string(a.size()) + " values for the part's " + std::to_string(end_ - first_) + " frames");
    }
    for (const json& v : a) check(v);
    return a;
  }

 private:
  const BenchPart& part_;
  int first_ = 0, end_ = 0;
};

// Appends a[key] of every part, in part order (the parts are sorted by their frames).
json concat(const std::vector<Reader>& readers, const std::vector<const json*>& objects, const std::string& key,
            const std::string& path) {
  json out = json::array();
  for (size_t i = 0; i < objects.size(); ++i) {
    for (const json& v : readers[i].array(*objects[i], key, path)) out.push_back(v);
  }
  return out;
}

std::vector<double> numbers(const Reader& reader, const json& array, const std::string& path) {
  std::vector<double> out;
  out.reserve(array.size());
  for (const json& v : array) out.push_back(reader.number(v, path));
  return out;
}

// Keys that must be equal in every part (the same batch); the first part's value is kept.
void require_same(const std::vector<Reader>& readers, const std::vector<const json*>& objects,
                  const std::vector<std::string>& keys, const std::string& prefix, json& out) {
  for (const std::string& key : keys) {
    const std::string path = prefix + key;
    const json& first = readers[0].at(*objects[0], key, path);
    for (size_t i = 1; i < objects.size(); ++i) {
      if (readers[i].at(*objects[i], key, path) != first) {
        readers[i].refuse(path, "differs from " + readers[0].name() + "'s: parts of different batches");
      }
    }
    out[key] = first;
  }
}

// A curve [[x, fraction of n], ...] of every part -> the curve of the pooled pixels: the
// fractions become counts again (each is count / n in double, so rounding recovers the count),
// are summed and divided by the summed n, as one run divides its count.
json merge_curve(const std::vector<Reader>& readers, const std::vector<const json*>& curves,
                 const std::vector<uint64_t>& pixels, const std::string& path) {
  std::vector<uint64_t> counts;
  json xs = json::array();
  uint64_t total_pixels = 0;
  for (size_t i = 0; i < curves.size(); ++i) {
    const Reader& r = readers[i];
    const json& curve = *curves[i];
    if (!curve.is_array()) r.refuse(path, "expected an array");
    const uint64_t n = pixels[i];
    if (i == 0) counts.assign(curve.size(), 0);
    if (curve.size() != counts.size()) r.refuse(path, "has another number of points than " + readers[0].name() + "'s");
    for (size_t j = 0; j < curve.size(); ++j) {
      if (!curve[j].is_array() || curve[j].size() != 2) r.refuse(path, "expected [x, fraction] pairs");
      (void)r.number(curve[j][0], path);
      const double fraction = r.number(curve[j][1], path);
      if (i == 0) {
        xs.push_back(curve[j][0]);
      } else if (curve[j][0] != xs[j]) {
        r.refuse(path, "has other x values than " + readers[0].name() + "'s");
      }
      const double c = fraction * static_cast<double>(n);
      const double rounded = std::round(c);
      if (fraction < 0 || fraction > 1 || std::abs(c - rounded) > 1e-6 * std::max(1.0, c)) {
        r.refuse(path, "a fraction that is not a count of the " + std::to_string(n) + " pixels");
      }
      counts[j] = r.add(counts[j], static_cast<uint64_t>(rounded), path);
    }
    total_pixels = r.add(total_pixels, n, path);
  }
  json out = json::array();
  for (size_t j = 0; j < counts.size(); ++j) {
    out.push_back({xs[j], total_pixels == 0 ? 0.0 : static_cast<double>(counts[j]) / static_cast<double>(total_pixels)});
  }
  return out;
}

// Both curves of a pooled statistic: `curve` over `pixels`, `seam_curve` over `seam_pixels`
// (the counts read from counts_of[i]).
void merge_curves(const std::vector<Reader>& readers, const std::vector<const json*>& curve_owners,
                  const std::vector<const json*>& counts_of, const std::string& prefix, const std::string& count_prefix,
                  json& out) {
  for (const auto& [key, pixels_key] : std::vector<std::pair<std::string, std::string>>{
           {"curve", "pixels"}, {"seam_curve", "seam_pixels"}}) {
    std::vector<const json*> curves;
    std::vector<uint64_t> pixels;
    for (size_t i = 0; i < curve_owners.size(); ++i) {
      curves.push_back(&readers[i].at(*curve_owners[i], key, prefix + key));
      pixels.push_back(readers[i].count(*counts_of[i], pixels_key, count_prefix + pixels_key));
    }
    out[key] = merge_curve(readers, curves, pixels, prefix + key);
  }
}

// The pooled error statistics of errors_json (plus `frames` where present), of every part.
json merge_errors(const std::vector<Reader>& readers, const std::vector<const json*>& objects,
                  const std::string& prefix, json out) {
  for (const char* key : {"pixels", "seam_pixels", "off_seam_pixels", "nan_pixels", "seam_nan_pixels"}) {
    uint64_t sum = 0;
    for (size_t i = 0; i < objects.size(); ++i) sum = readers[i].add(sum, readers[i].count(*objects[i], key, prefix + key), prefix + key);
    out[key] = sum;
  }
  if (objects[0]->contains("frames")) {
    uint64_t sum = 0;
    for (size_t i = 0; i < objects.size(); ++i)
      sum = readers[i].add(sum, readers[i].count(*objects[i], "frames", prefix + "frames"), prefix + "frames");
    out["frames"] = sum;
  }
  // (statistic prefix, its pixel count)
  const std::vector<std::pair<std::string, std::string>> pools = {
      {"", "pixels"}, {"seam_", "seam_pixels"}, {"off_seam_", "off_seam_pixels"}};
  for (const auto& [pool, pixels_key] : pools) {
    double weighted = 0, largest = 0, largest_p99 = 0;
    uint64_t pixels = 0;
    for (size_t i = 0; i < objects.size(); ++i) {
      const Reader& r = readers[i];
      const uint64_t n = r.count(*objects[i], pixels_key, prefix + pixels_key);
      const double mean = r.measure(*objects[i], pool + "mean", prefix + pool + "mean");
      const double max = r.measure(*objects[i], pool + "max", prefix + pool + "max");
      const double p99 = r.measure(*objects[i], pool + "p99", prefix + pool + "p99");
      if (n == 0) continue;
      weighted += mean * static_cast<double>(n);
      pixels = r.add(pixels, n, prefix + pixels_key);
      largest = std::max(largest, max);
      largest_p99 = std::max(largest_p99, p99);
    }
    out[pool + "mean"] = pixels == 0 ? 0.0 : weighted / static_cast<double>(pixels);
    out[pool + "max"] = largest;
    out[pool + "p99"] = largest_p99;
  }
  // bench's pooled seam_coverage: kept when the parts agree, else pixel-weighted.
  {
    const double first = readers[0].measure(*objects[0], "seam_coverage", prefix + "seam_coverage");
    bool same = true;
    double weighted = 0;
    uint64_t pixels = 0;
    for (size_t i = 0; i < objects.size(); ++i) {
      const double c = readers[i].measure(*objects[i], "seam_coverage", prefix + "seam_coverage");
      const uint64_t n = readers[i].count(*objects[i], "pixels", prefix + "pixels");
      same = same && c == first;
      weighted += c * static_cast<double>(n);
      pixels = readers[i].add(pixels, n, prefix + "pixels");
    }
    out["seam_coverage"] = same ? first : (pixels == 0 ? 0.0 : weighted / static_cast<double>(pixels));
  }
  return out;
}

// One part's results[e], every key the merge reads, checked before any of it is used.
void check_result(const Reader& r, const json& item, bool with_errors, const std::string& prefix) {
  (void)r.string(item, "method", prefix + "method");
  (void)r.string(item, "filter", prefix + "filter");
  (void)r.integer(item, "msaa", prefix + "msaa", 1, 16);
  (void)r.integer(item, "aniso", prefix + "aniso", 1, 16);
  for (const char* key : {"texture_bytes", "padding_bytes", "adjacency_bytes"}) (void)r.count(item, key, prefix + key);
  const auto measures = [&r](const std::string& path) {
    return [&r, path](const json& v) { (void)r.measure(v, path); };
  };
  r.per_frame(item, "ms_per_frame", prefix + "ms_per_frame", measures(prefix + "ms_per_frame"));
  const json& stages = r.object_field(item, "ms_stages_per_frame", prefix + "ms_stages_per_frame");
  for (const auto& [stage, unused] : stages.items()) {
    (void)unused;
    const std::string path = prefix + "ms_stages_per_frame." + stage;
    r.per_frame(stages, stage, path, measures(path));
  }
  const std::string nan_path = prefix + "nan_pixels_per_frame";
  uint64_t nan_sum = 0;
  r.per_frame(item, "nan_pixels_per_frame", nan_path, [&](const json& v) { nan_sum = r.add(nan_sum, r.count(v, nan_path), nan_path); });
  if (r.count(item, "nan_pixels", prefix + "nan_pixels") != nan_sum) {
    r.refuse(prefix + "nan_pixels", "is not the sum of nan_pixels_per_frame (" + std::to_string(nan_sum) + ")");
  }
  const std::string temporal = prefix + "temporal_per_frame";
  for (const json& pair : r.array(item, "temporal_per_frame", temporal)) {
    (void)r.frame(pair, "frame", temporal + ".frame");
    (void)r.measure(pair, "mean", temporal + ".mean");
    const json& seam = r.at(pair, "seam_mean", temporal + ".seam_mean");
    if (!seam.is_null()) (void)r.measure(seam, temporal + ".seam_mean");
  }
  if (with_errors) {
    (void)r.object_field(item, "error", prefix + "error");
    const std::string errors = prefix + "error_per_frame";
    for (const json& e : r.array(item, "error_per_frame", errors)) {
      (void)r.frame(e, "frame", errors + ".frame");
      for (const char* key : {"mean", "p99", "seam_mean"}) (void)r.measure(e, key, errors + "." + key);
      (void)r.count(e, "nan_pixels", errors + ".nan_pixels");
    }
  }
}

json merge_result(const std::vector<Reader>& readers, const std::vector<const json*>& items, bool with_errors,
                  const std::string& prefix) {
  for (size_t i = 0; i < items.size(); ++i) check_result(readers[i], *items[i], with_errors, prefix);
  json out = json::object();
  require_same(readers, items, {"method", "msaa", "aniso", "filter", "texture_bytes", "padding_bytes", "adjacency_bytes"},
               prefix, out);
  // Times: the samples of every frame, then their statistics as one run computes them.
  out["ms_per_frame"] = concat(readers, items, "ms_per_frame", prefix + "ms_per_frame");
  std::vector<double> total;
  for (const json& v : out["ms_per_frame"]) total.push_back(v.get<double>());  // checked per part above
  json ms = bench_timing_stats(total);
  json stages_per_frame = json::object();
  json stage_medians = json::object();
  const json& first_stages = (*items[0])["ms_stages_per_frame"];
  std::vector<const json*> stage_objects;
  for (size_t i = 0; i < items.size(); ++i) {
    stage_objects.push_back(&(*items[i])["ms_stages_per_frame"]);
    if (stage_objects.back()->size() != first_stages.size()) {
      readers[i].refuse(prefix + "ms_stages_per_frame", "has other stages than " + readers[0].name() + "'s");
    }
  }
  for (const auto& [stage, unused] : first_stages.items()) {
    (void)unused;
    stages_per_frame[stage] = concat(readers, stage_objects, stage, prefix + "ms_stages_per_frame." + stage);
    stage_medians[stage] = median_of(numbers(readers[0], stages_per_frame[stage], prefix + "ms_stages_per_frame." + stage));
  }
  ms["stages"] = stage_medians;
  out["ms"] = ms;
  out["ms_stages_per_frame"] = stages_per_frame;

  out["nan_pixels_per_frame"] = concat(readers, items, "nan_pixels_per_frame", prefix + "nan_pixels_per_frame");
  uint64_t nan_total = 0;
  for (size_t i = 0; i < items.size(); ++i)  // each part's sum, checked there, summed checked
    nan_total = readers[i].add(nan_total, readers[i].count(*items[i], "nan_pixels", prefix + "nan_pixels"), prefix + "nan_pixels");
  out["nan_pixels"] = nan_total;

  // Temporal: the per-pair values in frame order (each part carries the pair across its first
  // frame), averaged as one run averages them; pairs without seam pixels have seam_mean null.
  out["temporal_per_frame"] = concat(readers, items, "temporal_per_frame", prefix + "temporal_per_frame");
  std::vector<double> all, seam;
  for (const json& pair : out["temporal_per_frame"]) {  // checked per part above
    all.push_back(pair["mean"].get<double>());
    if (!pair["seam_mean"].is_null()) seam.push_back(pair["seam_mean"].get<double>());
  }
  out["temporal"] = {{"seam_mean", finite_or_zero(mean_in_order(seam))},
                     {"mean", finite_or_zero(mean_in_order(all))},
                     {"pairs", all.size()},
                     {"seam_pairs", seam.size()}};

  if (with_errors) {
    std::vector<const json*> errors;
    for (size_t i = 0; i < items.size(); ++i) errors.push_back(&readers[i].at(*items[i], "error", prefix + "error"));
    out["error"] = merge_errors(readers, errors, prefix + "error.", json::object());
    merge_curves(readers, items, errors, prefix, prefix + "error.", out);
    out["error_per_frame"] = concat(readers, items, "error_per_frame", prefix + "error_per_frame");
  }
  return out;
}

json merge_difference(const std::vector<Reader>& readers, const std::vector<const json*>& items,
                      const std::string& prefix) {
  for (size_t i = 0; i < items.size(); ++i) {
    (void)readers[i].string(*items[i], "a", prefix + "a");
    (void)readers[i].string(*items[i], "b", prefix + "b");
    (void)readers[i].integer(*items[i], "msaa", prefix + "msaa", 1, 16);
  }
  json out = json::object();
  require_same(readers, items, {"a", "b", "msaa"}, prefix, out);
  out = merge_errors(readers, items, prefix, out);
  merge_curves(readers, items, items, prefix, prefix, out);
  return out;
}

json merge_notes() {
  return {
      {"exact",
       {"results[].ms_per_frame, ms_stages_per_frame, nan_pixels_per_frame, error_per_frame, temporal_per_frame: "
        "concatenated in frame order",
        "seam_pixels_per_frame, error_frames: concatenated in frame order",
        "results[].nan_pixels, error.{pixels, seam_pixels, off_seam_pixels, nan_pixels, seam_nan_pixels, frames}, "
        "reference.{cached, rendered}: sums",
        "results[].error.{max, seam_max, off_seam_max}, differences[].{max, seam_max, off_seam_max}: the largest part's",
        "results[].curve, seam_curve, differences[].curve, seam_curve: counts of pixels summed, over the summed pixels"}},
      {"recomputed",
       {"results[].ms.{median, min, max, mean, p10, p90, spread, frames} and ms.stages: from the merged "
        "ms_per_frame and ms_stages_per_frame, with bench's own functions (timings are new measurements in every run)",
        "results[].temporal: from the merged temporal_per_frame, in frame order (each part renders the frame "
        "before its first, so no pair is lost at a part's edge)"}},
      {"inexact",
       {"results[].error.{mean, seam_mean, off_seam_mean}, differences[].{mean, seam_mean, off_seam_mean}: "
        "pixel-weighted means of the parts' means (an unsharded run sums the sorted pooled pixels: equal to "
        "about 1e-15 relative, not bit for bit)",
        "results[].error.{p99, seam_p99, off_seam_p99}, differences[].{p99, ...}: the largest part's p99, an "
        "upper bound of the pooled nearest-rank p99 (which needs every pixel)",
        "wall_s, reference.ms: sums over the parts (work done, not the batch's wall time)"}}};
}

// A part's own top-level keys (results and differences are checked entry by entry as they are
// merged): types, and the ranges bench itself allows. The parts come in shard order, and their
// frames must tile 0..frames-1 in order: this one's start at expected_first, which moves to its
// end. Sets the reader's frames.
void check_part(Reader& r, const json& top, int& expected_first) {
  for (const char* key : {"scene", "size", "order", "device"}) (void)r.string(top, key, key);
  if (top.contains("seam_mask")) (void)r.string(top, "seam_mask", "seam_mask");
  const int frames = static_cast<int>(r.integer(top, "frames", "frames", 1, kMaxFrames));
  (void)r.integer(top, "reference_frames", "reference_frames", 1, INT32_MAX);
  const json& errors = r.at(top, "errors", "errors");
  if (!errors.is_boolean()) r.refuse("errors", "expected true or false");
  (void)r.integer(top, "seam_radius", "seam_radius", 0, INT32_MAX);
  (void)r.object_field(top, "options", "options");
  (void)r.measure(top, "wall_s", "wall_s");
  const json& shard = r.at(top, "shard", "shard");
  const int first = static_cast<int>(r.integer(shard, "first_frame", "shard.first_frame", 0, frames - 1));
  const int end = static_cast<int>(r.integer(shard, "end_frame", "shard.end_frame", 1, frames));
  if (first != expected_first || end <= first) {
    r.refuse("shard.first_frame", "frames [" + std::to_string(first) + ", " + std::to_string(end) +
                                      ") do not continue the parts before it at frame " +
                                      std::to_string(expected_first));
  }
  expected_first = end;
  r.set_frames(first, end);
  for (const json& k : r.array(top, "error_frames", "error_frames")) (void)r.integer(k, "error_frames", first, end - 1);
  r.per_frame(top, "seam_pixels_per_frame", "seam_pixels_per_frame",
              [&r](const json& v) { (void)r.count(v, "seam_pixels_per_frame"); });
  if (r.array(top, "results", "results").empty()) {
    r.refuse("results", "no entries (a part measures one method at least)");
  }
  (void)r.array(top, "differences", "differences");
  if (errors.get<bool>()) {
    // A part without an error frame made no reference: its method is "" and its msaa 0.
    const json& reference = r.object_field(top, "reference", "reference");
    const std::string prefix = "reference.";
    for (const char* key : {"method", "filter"}) (void)r.string(reference, key, prefix + key);
    (void)r.integer(reference, "msaa", prefix + "msaa", 0, 16);
    for (const char* key : {"scale", "filter_width", "B", "C"}) (void)r.number(reference, key, prefix + key);
    (void)r.count(reference, "cached", "reference.cached");
    (void)r.count(reference, "rendered", "reference.rendered");
    (void)r.measure(reference, "ms", "reference.ms");
  }
}

}  // namespace

json merge_bench_parts(const std::vector<BenchPart>& input) {
  if (input.empty()) throw InputError("parts", "no parts to merge");
  // Order the parts by their shard index, checking that they are the N parts of one batch.
  std::vector<Reader> readers;
  std::vector<std::pair<int, size_t>> order;  // (index, position in input)
  int count = 0;
  std::map<int, std::string> seen;
  for (size_t i = 0; i < input.size(); ++i) {
    Reader r(input[i]);
    if (!input[i].json.is_object()) r.refuse("parts", "not a JSON object");
    const json& shard = r.at(input[i].json, "shard", "shard");
    const int index = static_cast<int>(r.integer(shard, "index", "shard.index", 1, kMaxShards));
    const int n = static_cast<int>(r.integer(shard, "count", "shard.count", 1, kMaxShards));
    if (index > n) {
      r.refuse("shard.index", "must be in 1..count (" + std::to_string(n) + "), got " + std::to_string(index));
    }
    if (i == 0) count = n;
    if (n != count) r.refuse("shard.count", "is " + std::to_string(n) + ", " + input[0].name + "'s is " + std::to_string(count));
    const auto [it, fresh] = seen.emplace(index, input[i].name);
    if (!fresh) r.refuse("shard.index", "part " + std::to_string(index) + "/" + std::to_string(n) + " is also " + it->second);
    order.emplace_back(index, i);
  }
  if (static_cast<int>(order.size()) != count) {
    std::string missing;
    for (int k = 1; k <= count && missing.size() < 200; ++k) {
      if (!seen.count(k)) missing += (missing.empty() ? "" : ", ") + std::to_string(k) + "/" + std::to_string(count);
    }
    throw InputError("parts", "parts missing: " + missing + " (got " + std::to_string(order.size()) + " of " +
                                  std::to_string(count) + ")");
  }
  std::sort(order.begin(), order.end());
  std::vector<const json*> tops;
  int expected_first = 0;  // where the next part's frames start
  for (const auto& [index, i] : order) {
    (void)index;
    readers.emplace_back(input[i]);
    tops.push_back(&input[i].json);
    check_part(readers.back(), input[i].json, expected_first);
  }

  json out = json::object();
  require_same(readers, tops, {"scene", "size", "frames", "reference_frames", "errors", "order", "seam_radius", "options"},
               "", out);
  // Parts written before bench had --seam-mask carry no seam_mask: they pooled the band.
  const auto mask_of = [](const json& part) { return part.contains("seam_mask") ? part["seam_mask"] : json("band"); };
  for (size_t i = 1; i < tops.size(); ++i) {
    if (mask_of(*tops[i]) != mask_of(*tops[0])) {
      readers[i].refuse("seam_mask", "differs from " + readers[0].name() + "'s: parts of different batches");
    }
  }
  out["seam_mask"] = mask_of(*tops[0]);
  const bool with_errors = out["errors"].get<bool>();  // checked by check_part, as frames
  const int frames = static_cast<int>(out["frames"].get<int64_t>());

  json parts_info = json::array();
  for (size_t i = 0; i < tops.size(); ++i) {
    const Reader& r = readers[i];
    const json& top = *tops[i];  // every key checked by check_part
    parts_info.push_back({{"name", r.name()},
                          {"shard", std::to_string(top["shard"]["index"].get<int64_t>()) + "/" + std::to_string(count)},
                          {"first_frame", r.first_frame()},
                          {"end_frame", r.end_frame()},
                          {"wall_s", top["wall_s"].get<double>()},
                          {"device", top["device"]}});
  }
  // check_part saw the parts' frames tile 0..expected_first-1 in order: they must reach the end.
  if (expected_first != frames) {
    readers.back().refuse("shard.end_frame", "the parts end at frame " + std::to_string(expected_first) + " of " +
                                                 std::to_string(frames));
  }

  // One device for all, or the distinct ones named together.
  std::vector<std::string> devices;
  for (const json& p : parts_info) {
    const std::string d = p["device"].get<std::string>();
    if (std::find(devices.begin(), devices.end(), d) == devices.end()) devices.push_back(d);
  }
  std::string device;
  for (const std::string& d : devices) device += (device.empty() ? "" : " | ") + d;
  out["device"] = device;

  out["error_frames"] = concat(readers, tops, "error_frames", "error_frames");
  out["seam_pixels_per_frame"] = concat(readers, tops, "seam_pixels_per_frame", "seam_pixels_per_frame");
  double wall = 0;
  for (const json& p : parts_info) wall += p["wall_s"].get<double>();
  out["wall_s"] = wall;
  out["shard"] = {{"index", 1}, {"count", 1}, {"first_frame", 0}, {"end_frame", frames}};

  // Results: the same entries, in the same order, in every part.
  const size_t entries = readers[0].array(*tops[0], "results", "results").size();
  json results = json::array();
  for (size_t e = 0; e < entries; ++e) {
    const std::string prefix = "results[" + std::to_string(e) + "].";
    std::vector<const json*> items;
    for (size_t i = 0; i < tops.size(); ++i) {
      const json& list = readers[i].array(*tops[i], "results", "results");
      if (list.size() != entries) readers[i].refuse("results", "has another number of entries than " + readers[0].name() + "'s");
      items.push_back(&list[e]);
    }
    results.push_back(merge_result(readers, items, with_errors, prefix));
  }
  out["results"] = results;

  const size_t diffs = readers[0].array(*tops[0], "differences", "differences").size();
  json differences = json::array();
  for (size_t d = 0; d < diffs; ++d) {
    const std::string prefix = "differences[" + std::to_string(d) + "].";
    std::vector<const json*> items;
    for (size_t i = 0; i < tops.size(); ++i) {
      const json& list = readers[i].array(*tops[i], "differences", "differences");
      if (list.size() != diffs) readers[i].refuse("differences", "has another number of entries than " + readers[0].name() + "'s");
      items.push_back(&list[d]);
    }
    json merged = merge_difference(readers, items, prefix);
    uint64_t frames_sum = 0;
    for (size_t i = 0; i < items.size(); ++i)
      frames_sum = readers[i].add(frames_sum, readers[i].count(*items[i], "frames", prefix + "frames"), prefix + "frames");
    merged["frames"] = frames_sum;
    differences.push_back(merged);
  }
  out["differences"] = differences;

  if (with_errors) {
    // How references were made: from the parts that made any (a part may have no error frame).
    json reference = json::object();
    uint64_t cached = 0, rendered = 0;
    double ms = 0;
    std::vector<Reader> makers;
    std::vector<const json*> made;
    for (size_t i = 0; i < tops.size(); ++i) {
      const json& ref = readers[i].at(*tops[i], "reference", "reference");
      const uint64_t c = readers[i].count(ref, "cached", "reference.cached");
      const uint64_t r = readers[i].count(ref, "rendered", "reference.rendered");
      cached = readers[i].add(cached, c, "reference.cached");
      rendered = readers[i].add(rendered, r, "reference.rendered");
      ms += readers[i].measure(ref, "ms", "reference.ms");
      if (c + r > 0) {
        makers.push_back(readers[i]);
        made.push_back(&ref);
      }
    }
    if (made.empty()) {
      reference = readers[0].at(*tops[0], "reference", "reference");
    } else {
      require_same(makers, made, {"method", "msaa", "scale", "filter", "filter_width", "B", "C"}, "reference.", reference);
    }
    reference["cached"] = cached;
    reference["rendered"] = rendered;
    reference["ms"] = ms;
    out["reference"] = reference;
  }

  json notes = merge_notes();
  notes["parts"] = parts_info;
  out["merge"] = notes;
  return out;
}

}  // namespace seamcl
