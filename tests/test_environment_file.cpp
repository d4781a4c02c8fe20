// Image environments (issue 12): an equirect map, a horizontal or vertical cross and six face
// images, written here through seamcl's image writer, loaded from a scene file and baked into cube maps
// exactly as the analytic environment is.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <sys/stat.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "assets/environment_file.h"
#include <seamcl/assets/scene_source.h>
#include <seamcl/core/input_error.h>
#include <seamcl/io/image_io.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/cube_map.h>
#include <seamcl/scene/environment.h>
#include <seamcl/scene/scene_json.h>

namespace seamcl {
namespace {

namespace fs = std::filesystem;
constexpr float kPi = 3.14159265358979f;

class EnvironmentDir {
 public:
  EnvironmentDir() {
    std::string pattern = (fs::temp_directory_path() / "seamcl_environment_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp");
    path_ = pattern;
  }
  ~EnvironmentDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  // A generator scene file whose environment is `environment` (a JSON object's text).
  std::string scene(const std::string& environment) const {
    const std::string path = file("scene.json");
    std::ofstream(path) << R"({"generator": "envmap", "options": {"environment": )" << environment << "}}";
    return path;
  }

 private:
  fs::path path_;
};

// A function with a different value in every direction, so that a turned or mirrored face shows.
glm::vec4 known(glm::vec3 d) { return {0.5f + 0.5f * d.x, 0.5f + 0.5f * d.y, 0.5f + 0.5f * d.z, 1.0f}; }

// The equirect convention of environment.h: u = 1/2 + atan2(x, -z) / 2 pi, v = acos(y) / pi.
std::vector<glm::vec4> equirect_pixels(int width, int height) {
  std::vector<glm::vec4> pixels;
  for (int j = 0; j < height; ++j)
    for (int i = 0; i < width; ++i) {
      const float longitude = ((static_cast<float>(i) + 0.5f) / static_cast<float>(width) - 0.5f) * 2 * kPi;
      const float polar = (static_cast<float>(j) + 0.5f) / static_cast<float>(height) * kPi;
      pixels.push_back(known({std::sin(polar) * std::sin(longitude), std::cos(polar),
                              -std::sin(polar) * std::cos(longitude)}));
    }
  return pixels;
}

// Texel (i, j) of face `face` (row j at t = (j + .5) / n, as in cube_map.h).
glm::vec4 face_texel(int face, int i, int j, int n) {
  const auto centre = [n](int x) { return (static_cast<float>(x) + 0.5f) * 2.0f / static_cast<float>(n) - 1.0f; };
  return known(glm::normalize(cube_direction(face, centre(i), centre(j))));
}

// A cross of n x n faces: cells (column, row) per face; the vertical cross's -Z turned by 180.
std::vector<glm::vec4> cross_pixels(int n, bool horizontal) {
  const int columns = horizontal ? 4 : 3, rows = horizontal ? 3 : 4;
  const std::array<std::array<int, 2>, 6> cells =
      horizontal ? std::array<std::array<int, 2>, 6>{{{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {3, 1}}}
                 : std::array<std::array<int, 2>, 6>{{{2, 1}, {0, 1}, {1, 0}, {1, 2}, {1, 1}, {1, 3}}};
  std::vector<glm::vec4> pixels(static_cast<size_t>(columns * n) * rows * n, glm::vec4(0, 0, 0, 1));
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const bool turned = !horizontal && face == 5;
        const glm::vec4 value = face_texel(face, turned ? n - 1 - x : x, turned ? n - 1 - y : y, n);
        pixels[static_cast<size_t>(cells[face][1] * n + y) * columns * n + cells[face][0] * n + x] = value;
      }
  return pixels;
}

std::vector<glm::vec4> face_pixels(int face, int n) {
  std::vector<glm::vec4> pixels;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) pixels.push_back(face_texel(face, i, j, n));
  return pixels;
}

Environment loaded_environment(const std::string& scene_path) {
  const Scene scene = load_scene_source(scene_path);
  EXPECT_TRUE(scene.environment.has_value());
  EXPECT_TRUE(scene.environment->image != nullptr);
  return *scene.environment;
}

// The largest difference over every texel of every level of every face.
float max_difference(const CubeMap& a, const CubeMap& b) {
  float worst = 0;
  for (int face = 0; face < kCubeFaces; ++face)
    for (size_t level = 0; level < a.faces[face].levels.size(); ++level) {
      const TextureLevel& la = a.faces[face].levels[level];
      const TextureLevel& lb = b.faces[face].levels[level];
      EXPECT_EQ(la.texels.size(), lb.texels.size());
      for (size_t k = 0; k < la.texels.size() && k < lb.texels.size(); ++k)
        for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(la.texels[k][c] - lb.texels[k][c]));
    }
  return worst;
}

