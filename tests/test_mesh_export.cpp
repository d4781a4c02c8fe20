// The displaced mesh export (render --export-mesh): the file holds every patch's own grid of the
// tessellation stage's vertices, bit for bit, in both formats, so a reader can check the surface
// is watertight. Read back here by small readers of our own, independent of the writer: every edge
// two patches share must carry the same float bits from both sides for the watertight methods, and
// must not for naive (so the check can fail).
#include <array>
#include <cstdlib>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/core/input_error.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "io/mesh_export.h"
#include "pipeline/displacement_packing.h"
#include "pipeline/stages/tessellate_launcher.h"
#include "test_support.h"

namespace {

using namespace seamcl;
using nlohmann::json;
using seamcl_tests::shared_runtime;
namespace fs = std::filesystem;

const std::string kAssets = std::string(SEAMCL_TEST_ASSETS_DIR) + "/ptex/";

struct ReadMesh {
  std::vector<std::array<float, 3>> vertices;
  std::vector<std::vector<uint32_t>> faces;  // 0-based
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

uint32_t le_u32(const std::string& bytes, size_t at) {
  uint32_t value = 0;
  for (int b = 0; b < 4; ++b) value |= static_cast<uint32_t>(static_cast<unsigned char>(bytes.at(at + b))) << (8 * b);
  return value;
}

float bits_to_float(uint32_t bits) {
  float value = 0;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

uint32_t float_bits(float value) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// A binary little-endian PLY with float x, y, z and a uchar/uint face list, as the header says;
// fails the test on anything else.
ReadMesh read_ply(const fs::path& path) {
  const std::string bytes = slurp(path);
  const std::string end = "end_header\n";
  const size_t header_end = bytes.find(end);
  EXPECT_NE(header_end, std::string::npos);
  if (header_end == std::string::npos) return {};
  std::istringstream header(bytes.substr(0, header_end));
  std::string line;
  size_t vertex_count = 0, face_count = 0;
  std::vector<std::string> properties;
  while (std::getline(header, line)) {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") {
      std::string format;
      words >> format;
      EXPECT_EQ(format, "binary_little_endian");
    } else if (word == "element") {
      std::string name;
      size_t count = 0;
      words >> name >> count;
      (name == "vertex" ? vertex_count : face_count) = count;
    } else if (word == "property") {
      properties.push_back(line);
    }
  }
  EXPECT_EQ(properties, (std::vector<std::string>{"property float x", "property float y", "property float z",
                                                   "property list uchar uint vertex_indices"}));
  ReadMesh mesh;
  size_t at = header_end + end.size();
  for (size_t v = 0; v < vertex_count; ++v, at += 12)
    mesh.vertices.push_back({bits_to_float(le_u32(bytes, at)), bits_to_float(le_u32(bytes, at + 4)),
                             bits_to_float(le_u32(bytes, at + 8))});
  for (size_t f = 0; f < face_count; ++f) {
    const int n = static_cast<unsigned char>(bytes.at(at++));
    std::vector<uint32_t> face;
    for (int k = 0; k < n; ++k, at += 4) face.push_back(le_u32(bytes, at));
    mesh.faces.push_back(face);
  }
  EXPECT_EQ(at, bytes.size()) << "bytes after the last face";
  return mesh;
}

// "v x y z" and "f a b c ..." (1-based); comments skipped. from_chars reads the nearest float, so a
// 9-digit text gives back the written bits.
ReadMesh read_obj(const fs::path& path) {
  std::istringstream in(slurp(path));
  std::string line;
  ReadMesh mesh;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string tag, word;
    words >> tag;
    if (tag == "v") {
      std::array<float, 3> p{};
      for (float& c : p) {
        words >> word;
        const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), c);
        EXPECT_TRUE(error == std::errc() && end == word.data() + word.size()) << line;
      }
      mesh.vertices.push_back(p);
    } else if (tag == "f") {
      std::vector<uint32_t> face;
      while (words >> word) face.push_back(static_cast<uint32_t>(std::stoul(word)) - 1);
      mesh.faces.push_back(face);
    } else {
      ADD_FAILURE() << "unexpected line: " << line;
    }
  }
  return mesh;
}

