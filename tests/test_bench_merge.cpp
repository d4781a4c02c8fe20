// Sharded batch work (host/batch/shard.h, host/batch/bench_merge.h, `seamcl bench --shard K/N`,
// `seamcl merge`): the parts of a bench, merged, give what one unsharded run gives, exactly for
// everything per frame, counted, summed or maximal, and as documented for the rest; bad shards and
// parts that do not belong together are refused naming the field.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/batch/bench_merge.h>
#include <seamcl/batch/shard.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>

namespace fs = std::filesystem;
using nlohmann::json;
using namespace seamcl;

namespace {

struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

fs::path make_temp_dir() {
  std::string pattern = (fs::temp_directory_path() / "seamcl_merge_XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  return pattern;
}

// seamcl with `args` in `dir`, the reference cache in dir/cache (shared by every run of a test,
// so the parts read the references the unsharded run wrote, as a farm's shared cache does).
CliRun seamcl(const fs::path& dir, const std::string& args) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = "cd '" + dir.string() + "' && SEAMCL_CACHE_DIR='" + (dir / "cache").string() + "' '" +
                              SEAMCL_BINARY + "' " + args + " >'" + out.string() + "' 2>'" + err.string() +
                              "' </dev/null";
  const int status = std::system(command.c_str());
  CliRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// Five frames, errors on frames 0, 2, 4, discard and traverse (so `differences` has entries).
const char* kBench = "bench --scene quad2 --methods discard,traverse,clamp --msaa 1,4 --size 40x36 --frames 5 "
                     "--reference-frames 2 --json";

class BenchMerge : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(make_temp_dir());
    whole_ = new CliRun(seamcl(*dir_, kBench));
    parts_ = new std::vector<CliRun>();
    for (int k = 1; k <= 3; ++k) {
      CliRun part = seamcl(*dir_, std::string(kBench) + " --shard " + std::to_string(k) + "/3");
      std::ofstream(*dir_ / ("part" + std::to_string(k) + ".json")) << part.out;
      parts_->push_back(part);
    }
    // In another order than the frames', to show the order does not matter.
    merge_ = new CliRun(seamcl(*dir_, "merge part3.json part1.json part2.json -o merged.json"));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
    delete whole_;
    delete parts_;
    delete merge_;
  }
  static json whole() { return json::parse(whole_->out); }
  static json merged() { return json::parse(slurp(*dir_ / "merged.json")); }
  static json part(int k) { return json::parse((*parts_)[static_cast<size_t>(k - 1)].out); }
  static std::vector<BenchPart> library_parts() {
    std::vector<BenchPart> parts;
    for (int k = 1; k <= 3; ++k) parts.push_back({"part" + std::to_string(k) + ".json", part(k)});
    return parts;
  }

  static fs::path* dir_;
  static CliRun* whole_;
  static std::vector<CliRun>* parts_;
  static CliRun* merge_;
};
fs::path* BenchMerge::dir_ = nullptr;
CliRun* BenchMerge::whole_ = nullptr;
std::vector<CliRun>* BenchMerge::parts_ = nullptr;
CliRun* BenchMerge::merge_ = nullptr;

// The pooled error keys that merge exactly, and the means that merge to rounding.
const std::vector<std::string> kExactErrorKeys = {"pixels",   "seam_pixels", "off_seam_pixels", "nan_pixels",
                                                  "seam_nan_pixels", "max", "seam_max", "off_seam_max"};
const std::vector<std::string> kMeanKeys = {"mean", "seam_mean", "off_seam_mean"};

void expect_pooled_errors_merged(const json& merged, const json& whole) {
  for (const std::string& k : kExactErrorKeys) EXPECT_EQ(merged[k], whole[k]) << k;
  for (const std::string& k : kMeanKeys) {
    EXPECT_NEAR(merged[k].get<double>(), whole[k].get<double>(), 1e-12 * std::max(1.0, whole[k].get<double>())) << k;
  }
  for (const std::string& pool : {std::string(""), std::string("seam_"), std::string("off_seam_")}) {
    // The largest part's p99 bounds the pooled p99 from above; no part's p99 exceeds the max.
    EXPECT_GE(merged[pool + "p99"].get<double>(), whole[pool + "p99"].get<double>()) << pool;
    EXPECT_LE(merged[pool + "p99"].get<double>(), whole[pool + "max"].get<double>()) << pool;
  }
}