void expect_input_error(const std::function<void()>& action, const std::string& field, const std::string& words) {
  try {
    action();
    ADD_FAILURE() << "no error; expected one naming " << field;
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), field) << error.what();
    EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
  }
}

TEST(EnvironmentFile, LayoutNamesRoundTripThroughTheirOneParsePair) {
  for (const std::string& name : environment_layout_names()) {
    const auto layout = parse_environment_layout(name);
    ASSERT_TRUE(layout.has_value()) << name;
    EXPECT_EQ(to_string(*layout), name);
  }
  EXPECT_EQ(environment_layout_names().size(), 3u);
  EXPECT_FALSE(parse_environment_layout("latlong").has_value());
}

TEST(EnvironmentFile, AnEquirectFileBakesACubeThatReproducesTheFunctionAtFaceCentres) {
  EnvironmentDir dir;
  write_image(dir.file("sky.exr"), 128, 64, equirect_pixels(128, 64));
  const Environment environment =
      loaded_environment(dir.scene(R"({"file": "sky.exr", "layout": "equirect", "cube_size": 8})"));
  const DirectionFunction radiance = environment_function(environment);
  for (CubeBake bake : {CubeBake::Centres, CubeBake::Stretch, CubeBake::Warp}) {
    const CubeMap cube = bake_cube_map(radiance, 8, bake, 1);
    for (int face = 0; face < kCubeFaces; ++face) {
      // The 1 x 1 level takes the face centre's own direction under every bake.
      const glm::vec4 centre = cube.faces[face].levels.back().texels.at(0);
      const glm::vec4 expected = known(cube_direction(face, 0, 0));
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(centre[c], expected[c], 0.02f) << "face " << face << " channel " << c << " bake " << to_string(bake);
    }
  }
  // Away from the poles a direction's value is the function's within the bilinear error.
  for (glm::vec3 d : {glm::vec3(0.3f, 0.2f, -0.9f), glm::vec3(-0.7f, -0.4f, 0.5f), glm::vec3(0.6f, 0.6f, 0.5f)}) {
    d = glm::normalize(d);
    const glm::vec4 value = radiance(d), expected = known(d);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(value[c], expected[c], 0.005f) << c;
  }
}