ReadMesh read_mesh(const fs::path& path) { return path.extension() == ".ply" ? read_ply(path) : read_obj(path); }

fs::path scratch_file(const std::string& name) {
  return fs::temp_directory_path() / ("seamcl_mesh_" + std::to_string(::getpid()) + "_" + name);
}

// Renders one 64x64 frame of `scene` through the render job, as `seamcl render` does, exporting
// to `path`.
void render_and_export(const Scene& scene, const std::string& scene_name, DisplacementMethod method, int t,
                       const fs::path& path) {
  const RenderJob job(json{{"scene", scene_name},
                           {"size", "64x64"},
                           {"displacement_method", to_string(method)},
                           {"tessellation", t},
                           {"export_mesh", path.string()}});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene, job.options().texels);
  const RenderRun run = job.run(shared_runtime(), renderer, renderer.scene(), JobControl{});
  EXPECT_EQ(run.last.width, 64);
}

// The tessellation stage's own read-back for the same settings.
std::vector<TessVertex> stage_vertices(const Scene& scene, DisplacementMethod method, int t) {
  RenderOptions options;
  TessellateLauncher stage(shared_runtime());
  stage.load(pack_displacement(scene, {method, t, 0}));
  return stage.tessellate();
}

// Grid point (i, j) of step k (0..T) along a patch's edge e, counted from corner e.
std::pair<int, int> edge_point(int e, int k, int t) {
  switch (e) {
    case 0: return {k, 0};
    case 1: return {t, k};
    case 2: return {t - k, t};
    default: return {0, t - k};
  }
}

struct EdgeCheck {
  size_t shared_edges = 0;
  size_t compared_points = 0;
  size_t differing_points = 0;  // points whose two copies differ in some coordinate's bits
};

// Every edge shared by two faces, found from the scene's own vertex indices (not the packing's
// neighbour data), its T+1 points compared between the two patches' grids in the file.
EdgeCheck check_shared_edges(const Scene& scene, const ReadMesh& mesh, int t) {
  const size_t side = static_cast<size_t>(t) + 1;
  auto index = [&](size_t patch, std::pair<int, int> ij) {
    return patch * side * side + static_cast<size_t>(ij.second) * side + static_cast<size_t>(ij.first);
  };
  std::map<std::pair<uint32_t, uint32_t>, std::vector<std::pair<size_t, int>>> edges;  // sorted ends -> (face, edge)
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int e = 0; e < 4; ++e) {
      const uint32_t a = scene.faces[f].vertices[e], b = scene.faces[f].vertices[(e + 1) % 4];
      edges[{std::min(a, b), std::max(a, b)}].push_back({f, e});
    }
  }
  EdgeCheck check;
  for (const auto& [ends, uses] : edges) {
    if (uses.size() != 2) continue;
    ++check.shared_edges;
    const auto [p, pe] = uses[0];
    const auto [q, qe] = uses[1];
    // Same direction when both edges start at the same mesh vertex.
    const bool same_way = scene.faces[p].vertices[pe] == scene.faces[q].vertices[qe];
    for (int k = 0; k <= t; ++k) {
      const auto& a = mesh.vertices.at(index(p, edge_point(pe, k, t)));
      const auto& b = mesh.vertices.at(index(q, edge_point(qe, same_way ? k : t - k, t)));
      ++check.compared_points;
      bool differs = false;
      for (int c = 0; c < 3; ++c) differs = differs || float_bits(a[c]) != float_bits(b[c]);
      check.differing_points += differs;
    }
  }
  return check;
}

struct ExportCase {
  std::string label;
  Scene scene;
  std::string scene_name;
};

std::vector<ExportCase> export_cases() {
  std::vector<ExportCase> cases;
  cases.push_back({"displaced", generate_scene("displaced", {}), "displaced"});
  Scene plane = load_scene_source(kAssets + "plane.obj");
  attach_ptex_displacement(plane, kAssets + "rand_lo.ptx");
  cases.push_back({"plane.obj + rand_lo.ptx", std::move(plane), kAssets + "plane.obj"});
  return cases;
}