TEST_F(BenchMerge, PartsCoverTheOrbitInContiguousBlocks) {
  ASSERT_EQ(whole_->exit_code, 0) << whole_->err;
  int expected_first = 0;
  for (int k = 1; k <= 3; ++k) {
    ASSERT_EQ((*parts_)[static_cast<size_t>(k - 1)].exit_code, 0) << (*parts_)[static_cast<size_t>(k - 1)].err;
    const json p = part(k);
    EXPECT_EQ(p["shard"]["index"], k);
    EXPECT_EQ(p["shard"]["count"], 3);
    EXPECT_EQ(p["shard"]["first_frame"], expected_first);
    const int end = p["shard"]["end_frame"];
    EXPECT_EQ(end, k * 5 / 3);
    EXPECT_EQ(p["frames"], 5);  // the orbit's length, not the part's
    for (const json& r : p["results"]) EXPECT_EQ(r["ms_per_frame"].size(), static_cast<size_t>(end - expected_first));
    expected_first = end;
  }
  EXPECT_EQ(expected_first, 5);
  EXPECT_EQ(whole()["shard"], json({{"index", 1}, {"count", 1}, {"first_frame", 0}, {"end_frame", 5}}));
}

TEST_F(BenchMerge, MergedPerFrameErrorsEqualTheUnshardedRunExactly) {
  ASSERT_EQ(whole_->exit_code, 0) << whole_->err;
  ASSERT_EQ(merge_->exit_code, 0) << merge_->err;
  const json w = whole(), m = merged();
  EXPECT_EQ(m["error_frames"], json::array({0, 2, 4}));
  for (const char* key : {"scene", "size", "frames", "reference_frames", "errors", "options", "error_frames",
                          "seam_pixels_per_frame", "shard", "order", "seam_mask", "seam_radius"}) {
    EXPECT_EQ(m[key], w[key]) << key;
  }
  ASSERT_EQ(m["results"].size(), w["results"].size());
  for (size_t i = 0; i < w["results"].size(); ++i) {
    const json& a = m["results"][i];
    const json& b = w["results"][i];
    SCOPED_TRACE(b["method"].get<std::string>() + " x" + std::to_string(b["msaa"].get<int>()));
    for (const char* key : {"method", "msaa", "aniso", "filter", "error_per_frame", "nan_pixels_per_frame", "nan_pixels",
                            "temporal_per_frame", "temporal", "curve", "seam_curve", "texture_bytes", "padding_bytes",
                            "adjacency_bytes"}) {
      EXPECT_EQ(a[key], b[key]) << key;
    }
    EXPECT_EQ(a["error_per_frame"].size(), 3u);
    EXPECT_EQ(a["temporal_per_frame"].size(), 4u);  // pairs (0,1) .. (3,4): none lost at the parts' edges
    EXPECT_EQ(a["error"]["frames"], b["error"]["frames"]);
    expect_pooled_errors_merged(a["error"], b["error"]);
  }
  ASSERT_EQ(m["differences"].size(), w["differences"].size());
  ASSERT_FALSE(w["differences"].empty());
  for (size_t i = 0; i < w["differences"].size(); ++i) {
    const json& a = m["differences"][i];
    const json& b = w["differences"][i];
    for (const char* key : {"a", "b", "msaa", "frames", "curve", "seam_curve"}) EXPECT_EQ(a[key], b[key]) << key;
    expect_pooled_errors_merged(a, b);
  }
  // The parts found the references the unsharded run cached; every error frame has one.
  EXPECT_EQ(m["reference"]["method"], w["reference"]["method"]);
  EXPECT_EQ(m["reference"]["cached"].get<int>() + m["reference"]["rendered"].get<int>(), 3);
}

