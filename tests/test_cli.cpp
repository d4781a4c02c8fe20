// The real seamcl binary, run in a fresh directory: bad input exits 2 with one line on stderr
// naming the field and writes nothing; the success paths print what the contract in
// /work/shared/design.md promises and write images of the asked size.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/io/image_io.h>
#include <seamcl/version.h>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Process {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string read_file(const fs::path& path) {
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

}  // namespace

// A fresh working directory per test; stdout and stderr captured outside it, so that "wrote no
// file" means the directory's listing did not change. Outside the anonymous namespace, as the
// tests derive from it.
class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "seamcl_cli_XXXXXX").string();
    ASSERT_NE(mkdtemp(pattern.data()), nullptr);
    root_ = pattern;
    dir_ = root_ / "work";
    fs::create_directory(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }

  Process run(const std::string& args) {
    const fs::path out = root_ / "stdout.txt", err = root_ / "stderr.txt";
    const std::string command = "cd " + quoted(dir_.string()) + " && " + launcher_ + quoted(SEAMCL_BINARY) + " " + args + " >" +
                                quoted(out.string()) + " 2>" + quoted(err.string()) + " </dev/null";
    const int status = std::system(command.c_str());
    Process r;
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    r.out = read_file(out);
    r.err = read_file(err);
    return r;
  }

  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.insert(entry.path().filename().string());
    return names;
  }

  void write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
  }

  // Exit code 2, exactly one line on stderr that mentions `field` (or one of `alternatives`),
  // and no file written.
  void expect_input_error(const std::string& args, const std::string& field,
                          const std::vector<std::string>& alternatives = {}) {
    SCOPED_TRACE("seamcl " + args);
    const std::set<std::string> before = listing();
    const Process r = run(args);
    EXPECT_EQ(r.exit_code, 2) << "stderr: " << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.back(), '\n') << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    bool named = r.err.find(field) != std::string::npos;
    for (const std::string& other : alternatives) named = named || r.err.find(other) != std::string::npos;
    EXPECT_TRUE(named) << "stderr does not name '" << field << "': " << r.err;
    EXPECT_EQ(listing(), before);
  }

  fs::path root_, dir_;
  std::string launcher_;  // put before the binary: "timeout 30 " for a command that would otherwise run on
};

namespace {

const std::string kQuad2Json = R"({
  "name": "q",
  "positions": [[-1, -0.5, 0], [0, -0.5, 0], [1, -0.5, 0], [-1, 0.5, 0], [0, 0.5, 0], [1, 0.5, 0]],
  "faces": [
    {"vertices": [0, 1, 4, 3], "texture": {"width": 4, "height": 4, "content": "constant", "color": [0.8, 0.3, 0.2]}},
    {"vertices": [1, 2, 5, 4], "texture": {"width": 2, "height": 1, "content": "constant", "color": [0.2, 0.4, 0.8]}}
  ],
  "camera": {"eye": EYE, "target": [0, 0, 0]}
})";

std::string quad2_json(const std::string& eye) {
  std::string text = kQuad2Json;
  text.replace(text.find("EYE"), 3, eye);
  return text;
}

}  // namespace

TEST_F(Cli, UnknownMethodIsInputError) { expect_input_error("render --scene quad2 --size 16x16 --method bogus -o x.png", "method"); }

TEST_F(Cli, UnknownSceneIsInputError) { expect_input_error("render --scene nosuchscene --size 16x16 -o x.png", "scene"); }

TEST_F(Cli, BadMsaaIsInputError) { expect_input_error("render --scene quad2 --size 16x16 --msaa 3 -o x.png", "msaa"); }

TEST_F(Cli, BadSizeIsInputError) {
  expect_input_error("render --scene quad2 --size 0x0 -o x.png", "size");
  expect_input_error("render --scene quad2 --size 64 -o x.png", "size");
  expect_input_error("render --scene quad2 --size 20000x10 -o x.png", "size");
}