TEST(MeshExport, SharedEdgesAreBitExactForWatertightMethodsAndNotForNaive) {
  for (const ExportCase& c : export_cases()) {
    for (int t : {3, 4}) {
      for (DisplacementMethod method : {DisplacementMethod::Naive, DisplacementMethod::Zipper,
                                        DisplacementMethod::Ownership, DisplacementMethod::Fixed}) {
        const std::vector<TessVertex> expected = stage_vertices(c.scene, method, t);
        for (const char* extension : {".ply", ".obj"}) {
          const std::string label = c.label + " " + to_string(method) + " T=" + std::to_string(t) + " " + extension;
          const fs::path path = scratch_file(std::string("edges") + extension);
          fs::remove(path);
          render_and_export(c.scene, c.scene_name, method, t, path);
          ASSERT_TRUE(fs::exists(path)) << label;
          EXPECT_FALSE(fs::exists(path.string() + ".partial")) << label;
          const ReadMesh mesh = read_mesh(path);
          fs::remove(path);

          // Every patch's own grid: patches * (T+1)^2 vertices, T^2 quads each.
          const size_t patches = c.scene.faces.size();
          const size_t side = static_cast<size_t>(t) + 1;
          ASSERT_EQ(mesh.vertices.size(), patches * side * side) << label;
          ASSERT_EQ(mesh.faces.size(), patches * static_cast<size_t>(t) * t) << label;
          for (const auto& face : mesh.faces) {
            ASSERT_EQ(face.size(), 4u) << label;
            for (uint32_t v : face) ASSERT_LT(v, mesh.vertices.size()) << label;
          }
          // The first quad of patch 1 is its own grid's cell (0, 0): nothing shared with patch 0.
          if (patches > 1)
            EXPECT_EQ(mesh.faces[static_cast<size_t>(t) * t],
                      (std::vector<uint32_t>{static_cast<uint32_t>(side * side), static_cast<uint32_t>(side * side + 1),
                                             static_cast<uint32_t>(side * side + side + 1),
                                             static_cast<uint32_t>(side * side + side)}))
                << label;

          // The positions are the stage's read-back, bit for bit.
          ASSERT_EQ(expected.size(), mesh.vertices.size()) << label;
          size_t mismatched = 0;
          for (size_t v = 0; v < expected.size(); ++v)
            for (int k = 0; k < 3; ++k) mismatched += float_bits(expected[v].position[k]) != float_bits(mesh.vertices[v][k]);
          EXPECT_EQ(mismatched, 0u) << label;

          const EdgeCheck edges = check_shared_edges(c.scene, mesh, t);
          EXPECT_GT(edges.shared_edges, 0u) << label;
          EXPECT_EQ(edges.compared_points, edges.shared_edges * side) << label;
          if (method == DisplacementMethod::Naive) {
            EXPECT_GT(edges.differing_points, 0u) << label << ": naive should crack somewhere";
          } else {
            EXPECT_EQ(edges.differing_points, 0u) << label << ": " << edges.differing_points << " of "
                                                  << edges.compared_points << " shared-edge points differ";
          }
        }
      }
    }
  }
}

// The OBJ's 9 digits read back to the same bits on values that need all of them; the PLY holds
// the bits themselves.
TEST(MeshExport, EncodingsRoundTripAwkwardFloats) {
  std::vector<TessVertex> vertices(4);  // one patch at T = 1
  const std::array<float, 12> values{0.1f,      -0.0f,         1.0f / 3.0f, 16777217.0f,     1.5e-38f, -3.4028235e38f,
                                     2e-30f,     0.123456789f, -2.5f,       123456.789f, 7e-10f, 1.0f};
  for (size_t i = 0; i < values.size(); ++i) vertices[i / 3].position[i % 3] = values[i];
  for (const char* extension : {".ply", ".obj"}) {
    const fs::path path = scratch_file(std::string("floats") + extension);
    write_patch_mesh(path.string(), vertices, 1);
    const ReadMesh mesh = read_mesh(path);
    fs::remove(path);
    ASSERT_EQ(mesh.vertices.size(), 4u) << extension;
    for (size_t i = 0; i < values.size(); ++i)
      EXPECT_EQ(float_bits(mesh.vertices[i / 3][i % 3]), float_bits(values[i])) << extension << " value " << i;
    ASSERT_EQ(mesh.faces.size(), 1u);
    EXPECT_EQ(mesh.faces[0], (std::vector<uint32_t>{0, 1, 3, 2})) << extension;
  }
}