TEST_F(BenchMerge, TimingStatisticsAreRecomputedFromTheMergedSamples) {
  ASSERT_EQ(merge_->exit_code, 0) << merge_->err;
  const json m = merged();
  for (const json& r : m["results"]) {
    std::vector<double> ms;
    for (int k = 1; k <= 3; ++k) {
      const json p = part(k);
      for (const json& item : p["results"]) {
        if (item["method"] == r["method"] && item["msaa"] == r["msaa"]) {
          for (const json& v : item["ms_per_frame"]) ms.push_back(v.get<double>());
        }
      }
    }
    EXPECT_EQ(r["ms_per_frame"], json(ms));  // frame order, parts in shard order
    json expected = bench_timing_stats(ms);
    for (const auto& [key, value] : expected.items()) EXPECT_EQ(r["ms"][key], value) << key;
    std::vector<double> shade;
    for (const json& v : r["ms_stages_per_frame"]["shade"]) shade.push_back(v.get<double>());
    EXPECT_EQ(shade.size(), 5u);
    EXPECT_EQ(r["ms"]["stages"]["shade"].get<double>(), median_of(shade));
  }
  // The merged JSON says how each kind of statistic merged.
  for (const char* list : {"exact", "recomputed", "inexact"}) EXPECT_FALSE(m["merge"][list].empty()) << list;
  EXPECT_EQ(m["merge"]["parts"].size(), 3u);
  EXPECT_EQ(m["merge"]["parts"][0]["shard"], "1/3");
}

TEST_F(BenchMerge, RefusesPartsThatDoNotMakeOneBatch) {
  const std::vector<BenchPart> parts = library_parts();
  auto field_of = [](const std::vector<BenchPart>& p) -> std::string {
    try {
      (void)merge_bench_parts(p);
    } catch (const InputError& e) {
      return e.field() + " | " + e.what();
    }
    return "merged";
  };
  EXPECT_EQ(field_of(parts), "merged");
  // A missing part.
  std::vector<BenchPart> two = {parts[0], parts[2]};
  EXPECT_EQ(field_of(two).rfind("parts | parts: parts missing: 2/3", 0), 0u) << field_of(two);
  // A part twice.
  std::vector<BenchPart> twice = {parts[0], parts[1], parts[1]};
  EXPECT_NE(field_of(twice).find("shard.index"), std::string::npos) << field_of(twice);
  // A part of another batch (other options) names the key and the part.
  std::vector<BenchPart> other = parts;
  other[1].json["options"]["aniso"] = 4;
  EXPECT_EQ(field_of(other).rfind("options | options: part2.json: differs", 0), 0u) << field_of(other);
  // Parts pooled over different seam masks; parts without the key (written before --seam-mask)
  // pooled the band, so they merge with band parts only.
  other = parts;
  other[1].json["seam_mask"] = "footprint";
  EXPECT_EQ(field_of(other).rfind("seam_mask | seam_mask: part2.json: differs", 0), 0u) << field_of(other);
  other = parts;
  for (BenchPart& p : other) p.json.erase("seam_mask");
  EXPECT_EQ(field_of(other), "merged");
  EXPECT_EQ(merge_bench_parts(other)["seam_mask"], "band");
  other[0].json["seam_mask"] = "footprint";
  EXPECT_EQ(field_of(other).rfind("seam_mask", 0), 0u) << field_of(other);
  // Another count of parts.
  other = parts;
  other[2].json["shard"]["count"] = 4;
  EXPECT_EQ(field_of(other).rfind("shard.count", 0), 0u) << field_of(other);
  // A hole between the parts' frames.
  other = parts;
  other[1].json["shard"]["first_frame"] = other[1].json["shard"]["first_frame"].get<int>() + 1;
  EXPECT_EQ(field_of(other).rfind("shard.first_frame", 0), 0u) << field_of(other);
  // Hostile values: wrong types and a curve that is not a fraction of the pixels.
  other = parts;
  other[0].json["results"][0]["ms_per_frame"] = "fast";
  EXPECT_EQ(field_of(other).rfind("results[0].ms_per_frame", 0), 0u) << field_of(other);
  other = parts;
  other[0].json["results"][0]["curve"][3][1] = 0.123456789;
  EXPECT_EQ(field_of(other).rfind("results[0].curve", 0), 0u) << field_of(other);
  other = parts;
  other[0].json.erase("shard");
  EXPECT_EQ(field_of(other).rfind("shard | shard: part1.json: missing", 0), 0u) << field_of(other);
  EXPECT_EQ(field_of({}).rfind("parts", 0), 0u);
}