TEST_F(Cli, BadAnisoIsInputError) {
  expect_input_error("render --scene quad2 --size 16x16 --aniso 0 -o x.png", "aniso");
  expect_input_error("render --scene quad2 --size 16x16 --aniso 17 -o x.png", "aniso");
}

TEST_F(Cli, BadOutputExtensionIsInputError) { expect_input_error("render --scene quad2 --size 16x16 -o x.bmp", "output"); }

// Where output goes is checked before any work, naming its option.
TEST_F(Cli, OutputInAMissingDirectoryIsInputError) {
  expect_input_error("render --scene quad2 --size 16x16 -o no-such-dir/x.png", "output");
}

TEST_F(Cli, ImagesDirectoryThatCannotBeMadeIsInputError) {
  write("plain-file", "x");
  const std::set<std::string> before = listing();
  const Process r = run("compare --scene quad2 --methods discard --msaa 1 --size 16x16 --repeat 1 --no-progress "
                        "--images plain-file/images");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("images"), std::string::npos) << r.err;
  EXPECT_EQ(listing(), before);
}

TEST_F(Cli, DisplacementOptionsWithoutDisplacementAreInputErrors) {
  expect_input_error("render --scene quad2 --size 16x16 --crack-orbit 4 --json -o x.png", "crack_orbit");
  expect_input_error("render --scene displaced --displacement-method zipper --size 16x16 --crack-orbit 4 -o x.png",
                     "crack_orbit");
  expect_input_error("render --scene quad2 --size 16x16 --displacement-map d.ptx -o x.png", "displacement_map");
  expect_input_error("render --scene quad2 --size 16x16 --tessellation-pixels 4 -o x.png", "tessellation_pixels");
}

TEST_F(Cli, DeviceThatMatchesNoneIsInputError) {
  expect_input_error("--device no-such-device-anywhere render --scene quad2 --size 16x16 -o x.png", "device");
}

TEST_F(Cli, FrameOutsideOrbitIsInputError) {
  expect_input_error("render --scene quad2 --size 16x16 --frame 5 --frames 5 -o x.png", "frame");
}

TEST_F(Cli, TruncatedSceneFileIsInputError) {
  const std::string text = quad2_json("[0, 0, 2.7]");
  write("truncated.json", text.substr(0, text.size() / 2));
  expect_input_error("render --scene truncated.json --size 16x16 -o x.png", "scene");
}

TEST_F(Cli, SceneFileWithoutFacesIsInputError) {
  write("nofaces.json", R"({"positions": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], "camera": {"eye": [0, 0, 3], "target": [0, 0, 0]}})");
  expect_input_error("render --scene nofaces.json --size 16x16 -o x.png", "faces");
}

TEST_F(Cli, NonFiniteCameraIsInputError) {
  // JSON has no NaN: a string and 1e999 stand in for it. nlohmann's parser refuses 1e999 itself
  // ("number overflow parsing '1e999'"), before any field is read, so that message may name the
  // number instead of camera.eye.
  write("string_eye.json", quad2_json(R"(["nan", 0, 2.7])"));
  expect_input_error("render --scene string_eye.json --size 16x16 -o x.png", "camera.eye");
  write("huge_eye.json", quad2_json("[0, 1e999, 2.7]"));
  expect_input_error("render --scene huge_eye.json --size 16x16 -o x.png", "camera.eye", {"1e999"});
  write("zero_view.json", quad2_json("[0, 0, 0]"));  // eye on the target
  expect_input_error("render --scene zero_view.json --size 16x16 -o x.png", "camera.eye");
}