std::string field_of(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e.field();
  }
  return "";
}

TEST(MeshExport, BadRequestsAreRefusedNamingTheFieldAndWriteNothing) {
  const fs::path dir = scratch_file("dir");
  fs::create_directories(dir);
  auto request = [](const std::string& path) {
    return json{{"scene", "displaced"}, {"displacement_method", "fixed"}, {"tessellation", 2}, {"export_mesh", path}};
  };
  for (const std::string& bad : {std::string(""), (dir / "mesh.stl").string(), (dir / "mesh").string(),
                                 (dir / "missing" / "mesh.obj").string(), dir.string() + ".obj"}) {
    if (bad == dir.string() + ".obj") fs::create_directories(bad);  // a directory where the file would go
    EXPECT_EQ(field_of([&] { RenderJob job(request(bad)); }), "export_mesh") << "'" << bad << "'";
  }
  json not_string = request("x.obj");
  not_string["export_mesh"] = 5;
  EXPECT_EQ(field_of([&] { RenderJob job(not_string); }), "export_mesh");
  // Without displacement there is no tessellation to export: refused, not an empty file.
  EXPECT_EQ(field_of([&] { RenderJob job(json{{"scene", "displaced"}, {"export_mesh", (dir / "m.obj").string()}}); }),
            "export_mesh");
  // The extension's case does not matter.
  EXPECT_EQ(mesh_format_for_path("A.PLY"), MeshFormat::Ply);
  EXPECT_EQ(mesh_format_for_path("a.Obj"), MeshFormat::Obj);
  // A vertex count that is not whole grids is a caller's bug, refused before any file exists.
  const fs::path path = dir / "partial.obj";
  EXPECT_THROW(write_patch_mesh(path.string(), std::vector<TessVertex>(5), 1), std::invalid_argument);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".partial"));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 0) << "nothing written";
  fs::remove_all(dir);
  fs::remove_all(dir.string() + ".obj");
}

// The command line: exit 2 with one line naming export_mesh, and no file, for each refusal; a
// displaced render writes the file (the OBJ's vertex lines are patches * (T+1)^2).
TEST(MeshExport, CommandLineRefusesNamingTheFieldAndWrites) {
  const fs::path dir = scratch_file("cli");
  fs::create_directories(dir);
  const fs::path err = dir / "err.txt";
  auto run = [&](const std::string& args) {
    const std::string command = std::string(SEAMCL_BINARY) + " render --scene displaced --size 16x16 " + args + " >/dev/null 2>" +
                                err.string() + " </dev/null";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  const std::string obj = (dir / "m.obj").string();
  for (const std::string& args : {std::string("--displacement-method fixed --export-mesh ''"),
                                  "--displacement-method fixed --export-mesh " + (dir / "m.stl").string(),
                                  "--displacement-method fixed --export-mesh " + (dir / "none" / "m.obj").string(),
                                  "--export-mesh " + obj}) {
    EXPECT_EQ(run(args), 2) << args;
    EXPECT_NE(slurp(err).find("export_mesh"), std::string::npos) << args << ": " << slurp(err);
  }
  fs::remove(err);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 0) << "a refusal wrote something";
  ASSERT_EQ(run("--displacement-method zipper --tessellation 2 --export-mesh " + obj), 0) << slurp(err);
  const ReadMesh mesh = read_obj(obj);
  EXPECT_EQ(mesh.vertices.size(), generate_scene("displaced", {}).faces.size() * 9);
  fs::remove_all(dir);
}

}  // namespace