// Every field the merge reads is checked for its type and range before it is used: a corrupted
// part is refused naming the field and the part, never merged with a value cut down to fit.
TEST_F(BenchMerge, RefusesCorruptedFieldsNamingTheFieldAndThePart) {
  const std::vector<BenchPart> parts = library_parts();
  // The field and the message of the merge's InputError, or "merged".
  auto refusal = [](const std::vector<BenchPart>& p) -> std::pair<std::string, std::string> {
    try {
      (void)merge_bench_parts(p);
    } catch (const InputError& e) {
      return {e.field(), e.what()};
    }
    return {"merged", ""};
  };
  // Unchanged parts still merge, to what the command wrote.
  EXPECT_EQ(refusal(parts).first, "merged");
  EXPECT_EQ(merge_bench_parts(parts), merged());

  // The probe's case: frames beyond an int in every part (once merged as frames 4294967298 with
  // shard.end_frame 2).
  std::vector<BenchPart> other = parts;
  for (BenchPart& p : other) p.json["frames"] = 4294967298ull;
  auto [field, message] = refusal(other);
  EXPECT_EQ(field, "frames");
  EXPECT_EQ(message, "frames: part1.json: must be in 1..1000000, got 4294967298");

  struct Corruption {
    std::string what;             // for the failure message
    std::function<void(json&)> corrupt;  // applied to part2.json only
    std::string field;            // the field the refusal must name
  };
  const std::vector<Corruption> corruptions = {
      {"frames 0", [](json& j) { j["frames"] = 0; }, "frames"},
      {"frames -5", [](json& j) { j["frames"] = -5; }, "frames"},
      {"frames 5.0", [](json& j) { j["frames"] = 5.0; }, "frames"},
      {"nan_pixels \"x\"", [](json& j) { j["results"][0]["nan_pixels"] = "x"; }, "results[0].nan_pixels"},
      {"nan_pixels -1", [](json& j) { j["results"][0]["nan_pixels"] = -1; }, "results[0].nan_pixels"},
      {"nan_pixels not the per-frame sum", [](json& j) { j["results"][0]["nan_pixels"] = 7; }, "results[0].nan_pixels"},
      {"results []", [](json& j) { j["results"] = json::array(); }, "results"},
      {"device null", [](json& j) { j["device"] = nullptr; }, "device"},
      {"shard.end_frame beyond an int", [](json& j) { j["shard"]["end_frame"] = 4294967298ull; }, "shard.end_frame"},
      {"shard.index beyond an int", [](json& j) { j["shard"]["index"] = 4294967298ull; }, "shard.index"},
      {"msaa beyond an int", [](json& j) { j["results"][1]["msaa"] = 4294967297ull; }, "results[1].msaa"},
      {"no frame times", [](json& j) { j["results"][0]["ms_per_frame"] = json::array(); }, "results[0].ms_per_frame"},
      {"a negative time", [](json& j) { j["results"][2]["ms_per_frame"][0] = -1.0; }, "results[2].ms_per_frame"},
      {"an error frame outside the part", [](json& j) { j["error_frames"] = {99}; }, "error_frames"},
      {"pixels beyond 2^53", [](json& j) { j["results"][0]["error"]["pixels"] = 18446744073709551615ull; },
       "results[0].error.pixels"},
      {"a temporal frame outside the part", [](json& j) { j["results"][0]["temporal_per_frame"][0]["frame"] = 0; },
       "results[0].temporal_per_frame.frame"},
      {"differences[0].a null", [](json& j) { j["differences"][0]["a"] = nullptr; }, "differences[0].a"},
      {"wall_s a string", [](json& j) { j["wall_s"] = "1s"; }, "wall_s"},
      // Each count within 2^53, their sum past it (it would wrap past 2^64 over enough frames).
      {"per-frame counts that sum past 2^53",
       [](json& j) {
         for (json& v : j["results"][0]["nan_pixels_per_frame"]) v = uint64_t{1} << 53;
       },
       "results[0].nan_pixels_per_frame"},
  };
  for (const Corruption& c : corruptions) {
    other = parts;
    c.corrupt(other[1].json);
    std::tie(field, message) = refusal(other);
    EXPECT_EQ(field, c.field) << c.what << ": " << message;
    EXPECT_EQ(message.rfind(c.field + ": part2.json: ", 0), 0u) << c.what << ": " << message;
  }
}

