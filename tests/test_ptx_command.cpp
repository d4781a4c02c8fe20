// `seamcl ptx` run as a user runs it: `info` and `dump` give the Ptex library's own face facts,
// averages and texels (tests/assets/ptex/golden/), `lookup` gives its filtered values from the
// device, and bad input exits 2 with one line naming the field.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "ptex_test_writer.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using seamcl_tests::kPtexSamples;
using seamcl_tests::ptex_assets_dir;
using seamcl_tests::ptex_golden;


struct Process {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string sample_path(const std::string& name) { return quoted(ptex_assets_dir() + "/" + name + ".ptx"); }

class PtxCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "seamcl_ptx_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    dir_ = pattern;
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  Process run(const std::string& args) {
    const fs::path out = dir_ / "stdout.txt", err = dir_ / "stderr.txt";
    const std::string command = quoted(SEAMCL_BINARY) + " " + args + " >" + quoted(out.string()) + " 2>" +
                                quoted(err.string()) + " </dev/null";
    const int status = std::system(command.c_str());
    Process r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
  }
  std::string write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return quoted((dir_ / name).string());
  }
  // Exit 2, one line on stderr that names `field` ("seamcl: field: ...").
  void expect_refused(const std::string& args, const std::string& field, const std::string& words = "") {
    const Process p = run(args);
    EXPECT_EQ(p.exit_code, 2) << args << "\n" << p.err;
    EXPECT_EQ(p.err.rfind("seamcl: " + field + ": ", 0), 0u) << args << "\n" << p.err;
    EXPECT_EQ(std::count(p.err.begin(), p.err.end(), '\n'), 1) << p.err;
    if (!words.empty()) {
      EXPECT_NE(p.err.find(words), std::string::npos) << p.err;
    }
    EXPECT_TRUE(p.out.empty()) << p.out;
  }
  fs::path dir_;
};

TEST_F(PtxCommand, InfoGivesThePtexLibrarysFaceFactsAndAverages) {
  for (const char* name : kPtexSamples) {
    const json g = ptex_golden(name);
    const Process p = run("ptx info " + sample_path(name));
    ASSERT_EQ(p.exit_code, 0) << p.err;
    const json info = json::parse(p.out);
    const json& h = info["header"];
    EXPECT_EQ(h["mesh_type"], g["mesh_type"]) << name;
    EXPECT_EQ(h["data_type"], g["data_type"]) << name;
    EXPECT_EQ(h["channels"], g["channels"]) << name;
    EXPECT_EQ(h["alpha_channel"], g["alpha_channel"]) << name;
    EXPECT_EQ(h["faces"], g["faces"]) << name;
    EXPECT_EQ(h["has_mipmaps"], g["has_mipmaps"]) << name;
    EXPECT_EQ(h["u_border_mode"], std::string(name) == "black" ? "black" : "clamp") << name;
    EXPECT_TRUE(info["metadata"].empty()) << name;  // ptxinfo: no metadata in any sample
    ASSERT_EQ(info["face_info"].size(), g["face_info"].size()) << name;
    for (size_t f = 0; f < g["face_info"].size(); ++f) {
      const json& mine = info["face_info"][f];
      const json& theirs = g["face_info"][f];
      for (const char* key : {"ulog2", "vlog2", "constant", "adjfaces", "adjedges"})
        EXPECT_EQ(mine[key], theirs[key]) << name << " face " << f << " " << key;
    }
    for (size_t f = 0; f < g["face_average"].size(); ++f)
      for (size_t c = 0; c < g["face_average"][f].size(); ++c)
        EXPECT_NEAR(info["face_average"][f][c].get<double>(), g["face_average"][f][c].get<double>(), 1e-6)
            << name << " face " << f;
  }
}

TEST_F(PtxCommand, DumpGivesThePtexLibrarysTexels) {
  for (const char* name : kPtexSamples) {
    const json g = ptex_golden(name);
    // One face of the golden texels per sample (the one with most of them), every golden texel on it.
    std::map<int, std::vector<json>> by_face;
    for (const json& t : g["texels"]) by_face[t["face"].get<int>()].push_back(t);
    int texels_checked = 0;
    auto most = by_face.begin();
    for (auto it = by_face.begin(); it != by_face.end(); ++it)
      if (it->second.size() > most->second.size()) most = it;
    {
      const int face = most->first;
      const std::vector<json>& texels = most->second;
      const Process p = run("ptx dump " + sample_path(name) + " --face " + std::to_string(face));
      ASSERT_EQ(p.exit_code, 0) << p.err;
      const json dump = json::parse(p.out);
      EXPECT_EQ(dump["level"], 0);
      EXPECT_EQ(dump["ulog2"], g["face_info"][face]["ulog2"]);
      for (const json& t : texels) {
        const json& value = dump["texels"][t["v"].get<int>()][t["u"].get<int>()];
        for (size_t c = 0; c < t["value"].size(); ++c)
          EXPECT_NEAR(value[c].get<double>(), t["value"][c].get<double>(), 1e-6) << name << " face " << face;
        ++texels_checked;
      }
    }
    EXPECT_GE(texels_checked, 1) << name;
  }
  // A level below the stored ones: 2x2 of a 16x16 uint16 face, each side halved 3 times.
  const Process p = run("ptx dump " + sample_path("rand_lo") + " --face 1 --level 3");
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const json dump = json::parse(p.out);
  EXPECT_EQ(dump["texels"].size(), static_cast<size_t>(1 << (dump["vlog2"].get<int>())));
  EXPECT_EQ(dump["level"], 3);
}