TEST_F(Cli, RenderPngWithJson) {
  const Process r = run("render --scene quad2 --method clamp --size 64x48 -o x.png --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  json out;
  ASSERT_NO_THROW(out = json::parse(r.out)) << r.out;
  ASSERT_TRUE(out.is_object());
  EXPECT_TRUE(out.contains("device") && out["device"].is_string() && !out["device"].get<std::string>().empty()) << out;
  ASSERT_TRUE(out.contains("options")) << out;
  EXPECT_EQ(out["options"]["msaa"], 1);
  EXPECT_EQ(out["options"]["method"], "clamp");
  EXPECT_EQ(out["options"]["size"], "64x48");
  EXPECT_EQ(out["options"]["scene"], "quad2");
  ASSERT_TRUE(out.contains("ms")) << out;
  for (const char* stage : {"total", "setup", "binning", "raster", "shade"}) {
    ASSERT_TRUE(out["ms"].contains(stage)) << stage;
    EXPECT_GT(out["ms"][stage].get<double>(), 0.0) << stage;
  }
  EXPECT_EQ(out["triangles"], 4);
  EXPECT_GT(out["fragments"].get<long long>(), 0);

  int width = 0, height = 0;
  const std::vector<glm::vec4> pixels = seamcl::read_image((dir_ / "x.png").string(), width, height);
  EXPECT_EQ(width, 64);
  EXPECT_EQ(height, 48);
  EXPECT_EQ(pixels.size(), 64u * 48u);
  EXPECT_EQ(listing(), (std::set<std::string>{"x.png"}));  // no temporary file left beside it
}

TEST_F(Cli, RenderExr) {
  const Process r = run("render --scene quad2 --size 40x24 --msaa 4 --shading centroid -o out.exr");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  int width = 0, height = 0;
  const std::vector<glm::vec4> pixels = seamcl::read_image((dir_ / "out.exr").string(), width, height);
  EXPECT_EQ(width, 40);
  EXPECT_EQ(height, 24);
  ASSERT_EQ(pixels.size(), 40u * 24u);
  size_t bad = 0;
  for (const glm::vec4& p : pixels) bad += !(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && p.x >= 0);
  EXPECT_EQ(bad, 0u);
}

TEST_F(Cli, RenderSceneFile) {
  write("q.json", quad2_json("[0, 0, 2.7]"));
  const Process r = run("render --scene q.json --size 32x32 -o q.png --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(json::parse(r.out)["triangles"], 4);
  EXPECT_TRUE(fs::exists(dir_ / "q.png"));
}

TEST_F(Cli, ScenesListsBuiltIns) {
  const Process r = run("scenes");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const std::string name : {"paper", "quad2", "plane", "cube"}) {
    EXPECT_TRUE(r.out.rfind(name + " ", 0) == 0 || r.out.find("\n" + name + " ") != std::string::npos)
        << name << " not listed:\n" << r.out;
  }
  const Process j = run("scenes --json");
  ASSERT_EQ(j.exit_code, 0) << j.err;
  std::set<std::string> names;
  for (const json& entry : json::parse(j.out)) names.insert(entry["name"].get<std::string>());
  for (const std::string name : {"paper", "quad2", "plane", "cube"}) EXPECT_TRUE(names.count(name)) << name;
}

TEST_F(Cli, DevicesMarksOne) {
  const Process r = run("devices");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.rfind("* ", 0) == 0 || r.out.find("\n* ") != std::string::npos) << r.out;
}

TEST_F(Cli, VersionPrintsVersionAndDevice) {
  const Process r = run("--version");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find(std::string("seamcl ") + SEAMCL_VERSION), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("device:"), std::string::npos) << r.out;
}

TEST_F(Cli, HelpExitsZero) {
  const Process r = run("--help");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("render"), std::string::npos) << r.out;
  const Process sub = run("render --help");
  EXPECT_EQ(sub.exit_code, 0) << sub.err;
  EXPECT_NE(sub.out.find("--msaa"), std::string::npos) << sub.out;
}

TEST_F(Cli, UnknownFlagIsUsageError) {
  const Process r = run("render --no-such-flag");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_FALSE(r.err.empty());
  EXPECT_TRUE(listing().empty());
}