TEST_F(BenchMerge, MergeCommandRefusesACorruptedPartAndWritesNothing) {
  json bad = part(2);
  bad["frames"] = 4294967298ull;
  std::ofstream(*dir_ / "bad2.json") << bad.dump();
  const CliRun r = seamcl(*dir_, "merge part1.json bad2.json part3.json -o corrupt_merged.json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err.rfind("seamcl: frames: bad2.json: must be in 1..1000000, got 4294967298", 0), 0u) << r.err;
  EXPECT_FALSE(fs::exists(*dir_ / "corrupt_merged.json"));
}

TEST_F(BenchMerge, MergeCommandRefusesFilesThatAreNotParts) {
  std::ofstream(*dir_ / "garbage.json") << "{not json";
  CliRun r = seamcl(*dir_, "merge part1.json garbage.json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("parts: garbage.json: not valid JSON"), std::string::npos) << r.err;
  r = seamcl(*dir_, "merge part1.json missing.json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("parts: missing.json: no such file"), std::string::npos) << r.err;
  fs::create_directory(*dir_ / "a_directory");
  r = seamcl(*dir_, "merge part1.json a_directory");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("parts: a_directory: not a regular file"), std::string::npos) << r.err;
  r = seamcl(*dir_, "merge part1.json ''");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("parts: a part's path is empty"), std::string::npos) << r.err;
  r = seamcl(*dir_, "merge part1.json part2.json");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("parts missing: 3/3"), std::string::npos) << r.err;
}

TEST(Shard, ParsesKOfNAndRefusesEverythingElse) {
  EXPECT_EQ(parse_shard("1/1").index, 1);
  EXPECT_EQ(parse_shard("3/7").index, 3);
  EXPECT_EQ(parse_shard("3/7").count, 7);
  EXPECT_TRUE(parse_shard("1/1").whole());
  for (const char* bad : {"", "1", "0/3", "4/3", "-1/3", "1/0", "1/-2", " 1/2", "1/2 ", "a/b", "1//2", "1/2/3",
                          "9999999/9999999", "1/100001", "1.5/2"}) {
    try {
      (void)parse_shard(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "shard") << bad;
    }
  }
}

TEST(Shard, BlocksTileTheFramesInOrderAndDifferByOneAtMost) {
  for (int frames : {1, 2, 5, 7, 60, 1000}) {
    for (int n = 1; n <= std::min(frames, 13); ++n) {
      int next = 0, shortest = frames, longest = 0;
      for (int k = 1; k <= n; ++k) {
        const FrameRange r = shard_frames(Shard{k, n}, frames);
        EXPECT_EQ(r.first, next) << k << "/" << n << " of " << frames;
        EXPECT_GT(r.size(), 0);
        shortest = std::min(shortest, r.size());
        longest = std::max(longest, r.size());
        next = r.end;
      }
      EXPECT_EQ(next, frames);
      EXPECT_LE(longest - shortest, 1);
    }
  }
  try {
    (void)shard_frames(Shard{1, 6}, 5);
    ADD_FAILURE() << "6 parts of 5 frames accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "shard");
  }
}

TEST(Shard, BenchRefusesABadShardBeforeAnyWork) {
  const fs::path dir = make_temp_dir();
  for (const char* bad : {"0/2", "3/2", "x", "6/6"}) {
    const CliRun r = seamcl(dir, std::string("bench --scene quad2 --methods discard --msaa 1 --size 16x16 --frames 5 "
                                          "--no-errors --json --shard ") + bad);
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_EQ(r.err.rfind("seamcl: shard: ", 0), 0u) << bad << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << bad;
  }
  fs::remove_all(dir);
}

}  // namespace