TEST(EnvironmentFile, CrossesAndSixFacesGiveTheCubeOfTheEquirect) {
  constexpr int n = 32;
  EnvironmentDir dir;
  write_image(dir.file("sky.exr"), 256, 128, equirect_pixels(256, 128));
  write_image(dir.file("horizontal.exr"), 4 * n, 3 * n, cross_pixels(n, true));
  write_image(dir.file("vertical.exr"), 3 * n, 4 * n, cross_pixels(n, false));
  const std::array<std::string, 6> names{"px.exr", "nx.exr", "py.exr", "ny.exr", "pz.exr", "nz.exr"};
  for (int face = 0; face < 6; ++face) write_image(dir.file(names[face]), n, n, face_pixels(face, n));

  const Environment equirect = loaded_environment(dir.scene(R"({"file": "sky.exr"})"));
  const Environment horizontal = loaded_environment(dir.scene(R"({"file": "horizontal.exr", "layout": "cross"})"));
  const Environment vertical = loaded_environment(dir.scene(R"({"file": "vertical.exr", "layout": "cross"})"));
  const Environment faces = loaded_environment(
      dir.scene(R"({"faces": ["px.exr", "nx.exr", "py.exr", "ny.exr", "pz.exr", "nz.exr"]})"));
  EXPECT_FALSE(equirect.image->cube);
  EXPECT_TRUE(faces.image->cube);
  // The crosses hold the faces' texels: the same image, texel for texel.
  EXPECT_EQ(horizontal.image->texels, faces.image->texels);
  EXPECT_EQ(vertical.image->texels, faces.image->texels);

  for (CubeBake bake : {CubeBake::Centres, CubeBake::Stretch, CubeBake::Warp}) {
    const CubeMap from_faces = bake_cube_map(environment_function(faces), 16, bake, 2);
    const CubeMap from_cross = bake_cube_map(environment_function(horizontal), 16, bake, 2);
    const CubeMap from_equirect = bake_cube_map(environment_function(equirect), 16, bake, 2);
    const CubeMap exact = bake_cube_map(known, 16, bake, 2);
    EXPECT_EQ(max_difference(from_faces, from_cross), 0.0f) << to_string(bake);
    // Two different resamplings of one function: within 0.01 of each other and of the function.
    EXPECT_LT(max_difference(from_faces, from_equirect), 0.01f) << to_string(bake);
    EXPECT_LT(max_difference(from_faces, exact), 0.01f) << to_string(bake);
    EXPECT_LT(max_difference(from_equirect, exact), 0.01f) << to_string(bake);
  }
}

TEST(EnvironmentFile, WithoutFilesTheAnalyticEnvironmentIsUnchanged) {
  const Environment environment;
  const DirectionFunction radiance = environment_function(environment);
  for (glm::vec3 d : {glm::vec3(1, 0, 0), glm::normalize(glm::vec3(0.2f, 0.7f, -0.3f)), glm::vec3(0, -1, 0)}) {
    const glm::vec4 a = radiance(d), b = environment_radiance(environment.analytic, d);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(a[c], b[c]);
  }
}