TEST_F(PtxCommand, LookupGivesThePtexLibrarysFilteredValuesFromTheDevice) {
  for (const char* name : kPtexSamples) {
    const json g = ptex_golden(name);
    const std::string queries = write(std::string(name) + ".json", g["filtered"].dump());
    const Process p = run("ptx lookup " + sample_path(name) + " --queries " + queries);
    ASSERT_EQ(p.exit_code, 0) << p.err;
    const json values = json::parse(p.out)["values"];
    ASSERT_EQ(values.size(), g["filtered"].size());
    double largest = 0.0;
    for (size_t i = 0; i < values.size(); ++i) {
      const json& expected = g["filtered"][i]["value"];
      ASSERT_EQ(values[i].size(), expected.size());
      for (size_t c = 0; c < expected.size(); ++c) {
        EXPECT_NEAR(values[i][c].get<double>(), expected[c].get<double>(), 1e-4) << name << " lookup " << i;
        largest = std::max(largest, std::fabs(values[i][c].get<double>() - expected[c].get<double>()));
      }
    }
    std::cout << "[ptx lookup, device] " << name << ": largest difference " << largest << "\n";
  }
  // One lookup from the flags: the first golden entry of cellnoise.
  const json first = ptex_golden("cellnoise")["filtered"][0];
  std::ostringstream args;
  args.precision(9);
  args << "ptx lookup " << sample_path("cellnoise") << " --face " << first["face"].get<int>() << " --u "
       << first["u"].get<double>() << " --v " << first["v"].get<double>() << " --uw " << first["uw"].get<double>()
       << " --vw " << first["vw"].get<double>() << " --filter ptex-" << first["filter"].get<std::string>();
  const Process p = run(args.str());
  ASSERT_EQ(p.exit_code, 0) << p.err;
  const json value = json::parse(p.out)["value"];
  ASSERT_EQ(value.size(), 3u);
  for (size_t c = 0; c < 3; ++c) EXPECT_NEAR(value[c].get<double>(), first["value"][c].get<double>(), 1e-4);
}

TEST_F(PtxCommand, BadInputExitsTwoNamingTheField) {
  const std::string file = sample_path("rand_lo");  // 9 faces, the smallest sample with neighbours
  expect_refused("ptx lookup " + file + " --face 9", "face", "the file has 9 faces");
  expect_refused("ptx lookup " + file + " --face 2 --uw -0.25", "uw");
  expect_refused("ptx lookup " + file + " --face 2 --filter sinc", "filter", "sinc");
  expect_refused("ptx lookup " + file + " --face 2 --u nan", "u");
  expect_refused("ptx lookup " + file + " --queries " + write("bad.json", "[{\"face\": 1,"), "queries", "not valid JSON");
  expect_refused("ptx lookup " + file + " --queries " + write("notarray.json", "{\"face\": 1}"), "queries", "array");
  expect_refused("ptx lookup " + file + " --queries " + write("neg.json", "[{\"face\": 1}, {\"face\": 1, \"vw\": -1}]"),
                 "queries[1].vw");
  expect_refused("ptx lookup " + file + " --queries " + write("far.json", "[{\"face\": 400}]"), "queries[0].face",
                 "out of range");
  expect_refused("ptx lookup " + file + " --queries " + write("filt.json", "[{\"filter\": \"cubic\"}]"),
                 "queries[0].filter");
  expect_refused("ptx lookup " + file + " --queries " + write("flat.json", "[1, 1, 1]"), "queries[0]",
                 "must be a JSON object");
  // One lookup past the limit, each an object of defaults: refused by count, before any lookup.
  std::string many = "[{}";
  for (size_t i = 0; i < (size_t(1) << 22); ++i) many += ",{}";
  expect_refused("ptx lookup " + file + " --queries " + write("many.json", many + "]"), "queries",
                 "more than the limit of 4194304 lookups");
  expect_refused("ptx lookup " + file + " --face 1 --queries " + write("ok.json", "[]"), "queries", "either");
  expect_refused("ptx lookup " + file + " --queries ''", "queries", "must not be empty");
  expect_refused("ptx dump " + file + " --face -1", "face");
  expect_refused("ptx dump " + file, "face", "required");
  expect_refused("ptx dump " + file + " --face 0 --level 4", "level", "levels 0 to 3");
  expect_refused("ptx info " + quoted((dir_ / "missing.ptx").string()), "texture");
  expect_refused("ptx info " + write("notptex.ptx", std::string(100, 'x')), "texture", "magic");
}

}  // namespace