// An empty output path is a mistake (a shell variable that expanded to nothing, say), not the
// option left out: taken for none, it quietly wrote nothing, or wrote merge's JSON to stdout.
TEST_F(Cli, EmptyOutputPathsAreInputErrors) {
  expect_input_error("render --scene quad2 --size 16x16 -o ''", "output: must not be empty");
  write("part.json", "{}");
  expect_input_error("merge part.json -o ''", "output: must not be empty");
  expect_input_error("compare --scene quad2 --methods discard --msaa 1 --size 16x16 --repeat 1 --no-progress "
                     "--no-cache --images ''",
                     "images: must not be empty");
  expect_input_error("cube-metrics --cube-sizes 16 --size 16x16 --repeat 1 --images ''", "images: must not be empty");
  expect_input_error("displacement-metrics --tessellation 1 --size 16x16 --frames 0 --repeat 1 --no-progress "
                     "--images ''",
                     "images: must not be empty");
}

// An option that acts only with another (or only without one) is refused where it would be parsed
// and then ignored, naming itself: whoever gave it meant it to change something.
TEST_F(Cli, OptionsThatWouldBeIgnoredAreInputErrors) {
  expect_input_error("bench --scene quad2 --size 16x16 --sweep '' --check", "sweep: must not be empty");
  expect_input_error("bench --scene quad2 --size 16x16 --frames 2 --sweep-repeats 3 --check",
                     "sweep_repeats: is ignored without sweep");
  // The orbit's options with --sweep, which renders no orbit.
  expect_input_error("bench --scene quad2 --sweep msaa --msaa 4 --check", "msaa: is ignored with sweep");
  expect_input_error("bench --scene quad2 --sweep msaa --frames 2 --check", "frames: is ignored with sweep");
  expect_input_error("bench --scene quad2 --sweep msaa --shard 1/2 --check", "shard: is ignored with sweep");
  expect_input_error("bench --scene quad2 --sweep msaa --no-errors --check", "no_errors: is ignored with sweep");
  // The pixels sweep's points have sizes of their own; faces, msaa and texels render at --size.
  expect_input_error("bench --scene quad2 --sweep pixels --size 64x64 --check",
                     "size: is ignored with sweep pixels");
  expect_input_error("bench --scene quad2 --sweep msaa --sweep-repeats 0 --check", "sweep_repeats: must be in 1..100");
  // The reference's options without references.
  expect_input_error("bench --scene quad2 --size 16x16 --frames 2 --no-errors --reference-frames 2 --check",
                     "reference_frames: is ignored with no_errors");
  expect_input_error("bench --scene quad2 --size 16x16 --frames 2 --no-errors --reference-msaa 4 --check",
                     "reference_msaa: is ignored with no_errors");
  // --frames without --frame: the scene's own camera renders.
  expect_input_error("render --scene quad2 --size 16x16 --frames 30 -o x.png", "frames: is ignored without frame");
  expect_input_error("compare --scene quad2 --methods discard --msaa 1 --size 16x16 --repeat 1 --no-progress --no-cache "
                     "--frames 30",
                     "frames: is ignored without frame");
  // Each with what it needs, they are taken.
  for (const std::string args : {"bench --scene quad2 --sweep msaa --sweep-repeats 1 --check",
                                 "bench --scene quad2 --sweep pixels,msaa --size 64x64 --check",
                                 "bench --scene quad2 --size 16x16 --frames 2 --reference-frames 2 --check"}) {
    const Process r = run(args);
    EXPECT_EQ(r.exit_code, 0) << args << ": " << r.err;
  }
}