TEST(EnvironmentFile, HostileInputsAreRefusedNamingTheField) {
  EnvironmentDir dir;
  write_image(dir.file("sky.exr"), 16, 8, equirect_pixels(16, 8));
  write_image(dir.file("wide.exr"), 20, 8, std::vector<glm::vec4>(160, glm::vec4(0.5f)));
  std::vector<glm::vec4> poisoned = equirect_pixels(16, 8);
  poisoned[2 * 16 + 3].g = std::numeric_limits<float>::quiet_NaN();
  write_image(dir.file("nan.exr"), 16, 8, poisoned);
  std::vector<glm::vec4> infinite = equirect_pixels(16, 8);
  infinite[5].r = std::numeric_limits<float>::infinity();
  write_image(dir.file("inf.exr"), 16, 8, infinite);

  const auto load = [&dir](const std::string& environment) {
    return [&dir, environment] { load_scene_source(dir.scene(environment)); };
  };
  expect_input_error(load(R"({"file": "missing.exr"})"), "options.environment.file", "missing.exr");
  expect_input_error(load(R"({"file": "sky.exr", "layout": "latlong"})"), "options.environment.layout", "latlong");
  expect_input_error(load(R"({"file": "sky.exr", "layout": "faces"})"), "options.environment.layout", "faces");
  expect_input_error(load(R"({"file": "wide.exr"})"), "options.environment.file", "width = 2 x height");
  expect_input_error(load(R"({"file": "sky.exr", "layout": "cross"})"), "options.environment.file", "'cross' needs");
  expect_input_error(load(R"({"file": "nan.exr"})"), "options.environment.file", "texel (3, 2) is not finite");
  expect_input_error(load(R"({"file": "inf.exr"})"), "options.environment.file", "texel (5, 0) is not finite");
  // Finite but past kMaxColorMagnitude, written as a float EXR here.
  {
    std::vector<glm::vec4> huge = equirect_pixels(16, 8);  // (float: half could not hold 3e9)
    huge[16 + 7].b = 3e9f;
    write_image(dir.file("huge.exr"), 16, 8, huge);
  }
  expect_input_error(load(R"({"file": "huge.exr"})"), "options.environment.file", "texel (7, 1) has a magnitude over 1e9");
  // A FIFO would block the read until something wrote to it.
  ASSERT_EQ(::mkfifo(dir.file("fifo.exr").c_str(), 0600), 0);
  expect_input_error(load(R"({"file": "fifo.exr"})"), "options.environment.file", "not a regular file");
  expect_input_error(load(R"({"file": ""})"), "options.environment.file", "non-empty");
  expect_input_error(load(R"({"file": 3})"), "options.environment.file", "string");
  expect_input_error(load(R"({"layout": "cross"})"), "options.environment.layout", "goes with file");
  expect_input_error(load(R"({"file": "sky.exr", "faces": []})"), "options.environment.faces", "cannot go with file");
  expect_input_error(load(R"({"faces": ["sky.exr"]})"), "options.environment.faces", "6 files");
  expect_input_error(load(R"({"faces": ["a.exr", "b.exr", 7, "d.exr", "e.exr", "f.exr"]})"),
                     "options.environment.faces[2]", "string");
  expect_input_error(load(R"({"faces": ["sky.exr", "sky.exr", "sky.exr", "sky.exr", "sky.exr", "sky.exr"]})"),
                     "options.environment.faces[0]", "square");
  expect_input_error(load(R"({"file": "sky.exr", "constant": [1, 1, 1]})"), "options.environment.constant",
                     "image environment");
  // An inline scene (the service's) has no file to resolve names against: refused when parsed.
  expect_input_error(
      [] {
        parse_scene_json(
            nlohmann::json::parse(R"({"generator": "envmap", "options": {"environment": {"file": "sky.exr"}}})"));
      },
      "options.environment.file", "inline");
  // An environment that names files nobody read is refused when used, not shown as the analytic one.
  Environment unread;
  unread.files = EnvironmentFiles{EnvironmentLayout::Faces, {"a", "b", "c", "d", "e", "f"}, "environment"};
  expect_input_error([&] { environment_function(unread); }, "environment.faces", "not read");
}

TEST(EnvironmentFile, OversizedAndMisshapenPixelsAreRefusedBeforeUse) {
  DecodedImage huge;
  huge.width = kMaxEnvironmentImageSide + 1;
  huge.height = 1;
  expect_input_error([&] { environment_image_from_pixels(EnvironmentLayout::Equirect, {huge}, {"f"}); }, "f",
                     "each side");
  DecodedImage short_pixels{4, 2, std::vector<glm::vec4>(3)};
  expect_input_error([&] { environment_image_from_pixels(EnvironmentLayout::Equirect, {short_pixels}, {"f"}); },
                     "f", "holds 3 pixels");
  expect_input_error([&] { environment_image_from_pixels(EnvironmentLayout::Faces, {short_pixels}, {"f"}); }, "f",
                     "needs 6");
}

