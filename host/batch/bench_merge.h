// Merging the parts of a sharded `seamcl bench` (`--shard K/N --json`, one JSON object per part)
// into the JSON one unsharded run gives, and the summary statistics bench and the merge share (so
// that both compute them with the same code from the same samples).
//
// What merges how (the merged JSON's `merge` key repeats this, key by key):
// - exact: everything per frame (ms_per_frame, ms_stages_per_frame, nan_pixels_per_frame,
//   error_per_frame, temporal_per_frame, seam_pixels_per_frame, error_frames) is concatenated in
//   frame order; counts (pixels, nan pixels, frames, references cached/rendered) are summed;
//   maxima are the largest part's; the error curves are fractions of counted pixels, so they
//   merge as sums of counts over the summed pixels, exactly as one run divides them.
// - recomputed: the timing statistics (median, min, max, mean, p10, p90, spread, the stage
//   medians) and the temporal means come from the merged per-frame samples, with the functions
//   below, in frame order: what one run that had measured those samples reports, bit for bit.
//   (Timings are new measurements in every run, so they never equal another run's.)
// - inexact: the pooled error means (mean, seam_mean, off_seam_mean) are the pixel-weighted means
//   of the parts' means (one run sums every pixel in sorted order: equal to about 1e-15
//   relative, not bit for bit); the pooled p99s are the largest part's p99, an upper bound of the
//   pooled nearest-rank p99 (which needs every pixel); wall_s and reference.ms are sums over the
//   parts (work done, not the wall time of the batch).
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace seamcl {

// bench's timing summary of per-frame values: {median, min, max, mean, p10, p90 (linear
// interpolation between ranks), spread ((max - min) / median), frames}. Needs one value at least.
nlohmann::json bench_timing_stats(std::vector<double> values);

// The arithmetic mean, summed in the order given; 0 for no values.
double mean_in_order(const std::vector<double>& values);

struct BenchPart {
  std::string name;     // where the part came from (its file), named in every error about it
  nlohmann::json json;  // `seamcl bench --shard K/N --json` of that part
};

// The parts (any order) -> the unsharded run's JSON, plus `merge` (the parts and the lists
// above). InputError naming the key at fault and the part's name when a part is not a bench part
// (a key missing, of the wrong type, or out of the range bench writes: integers in range, never
// cut down to fit; measurements finite and >= 0; one result entry and one frame at least), the
// parts are of different batches (scene, options, methods, rates, frames...), a part appears
// twice, or parts are missing.
nlohmann::json merge_bench_parts(const std::vector<BenchPart>& parts);

}  // namespace seamcl