// compare and bench refuse a run this machine cannot hold before they allocate, as render does
// (tests/test_budget.cpp holds the refusal to the machine's memory). A bench pools every error
// frame's distances: a million frames at 1024x1024 need terabytes, so it names frames.
TEST_F(Cli, BenchTheMachineCannotHoldIsRefusedNamingFrames) {
  expect_input_error("bench --scene quad2 --methods discard,traverse --msaa 1,4 --size 1024x1024 --frames 1000000 "
                     "--no-cache",
                     "frames: this bench needs");
  // Without errors the discard / traverse differences are still pooled on every frame.
  expect_input_error("bench --scene quad2 --methods discard,traverse --msaa 1 --size 1024x1024 --frames 1000000 "
                     "--no-errors",
                     "frames: this bench needs");
  // A small bench is let through.
  const Process r = run("bench --scene quad2 --methods discard --msaa 1 --size 16x16 --frames 3 --no-errors --no-cache");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// --check refuses it too, as a pre-check of a batch must (scripts/farm checks part 1 of N), and
// judges the part it is given: one part of the same orbit fits.
TEST_F(Cli, BenchCheckRefusesWhatTheMachineCannotHold) {
  const std::string orbit = "bench --scene quad2 --methods discard,traverse --msaa 1,4 --size 1024x1024 --frames 1000000 ";
  expect_input_error(orbit + "--no-errors --check", "frames: this bench needs");
  expect_input_error(orbit + "--no-cache --check", "frames: this bench needs");
  const Process part = run(orbit + "--no-errors --shard 1/100000 --check");
  EXPECT_EQ(part.exit_code, 0) << part.err;
  EXPECT_NE(part.out.find("bench options valid: quad2, part 1/100000: frames 0..9 of 1000000"), std::string::npos)
      << part.out;
}

// An empty option value is a mistake (a shell variable that expanded to nothing, say), not the
// option left out: taken for none, each fell back to its default without a word.
TEST_F(Cli, EmptyOptionValuesAreInputErrors) {
  const std::string compare = "compare --scene quad2 --methods discard --msaa 1 --size 16x16 --repeat 1 --no-progress --no-cache ";
  expect_input_error("render --scene quad2 --size 16x16 --displacement-map ''", "displacement_map: must not be empty");
  expect_input_error("render --scene quad2 --size 16x16 --displacement-method naive --displacement-map ''",
                     "displacement_map: must not be empty");
  expect_input_error("displacement-metrics --tessellation 1 --size 16x16 --frames 0 --repeat 1 --no-progress "
                     "--displacement-map ''",
                     "displacement_map: must not be empty");
  expect_input_error(compare + "--constant-color ''", "constant_color:");
  expect_input_error(compare + "--reference-method ''", "reference_method: must not be empty");
  expect_input_error(compare + "--cache ''", "cache: must not be empty");
  // Named at once, not found out from every reference left uncached; --no-cache never reads it.
  expect_input_error("compare --scene quad2 --methods discard --msaa 1 --size 16x16 --repeat 1 --no-progress --cache /dev/null",
                     "cache: '/dev/null' is not a directory");
  expect_input_error("bench --scene quad2 --size 16x16 --frames 2 --reference-method '' --check",
                     "reference_method: must not be empty");
  expect_input_error("bench --scene quad2 --size 16x16 --frames 2 --cache '' --check", "cache: must not be empty");
  expect_input_error("bench --scene quad2 --sweep msaa --cache '' --check", "cache: must not be empty");
  expect_input_error("bench --scene quad2 --size 16x16 --frames 2 --images '' --check", "images: must not be empty");
  // bench --images writes the error frames: a bench without any is refused before any work.
  expect_input_error("bench --scene quad2 --size 16x16 --frames 2 --no-errors --images /tmp/unused --check",
                     "images: writes the orbit's error frames: no_errors leaves none");
  expect_input_error("bench --scene quad2 --sweep msaa --images /tmp/unused --check",
                     "images: writes the orbit's error frames: a sweep has none");
  expect_input_error("--device '' render --scene quad2 --size 16x16", "device: must not be empty");
  expect_input_error("--device '' devices", "device: must not be empty");
  // serve would listen until stopped: the timeout ends it where the refusal is missing.
  launcher_ = "timeout 30 ";
  expect_input_error("serve --port 0 --quick-start --host ''", "host: must not be empty");
  expect_input_error("serve --port 0 --quick-start --cache-dir ''", "cache-dir: must not be empty");
  expect_input_error("serve --port 0 --quick-start --cache-dir /dev/null", "cache_dir: '/dev/null' is not a directory");
  expect_input_error("serve --port 0 --quick-start --assets ''", "assets: must not be empty");
  expect_input_error("serve --port 0 --quick-start --cache-max-mib 9223372036854775807",
                     "cache-max-mib: must be in 0..2^40");
  expect_input_error("serve --port 0 --quick-start --assets-cache-mib 17592186044416",
                     "assets-cache-mib: must be in 0..16777216");
}