// Runs the seamcl binary in `dir`; stdout and stderr into files there.
int run_seamcl(const EnvironmentDir& dir, const std::string& args, std::string& out, std::string& err) {
  const std::string command = "cd '" + dir.file("") + "' && '" + std::string(SEAMCL_BINARY) + "' " + args +
                              " >stdout.txt 2>stderr.txt </dev/null";
  const int status = std::system(command.c_str());
  auto slurp = [](const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  out = slurp(dir.file("stdout.txt"));
  err = slurp(dir.file("stderr.txt"));
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(EnvironmentFile, CubeMetricsRunOnAnImageEnvironmentFromASceneFile) {
  EnvironmentDir dir;
  // A constant image: every method must then show no seam and no error; the analytic default does.
  write_image(dir.file("grey.exr"), 32, 16, std::vector<glm::vec4>(512, glm::vec4(0.25f, 0.5f, 0.75f, 1.0f)));
  dir.scene(R"({"file": "grey.exr"})");
  const std::string common = " --cube-sizes 4 --size 24x24 --repeat 1 --reference-scale 2 --json";
  std::string out, err;
  ASSERT_EQ(run_seamcl(dir, "cube-metrics --scene scene.json" + common, out, err), 0) << err;
  const nlohmann::json image = nlohmann::json::parse(out);
  ASSERT_EQ(image.at("results").size(), cube_method_names().size());
  for (const auto& entry : image.at("results")) {
    for (const auto& step : entry.at("seam_step")) EXPECT_LT(step.get<double>(), 1e-5) << entry.at("cube_method");
    EXPECT_LT(entry.at("error").at("max").get<double>(), 1e-3) << entry.at("cube_method");
    EXPECT_EQ(entry.at("error").at("nan_pixels"), 0) << entry.at("cube_method");
    EXPECT_EQ(entry.at("edge_error").at("nan_pixels"), 0) << entry.at("cube_method");
  }
  ASSERT_EQ(run_seamcl(dir, "cube-metrics --scene envmap --cube-methods cube-clamp" + common, out, err), 0) << err;
  const nlohmann::json analytic = nlohmann::json::parse(out);
  EXPECT_GT(analytic.at("results").at(0).at("seam_step").at(0).get<double>(), 1e-3);

  dir.scene(R"({"file": "nowhere.exr"})");
  EXPECT_EQ(run_seamcl(dir, "cube-metrics --scene scene.json" + common, out, err), 2);
  EXPECT_NE(err.find("options.environment.file"), std::string::npos) << err;
  EXPECT_NE(err.find("nowhere.exr"), std::string::npos) << err;
}

TEST(EnvironmentFile, DamagedFilesAreRefusedAndNeverCrash) {
  // Truncations and bit flips of a small EXR and PNG equirect: every damaged file either loads
  // (finite texels of the equirect's size) or is refused with an InputError naming the field;
  // nothing else escapes and nothing crashes.
  EnvironmentDir dir;
  std::mt19937 random(20261129);
  int refused = 0, loaded = 0;
  for (const std::string extension : {"exr", "png"}) {
    const std::string clean = dir.file("clean." + extension);
    write_image(clean, 16, 8, equirect_pixels(16, 8));
    std::ifstream in(clean, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 64u);
    std::vector<std::vector<char>> damaged;
    for (size_t length = 0; length < bytes.size(); length += std::max<size_t>(1, bytes.size() / 48))
      damaged.emplace_back(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(length));
    for (int flip = 0; flip < 96; ++flip) {
      std::vector<char> copy = bytes;
      for (int bit = 0; bit < 1 + flip % 4; ++bit) {
        const size_t at = random() % copy.size();
        copy[at] = static_cast<char>(copy[at] ^ (1 << (random() % 8)));
      }
      damaged.push_back(std::move(copy));
    }
    const std::string name = "damaged." + extension;
    for (const std::vector<char>& file : damaged) {
      std::ofstream(dir.file(name), std::ios::binary | std::ios::trunc).write(file.data(), static_cast<std::streamsize>(file.size()));
      EnvironmentFiles files;
      files.names = {name};
      files.field = "environment";
      try {
        const EnvironmentImage image = read_environment_files(files, dir.file(""), resolve_any_path);
        EXPECT_EQ(image.texels.size(), static_cast<size_t>(image.width) * image.height);
        for (const glm::vec3& texel : image.texels) ASSERT_TRUE(std::isfinite(texel.x + texel.y + texel.z));
        ++loaded;
      } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.field()).rfind("environment", 0), 0u) << error.what();
        ++refused;
      }
    }
  }
  EXPECT_GT(refused, 40) << "truncated files must be refused";
  std::cout << "damaged environment files: " << refused << " refused, " << loaded << " loaded\n";
}

}  // namespace
}  // namespace seamcl
