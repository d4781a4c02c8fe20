// Users' assets: the OBJ reader on the Ptex samples and on crafted files, scenes of a mesh and its
// .ptx (face counts, the file's adjacency against the mesh's), the camera framed from the bounds,
// per-face image textures, the asset directory's containment and cache, and whole renders of
// every sample: constant colours exact under discard, traverse and guardband, traverse seamless
// across cube_text's rotated neighbours, no NaN with any method at 1x and 8x.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/assets/asset_directory.h>
#include <seamcl/assets/asset_scene.h>
#include <seamcl/assets/file_stamp.h>
#include <seamcl/assets/obj_mesh.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/core/input_error.h>
#include <seamcl/io/image_io.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/pipeline/texture_lookups.h>
#include <seamcl/scene/scene_generators.h>
#include <seamcl/scene/scene_json.h>
#include "core/srgb.h"
#include "lit_constant.h"
#include "pipeline/adjacency.h"
#include "test_support.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
namespace fs = std::filesystem;

namespace {

// Whether a FaceNeighbors map only translates (its linear part the identity).
bool is_translation(uint8_t code) {
  const std::array<float, 6> t = map_coefficients(code);
  return t[0] == 1.0f && t[4] == 1.0f;
}

std::string sample(const std::string& name) { return std::string(SEAMCL_TEST_ASSETS_DIR "/ptex/") + name; }

// The message of an InputError thrown by `run`, with its field checked.
template <typename Run>
std::string input_error(Run run, const std::string& field) {
  try {
    run();
  } catch (const InputError& error) {
    EXPECT_EQ(error.field(), field) << error.what();
    return error.what();
  }
  ADD_FAILURE() << "no InputError";
  return {};
}

// Whether `message` names each of `figures`: what makes it about this input (an index with what it
// counts, a line, a size, a quoted word, the file) and, where cases differ only by it, the word for
// the rule broken. The sentence around them is free to change.
::testing::AssertionResult names_all(const std::string& message, const std::vector<std::string>& figures) {
  std::string missing;
  for (const std::string& figure : figures)
    if (message.find(figure) == std::string::npos) missing += (missing.empty() ? "" : ", ") + ("\"" + figure + "\"");
  if (missing.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "the message does not name " << missing << ": " << message;
}

// The refusals of the two methods that read neighbours (traverse, guardband), each checked to name
// `method`, for a 32x32 render of `scene`.
std::vector<std::string> neighbour_method_refusals(const Scene& scene) {
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  RenderOptions options;
  options.width = 32;
  options.height = 32;
  std::vector<std::string> messages;
  for (Method method : {Method::Traverse, Method::Guardband}) {
    options.method = method;
    messages.push_back(input_error([&] { renderer.render(scene.camera, options); }, "method"));
  }
  return messages;
}

// A fresh directory per test, removed after it.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::temp_directory_path() / "seamcl_assets_XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp");
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path file = path_ / name;
    fs::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
    return file.string();
  }

 private:
  fs::path path_;
};

// The sample pairs: mesh, texture (the textures share meshes).
struct SamplePair {
  const char* mesh;
  const char* texture;
};
constexpr SamplePair kPairs[] = {{"cube.obj", "cube_text.ptx"},
                                 {"plane.obj", "rand_lo.ptx"},
                                 {"plane.obj", "wave_lo.ptx"},
                                 {"ptex_test_object.obj", "cellnoise.ptx"}};

// Loaded once per test process: cube_text alone is 72 faces of 512x512.
const Scene& sample_scene(const std::string& mesh, const std::string& texture) {
  static std::map<std::string, std::unique_ptr<Scene>> scenes;
  std::unique_ptr<Scene>& scene = scenes[mesh + "+" + texture];
  if (!scene) scene = std::make_unique<Scene>(load_scene_source(sample(mesh), sample(texture)));
  return *scene;
}

// black.ptx holds one face and no mesh: it goes on a unit quad.
std::string unit_quad_obj(const TempDir& dir) {
  return dir.write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
}

bool all_finite(const std::vector<glm::vec4>& pixels) {
  for (const glm::vec4& p : pixels)
    if (!std::isfinite(p.r) || !std::isfinite(p.g) || !std::isfinite(p.b) || !std::isfinite(p.a)) return false;
  return true;
}

}  // namespace

TEST(Assets, ObjSamplesHaveTheirFaceAndVertexCountsInFileOrder) {
  struct Expected {
    const char* name;
    size_t faces, vertices;
  };
  for (const Expected& e : {Expected{"cube.obj", 72, 64}, Expected{"plane.obj", 9, 16}, Expected{"ptex_test_object.obj", 306, 308}}) {
    SCOPED_TRACE(e.name);
    const ObjMesh mesh = read_obj_file(sample(e.name));
    EXPECT_EQ(mesh.faces.size(), e.faces);
    EXPECT_EQ(mesh.positions.size(), e.vertices);
    // The first and last face lines, read here without tinyobjloader: 1-based "v/vt/vn" indices.
    std::ifstream in(sample(e.name));
    std::vector<std::array<uint32_t, 4>> lines;
    std::vector<glm::vec3> first_vertex;
    for (std::string line; std::getline(in, line);) {
      std::istringstream words(line);
      std::string word;
      words >> word;
      if (word == "v" && first_vertex.empty()) {
        glm::vec3 p;
        words >> p.x >> p.y >> p.z;
        first_vertex.push_back(p);
      }
      if (word != "f") continue;
      std::array<uint32_t, 4> face{};
      for (uint32_t& index : face) {
        words >> word;
        index = static_cast<uint32_t>(std::stoul(word.substr(0, word.find('/')))) - 1;
      }
      lines.push_back(face);
    }
    ASSERT_EQ(lines.size(), e.faces);
    EXPECT_EQ(mesh.faces.front(), lines.front());
    EXPECT_EQ(mesh.faces.back(), lines.back());
    EXPECT_EQ(mesh.positions.front(), first_vertex.front());
  }
}

TEST(Assets, ObjRefusesAFaceThatIsNotAQuadNamingItsIndexAndLine) {
  const std::string text = "version 1\nsurface subd per-face cage crafted\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
                           "f 1 2 3 4\nf 2 5 3 4\n# a triangle next\nf 1 2 3\n";
  const std::string message = input_error([&] { parse_obj(text, "crafted.obj"); }, "scene");
  EXPECT_TRUE(names_all(message, {"'crafted.obj'", "face 2", "line 11", "3 vertices", "quads"}));
  const std::string missing = input_error([] { parse_obj("v 0 0 0\nf 1 2 3 4\n", "m.obj", "mesh"); }, "mesh");
  EXPECT_TRUE(names_all(missing, {"'m.obj'", "face 0", "line 2", "does not exist"}));
  EXPECT_TRUE(names_all(input_error([] { parse_obj("v 0 0 0\n", "empty.obj"); }, "scene"), {"'empty.obj'", "no faces"}));
  EXPECT_TRUE(names_all(input_error([] { read_obj_file("/nonexistent/x.obj"); }, "scene"), {"/nonexistent/x.obj", "no such file"}));
}

// Faces are counted before any is read: one over the bound is refused, even where a face names no vertex.
TEST(Assets, ObjRefusesMoreFacesThanItsBoundBeforeReadingThem) {
  std::string text = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  text.reserve(text.size() + 10 * (kMaxObjFaces + 1));
  for (size_t f = 0; f < kMaxObjFaces; ++f) text += "f 1 2 3 4\n";
  text += "f 1 2 3 99\n";  // past the bound and naming no vertex: the count is refused first
  const std::string message = input_error([&] { parse_obj(text, "many.obj", "mesh"); }, "mesh");
  EXPECT_TRUE(names_all(message, {"'many.obj'", "4194305 face lines", "limit of 4194304"})) << message;
  EXPECT_EQ(message.find("does not exist"), std::string::npos) << message;
}

// tinyobjloader reads an index with atoi (which wraps) and a number as its longest numeric prefix or 0;
// the reader's own pre-scan refuses them first, naming the line and the word.
TEST(Assets, ObjRefusesBadNumbersAndIndicesNamingTheLineAndTheWord) {
  const std::string quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";
  struct Case {
    std::string text;
    std::vector<std::string> figures;
  };
  for (const Case& c : {
           Case{quad + "f 99999999999999999999 2 3 4\n", {"'bad.obj'", "face 0", "line 5", "'99999999999999999999'", "4 vertices"}},
           Case{quad + "f 4294967297 2 3 4\n", {"'bad.obj'", "face 0", "line 5", "'4294967297'", "4 vertices"}},
           Case{"v nan 0 0\n" + quad + "f 1 2 3 4\n", {"'bad.obj'", "vertex 0", "line 1", "'nan'", "finite"}},
           Case{quad + "v inf 0 0\nf 1 2 3 4\n", {"'bad.obj'", "vertex 4", "line 5", "'inf'", "finite"}},
           Case{quad + "v 0x10 0 0\nf 1 2 3 4\n", {"'bad.obj'", "vertex 4", "line 5", "'0x10'", "decimal"}},
           Case{quad + "v 1,5 0 0\nf 1 2 3 4\n", {"'bad.obj'", "vertex 4", "line 5", "'1,5'", "decimal"}},
           // More of the same kind.
           Case{quad + "v 0 -INF 0\nf 1 2 3 4\n", {"vertex 4", "line 5", "'-INF'", "finite"}},
           Case{quad + "v 0 0 1e39\nf 1 2 3 4\n", {"vertex 4", "line 5", "'1e39'", "32-bit float"}},
           // Within float's range but past what the mesh's areas and framing can take in float.
           Case{quad + "v -3e38 0 0\nf 1 2 3 4\n", {"vertex 4", "line 5", "'-3e38'", "larger in magnitude than 1e9"}},
           Case{quad + "v 0 1000000001 0\nf 1 2 3 4\n", {"vertex 4", "line 5", "'1000000001'", "1e9"}},
           Case{quad + "v 1 2\nf 1 2 3 4\n", {"vertex 4", "line 5", "2 numbers"}},
           Case{quad + "f 1 2 3 0\n", {"face 0", "line 5", "'0'", "start at 1"}},
           Case{quad + "f 1 2 3 4.0\n", {"face 0", "line 5", "'4.0'", "integer"}},
           Case{quad + "f 1 2 3 -5\n", {"face 0", "line 5", "'-5'", "4 vertices"}},
           Case{quad + "f 1 2 3 4\nf 1 2 3 -4294967295\n", {"face 1", "line 6", "'-4294967295'", "does not exist"}},
           Case{quad + "f 1/x 2 3 4\n", {"face 0", "line 5", "texture coordinate", "'x'", "'1/x'", "integer"}},
           Case{quad + "f 1/0 2 3 4\n", {"face 0", "line 5", "texture coordinate", "'0'", "'1/0'"}},
           Case{"vn 0 0 1\n" + quad + "f 1//x 2 3 4\n", {"face 0", "line 6", "normal", "'x'", "'1//x'"}},
           Case{quad + "f 1/1/1/1 2 3 4\n", {"face 0", "line 5", "'1/1/1/1'"}},
           // A lone carriage return ends a line for tinyobjloader, so it does here: no line hides behind a comment.
           Case{"# a comment\rv nan 0 0\r\n" + quad + "f 1 2 3 4\n", {"vertex 0", "line 2", "'nan'", "finite"}},
       }) {
    SCOPED_TRACE(c.text);
    const std::string message = input_error([&] { parse_obj(c.text, "bad.obj"); }, "scene");
    EXPECT_TRUE(names_all(message, c.figures));
  }
  // A hostile word is quoted cut short and without control characters, so the message stays one short line.
  const std::string long_word = input_error([&] { parse_obj(quad + "v 1 2 3" + std::string(1000, '\x01') + "\nf 1 2 3 4\n", "bad.obj"); }, "scene");
  EXPECT_TRUE(names_all(long_word, {"vertex 4", "line 5", "'3???"}));
  EXPECT_LT(long_word.size(), 200u) << long_word;
  // Through read_obj_file and the field a scene file names, as a mesh on disk is read.
  TempDir dir;
  const std::string path = dir.write("nan.obj", quad + "v nan 0 0\nf 1 2 3 4\n");
  const std::string message = input_error([&] { read_obj_file(path, "mesh"); }, "mesh");
  EXPECT_TRUE(names_all(message, {"'" + path + "'", "vertex 4", "line 5", "'nan'", "finite"}));
}

// Damaged OBJ text: byte flips, truncations, spliced lines and hostile words in each sample file.
// Each case must either read into a mesh that keeps the reader's invariants (every index names a
// vertex, every coordinate finite and at most 1e9 in magnitude; the scene made from it validated,
// or refused) or be refused with InputError: no crash, no other exception.
// Deterministic: a fixed seed, no std distributions.
TEST(Assets, ObjFuzzNeverCrashes) {
  std::mt19937_64 random(20261205);
  const auto below = [&](size_t n) { return n == 0 ? size_t{0} : static_cast<size_t>(random() % n); };
  const std::vector<std::string> words = {"f", "v", "vt", "vn", "#", "/", "//", "-1", "0", "4294967296", "1e39",
                                          "nan", "-inf", "0x1p3", "+", "\r", "\n", "\t", " ", "f 1 2 3 4",
                                          "v 1 2 3", std::string(1, '\0'), "99999999999999999999", "1/2/3/4"};
  int read = 0, refused = 0;
  for (const char* name : {"cube.obj", "plane.obj", "ptex_test_object.obj"}) {
    std::ifstream in(sample(name), std::ios::binary);
    const std::string seed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_FALSE(seed.empty()) << name;
    for (int round = 0; round < 1500; ++round) {
      std::string text = seed;
      for (int edits = 1 + static_cast<int>(below(4)); edits > 0; --edits) {
        const size_t at = below(text.size() + 1);
        switch (below(5)) {
          case 0: if (at < text.size()) text[at] = static_cast<char>(text[at] ^ (1 << below(8))); break;
          case 1: text.resize(at); break;
          case 2: text.insert(at, words[below(words.size())]); break;
          case 3: {  // a line of the text again, somewhere else
            const size_t from = below(text.size()), end = text.find('\n', from);
            text.insert(at, text.substr(from, end == std::string::npos ? std::string::npos : end - from + 1));
            break;
          }
          default: if (at < text.size()) text.erase(at, 1 + below(8)); break;
        }
      }
      SCOPED_TRACE(std::string(name) + " round " + std::to_string(round));
      try {
        const ObjMesh mesh = parse_obj(text, name);
        ++read;
        ASSERT_FALSE(mesh.faces.empty());
        for (const glm::vec3& p : mesh.positions)
          for (int c = 0; c < 3; ++c) ASSERT_TRUE(std::isfinite(p[c]) && std::fabs(p[c]) <= 1e9f) << p[c];
        for (const auto& face : mesh.faces)
          for (uint32_t v : face) ASSERT_LT(v, mesh.positions.size());
        try {
          scene_from_mesh(mesh, 4, name);
        } catch (const InputError&) {
        }
      } catch (const InputError&) {
        ++refused;
      }
    }
  }
  std::printf("OBJ fuzz: %d cases read, %d refused\n", read, refused);
  // Both outcomes happen, so the mutations reach past the first check.
  EXPECT_GT(read, 300);
  EXPECT_GT(refused, 300);
}

TEST(Assets, ObjStillReadsSlashedRelativeAndForwardIndicesWAndVertexColours) {
  // w, vertex colours, a comment after a vertex or a face, '+' and exponents; i/j/k, i/j, i//k, negative
  // (relative) indices in every part, and a forward reference to a vertex defined further on.
  const std::string text = "vt 0 0\nvt 1 0\nvn 0 0 1\n"
                           "v +1 +.5 -.5e-3 1.\n"
                           "v 1 2 3 0.5 0.5 0.5 # coloured\n"
                           "v 1e-5 2.5E+2 -0 \t\r\n"
                           "v .25 1. 7\n"
                           "f 1/1/1 2/2/1 3//1 4/1\n"
                           "f -4 -3/-2 -2//-1 -1/-1/-1\n"
                           "f 4 3 2 1\n"
                           "f 1 2 3 5\n"
                           "f 1/7 2/8 3/9 4//5\n"  // texture coordinates and normals a careless exporter left out
                           "f 2 3 4 1 # a comment after a face, # 5 6\n"
                           "v 9 9 9\n";
  const ObjMesh mesh = parse_obj(text, "forms.obj");
  const std::vector<glm::vec3> positions{{1.0f, 0.5f, -0.5e-3f}, {1, 2, 3}, {1e-5f, 250, -0.0f}, {0.25f, 1, 7}, {9, 9, 9}};
  EXPECT_EQ(mesh.positions, positions);
  const std::vector<std::array<uint32_t, 4>> faces{{0, 1, 2, 3}, {0, 1, 2, 3}, {3, 2, 1, 0},
                                                   {0, 1, 2, 4}, {0, 1, 2, 3}, {1, 2, 3, 0}};
  EXPECT_EQ(mesh.faces, faces);
}

TEST(Assets, SamplePairsLoadWithTheFilesAdjacencyAgreeingWithTheMesh) {
  for (const SamplePair& pair : kPairs) {
    SCOPED_TRACE(pair.texture);
    const Scene& scene = sample_scene(pair.mesh, pair.texture);
    const ObjMesh mesh = read_obj_file(sample(pair.mesh));
    ASSERT_EQ(scene.faces.size(), mesh.faces.size());
    EXPECT_EQ(scene.positions, mesh.positions);  // units unchanged
    EXPECT_TRUE(scene.orbit.has_value());
    EXPECT_TRUE(has_adjacency(build_adjacency(scene)));
  }
  // cube.obj's neighbours include rotated ones: some shared edge is not the opposite edge.
  const Scene& cube = sample_scene("cube.obj", "cube_text.ptx");
  int rotated = 0;
  for (const FaceNeighbors& n : build_adjacency(cube))
    for (int k = 0; k < 4; ++k) rotated += n.neighbor[k] >= 0 && !is_translation(n.edge_map[k]);
  EXPECT_GT(rotated, 0);
}

TEST(Assets, FaceCountsMustMatchAndADisagreeingAdjacencyNamesBothFaces) {
  const std::string counts = input_error([] { load_scene_source(sample("plane.obj"), sample("cube_text.ptx")); }, "texture");
  EXPECT_TRUE(names_all(counts, {"cube_text.ptx'", "72 faces", "plane.obj'", "has 9"}));

  // rand_lo on plane.obj, with face 4's right neighbour moved in the file only.
  PtexFile file = read_ptex_file(sample("rand_lo.ptx"));
  const int old_neighbor = file.faces[4].adjacent_faces[1];
  ASSERT_GE(old_neighbor, 0);
  file.faces[4].adjacent_faces[1] = 0;
  const std::string message = input_error(
      [&] { scene_from_ptex(read_obj_file(sample("plane.obj")), file, "plane.obj", "rand_lo.ptx"); }, "texture");
  EXPECT_TRUE(names_all(message, {"face 4 edge 1", "face 0 edge", "face " + std::to_string(old_neighbor) + " edge"}));
}

// Faces that share an edge, but only an edge of three faces: nothing links them, and the refusal
// says so instead of claiming that no two faces share an edge.
TEST(Assets, TraverseRefusesAMeshWhoseOnlySharedEdgeIsNonManifoldSayingSo) {
  TempDir dir;
  // Three quads around the edge from vertex 1 to vertex 2 (0-based 0 and 1), like pages of a book.
  const std::string book = dir.write("book.obj", "v 0 0 0\nv 0 1 0\nv 1 1 0\nv 1 0 0\nv -1 1 0\nv -1 0 0\n"
                                                 "v 0 1 1\nv 0 0 1\nf 1 2 3 4\nf 2 1 6 5\nf 1 2 7 8\n");
  const Scene scene = load_scene_source(book);
  const NonManifoldEdges non_manifold = non_manifold_edges(scene);
  EXPECT_EQ(non_manifold.count, 1u);
  EXPECT_EQ(non_manifold.first_vertex, 0u);
  EXPECT_EQ(non_manifold.second_vertex, 1u);
  EXPECT_EQ(non_manifold.example_faces, 3u);
  for (const std::string& message : neighbour_method_refusals(scene)) {
    EXPECT_EQ(message.find("no two of"), std::string::npos) << message;
    EXPECT_TRUE(names_all(message, {"vertices 0 and 1", "3 faces"}));
  }
  // A manifold mesh has none.
  EXPECT_EQ(non_manifold_edges(load_scene_source(sample("plane.obj"))).count, 0u);

  // example_faces counts a face once per time it holds the edge; no loaded face holds one twice,
  // as such a quad (folded back along the edge) has no area and is refused.
  const std::string folded = dir.write("folded.obj", "v 0 0 0\nv 0 1 0\nv 1 1 0\nv -1 0 0\nv -1 1 0\n"
                                                     "f 1 2 1 3\nf 2 1 4 5\n");
  const std::string refusal = input_error([&] { load_scene_source(folded); }, "faces[0].vertices");
  EXPECT_TRUE(names_all(refusal, {"zero area"}));
}

TEST(Assets, TraverseAndGuardbandRefuseAMeshWithoutSharedEdgesSingleQuadsStillRender) {
  TempDir dir;
  // Two quads side by side, each with vertices of its own: no edge is shared by index.
  const std::string split = dir.write("split.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\n"
                                                   "f 1 2 3 4\nf 5 6 7 8\n");
  const Scene scene = load_scene_source(split);
  const std::vector<std::string> refusals = neighbour_method_refusals(scene);
  ASSERT_EQ(refusals.size(), 2u);
  for (const std::string& message : refusals) {
    EXPECT_TRUE(names_all(message, {"2 faces", "'split'", "share an edge"}));
  }
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  RenderOptions options;
  options.width = 32;
  options.height = 32;
  options.method = Method::Discard;
  EXPECT_TRUE(all_finite(renderer.render(scene.camera, options).pixels));
  // Whatever came before: a discard render (no adjacency packed), a seam-mask render (the empty
  // adjacency packed and kept), a guardband band that is not 1..16.
  for (Method method : {Method::Guardband, Method::Traverse, Method::TraverseEdges}) {
    options.method = method;
    EXPECT_TRUE(names_all(input_error([&] { renderer.render(scene.camera, options); }, "method"), {"2 faces", "'split'"}));
  }
  options.method = Method::Black;
  EXPECT_EQ(renderer.render(scene.camera, options, true).seam_mask.size(), size_t{32 * 32});
  EXPECT_EQ(renderer.packed_scene().neighbors.size(), 2u);
  for (Method method : {Method::Traverse, Method::Guardband}) {
    options.method = method;
    EXPECT_TRUE(names_all(input_error([&] { renderer.render(scene.camera, options); }, "method"), {"2 faces", "'split'"}));
  }
  options.method = Method::Guardband;
  for (int band : {0, -1, 17}) {
    options.guard_band = band;
    EXPECT_TRUE(names_all(input_error([&] { renderer.render(scene.camera, options); }, "guard_band"),
                          {"1..16", "got " + std::to_string(band)}));
  }
  options.guard_band = 4;
  options.method = Method::Discard;
  EXPECT_TRUE(all_finite(renderer.render(scene.camera, options).pixels));  // still usable
  const Scene quad = load_scene_source(unit_quad_obj(dir));
  renderer.load_scene(quad);
  options.method = Method::Traverse;
  EXPECT_TRUE(all_finite(renderer.render(quad.camera, options).pixels));
}

TEST(Assets, TheFramedCameraSeesTheWholeMeshOnEveryOrbitFrame) {
  for (const char* mesh : {"cube.obj", "plane.obj", "ptex_test_object.obj"}) {
    SCOPED_TRACE(mesh);
    const Scene scene = load_scene_source(sample(mesh));
    for (int frame = 0; frame < 8; ++frame) {
      const Camera camera = orbit_camera(scene, frame, 8);
      if (frame == 0) EXPECT_EQ(camera.eye, scene.camera.eye);
      for (float aspect : {0.75f, 480.0f / 540.0f, 4.0f / 3.0f}) {
        const glm::mat4 view_projection = glm::perspective(glm::radians(camera.fov_y_degrees), aspect, 0.01f, 1000.0f) *
                                          glm::lookAt(camera.eye, camera.target, camera.up);
        for (const glm::vec3& p : scene.positions) {
          const glm::vec4 clip = view_projection * glm::vec4(p, 1.0f);
          ASSERT_GT(clip.w, 0.0f);
          EXPECT_LE(std::abs(clip.x / clip.w), 1.0f);
          EXPECT_LE(std::abs(clip.y / clip.w), 1.0f);
        }
      }
    }
  }
}

TEST(Assets, ConstantColourSamplesRenderExactlyUnderDiscardTraverseAndGuardband) {
  const glm::vec3 color(0.8f, 0.5f, 0.2f);
  const glm::vec3 stored(decode_srgb8(encode_srgb8(glm::vec4(color, 1.0f))));
  TempDir dir;
  for (const char* mesh : {"cube.obj", "plane.obj", "ptex_test_object.obj"}) {
    SCOPED_TRACE(mesh);
    // The meshes' own texture sizes, painted one colour (set_constant_textures keeps sizes).
    Scene scene = std::string(mesh) == "cube.obj"            ? sample_scene(mesh, "cube_text.ptx")
                  : std::string(mesh) == "plane.obj"         ? sample_scene(mesh, "wave_lo.ptx")
                                                             : sample_scene(mesh, "cellnoise.ptx");
    set_constant_textures(scene, glm::vec4(color, 1.0f));
    Renderer renderer(shared_runtime());
    renderer.load_scene(scene);
    for (int msaa : {1, 4}) {
      for (Method method : {Method::Discard, Method::Traverse, Method::Guardband}) {
        RenderOptions options;
        options.width = 96;
        options.height = 72;
        options.msaa = msaa;
        options.method = method;
        const seamcl_tests::SeamCheck check =
            seamcl_tests::compare_with_lit_constant(renderer, renderer.render(scene.camera, options), stored);
        EXPECT_GT(check.checked, 300u);
        EXPECT_EQ(check.off, 0u) << to_string(method) << " msaa " << msaa << " worst " << check.worst;
      }
    }
  }
}

// Lookups placed just inside a face, at the middle of an edge whose neighbour is rotated in uv,
// with a footprint that reaches over it. Each such pair of faces gets a texture that is linear in
// the first face's uv, continued over the second by unfolding it about the shared edge in 3D
// (from the mesh's positions, not from the adjacency transform under test); every filter
// reproduces linear content exactly where its taps read the right texels. Traverse must match
// it; clamp, which repeats the edge texels, must not (so the lookups do reach over the seam).
TEST(Assets, TraverseIsSeamlessAcrossCubeTextsRotatedNeighbours) {
  Scene scene = sample_scene("cube.obj", "cube_text.ptx");
  constexpr int kSide = 64;
  auto linear = [](glm::vec2 uv) { return glm::vec4(0.3f + 0.2f * uv.x, 0.4f + 0.15f * uv.y, 0.5f + 0.1f * (uv.x - uv.y), 1.0f); };
  for (Face& face : scene.faces) face.texture = build_mip_chain(TextureLevel{kSide, kSide, std::vector<glm::vec4>(kSide * kSide, glm::vec4(0.5f))});
  const std::vector<FaceNeighbors> adjacency = build_adjacency(scene);
  std::vector<bool> used(scene.faces.size(), false);
  std::vector<Lookup> lookups;
  std::vector<glm::vec4> expected;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    for (int k = 0; k < 4 && !used[f]; ++k) {
      const FaceNeighbors& n = adjacency[f];
      const int g = n.neighbor[k];
      if (g < 0 || used[static_cast<size_t>(g)] || is_translation(n.edge_map[k])) continue;
      used[f] = used[static_cast<size_t>(g)] = true;
      // f's uv frame in 3D (the cube's faces are squares): origin corner 0, axes to corners 1 and 3.
      const std::array<glm::vec3, 4> fc = scene.corners(scene.faces[f]);
      const glm::vec3 eu = fc[1] - fc[0], ev = fc[3] - fc[0];
      auto uv_in_f = [&](glm::vec3 p) { return glm::vec2(glm::dot(p - fc[0], eu) / glm::dot(eu, eu), glm::dot(p - fc[0], ev) / glm::dot(ev, ev)); };
      // g's corners unfolded into f's plane about the shared edge a-b.
      const glm::vec3 a = fc[static_cast<size_t>(k)], b = fc[static_cast<size_t>((k + 1) % 4)];
      const glm::vec3 edge = glm::normalize(b - a);
      const glm::vec3 centre = 0.25f * (fc[0] + fc[1] + fc[2] + fc[3]);
      const glm::vec3 outward = -glm::normalize((centre - a) - glm::dot(centre - a, edge) * edge);
      std::array<glm::vec2, 4> g_uv_in_f;
      const std::array<glm::vec3, 4> gc = scene.corners(scene.faces[static_cast<size_t>(g)]);
      for (size_t c = 0; c < 4; ++c) {
        const glm::vec3 d = gc[c] - a;
        const glm::vec3 perpendicular = d - glm::dot(d, edge) * edge;
        g_uv_in_f[c] = uv_in_f(a + glm::dot(d, edge) * edge + glm::length(perpendicular) * outward);
      }
      TextureLevel fl{kSide, kSide, {}}, gl{kSide, kSide, {}};
      for (int j = 0; j < kSide; ++j) {
        for (int i = 0; i < kSide; ++i) {
          const float u = (i + 0.5f) / kSide, v = (j + 0.5f) / kSide;
          fl.texels.push_back(linear({u, v}));
          const glm::vec2 in_f = (1 - u) * (1 - v) * g_uv_in_f[0] + u * (1 - v) * g_uv_in_f[1] + u * v * g_uv_in_f[2] + (1 - u) * v * g_uv_in_f[3];
          gl.texels.push_back(linear(in_f));
        }
      }
      scene.faces[f].texture = build_mip_chain(std::move(fl));
      scene.faces[static_cast<size_t>(g)].texture = build_mip_chain(std::move(gl));
      // Mid-edge, 1.5 texels inside, with a 4-texel footprint.
      const glm::vec2 uv = 0.5f * (uv_in_f(a) + uv_in_f(b)) + (1.5f / kSide) * glm::normalize(0.5f - 0.5f * (uv_in_f(a) + uv_in_f(b)));
      lookups.push_back({static_cast<uint32_t>(f), uv.x, uv.y, 4.0f / kSide, 0, 0, 4.0f / kSide});
      expected.push_back(linear(uv));
    }
  }
  ASSERT_GT(lookups.size(), 4u) << "cube.obj should have rotated neighbours";
  const PackedScene packed = pack_scene(scene, TexelFormat::Rgba32f, 0);
  TextureLookups batch(shared_runtime(), packed);
  batch.set_lookups(lookups);
  auto worst_error = [&](Method method) {
    const std::vector<glm::vec4> got = batch.sample(sampler_params(method, Filter::Trilinear, 16, ZeroCoverage::Clamp));
    float worst = 0;
    for (size_t i = 0; i < got.size(); ++i) worst = std::max(worst, glm::length(glm::vec3(got[i] - expected[i])));
    return worst;
  };
  const float traverse = worst_error(Method::Traverse);
  const float clamp = worst_error(Method::Clamp);
  RecordProperty("rotated_pairs", static_cast<int>(lookups.size()));
  EXPECT_LT(traverse, 1e-4f);
  EXPECT_GT(clamp, 100 * traverse + 1e-3f);
}

TEST(Assets, EverySampleRendersWithEveryMethodAt1xAnd8xWithoutNaN) {
  TempDir dir;
  std::vector<std::pair<std::string, std::string>> samples;
  for (const SamplePair& pair : kPairs) samples.emplace_back(pair.mesh, pair.texture);
  for (const auto& [mesh, texture] : samples) {
    SCOPED_TRACE(texture);
    const Scene& scene = sample_scene(mesh, texture);
    Renderer renderer(shared_runtime());
    renderer.load_scene(scene);
    for (const std::string& method : method_names()) {
      for (int msaa : {1, 8}) {
        const RenderOptions options = parse_render_options({{"method", method}, {"msaa", msaa}, {"size", "64x48"}});
        const RenderResult result = renderer.render(scene.camera, options);
        EXPECT_TRUE(all_finite(result.pixels)) << method << " " << msaa;
        EXPECT_GT(result.stats.fragments, 0u);
      }
    }
  }
  // black.ptx: one face, no mesh in the file, so on a unit quad.
  const Scene black = load_scene_source(unit_quad_obj(dir), sample("black.ptx"));
  Renderer renderer(shared_runtime());
  renderer.load_scene(black);
  for (const std::string& method : method_names())
    for (int msaa : {1, 8})
      EXPECT_TRUE(all_finite(renderer.render(black.camera, parse_render_options({{"method", method}, {"msaa", msaa}, {"size", "32x24"}})).pixels));
}

TEST(Assets, MeshSceneFilesNamePathsRelativeToTheFile) {
  TempDir dir;
  const std::string mesh = fs::relative(sample("plane.obj"), dir.path() / "scenes").string();
  const std::string texture = fs::relative(sample("wave_lo.ptx"), dir.path() / "scenes").string();
  const std::string file = dir.write("scenes/plane_wave.json", nlohmann::json{{"mesh", mesh}, {"texture", texture},
      {"light", {{"ambient", 0.5}}}}.dump());
  const Scene scene = load_scene_source(file);
  EXPECT_EQ(scene.name, "plane_wave");
  EXPECT_EQ(scene.faces.size(), 9u);
  EXPECT_EQ(scene.light.ambient, 0.5f);
  EXPECT_EQ(scene.faces[0].texture.width(), sample_scene("plane.obj", "wave_lo.ptx").faces[0].texture.width());
  // A camera given wins over the framed one; the framed orbit stays for --frame.
  const std::string with_camera = dir.write("scenes/camera.json", nlohmann::json{{"mesh", mesh},
      {"camera", {{"eye", {0, 0, 3}}, {"target", {0, 0, 0}}}}}.dump());
  const Scene framed = load_scene_source(with_camera);
  EXPECT_EQ(framed.camera.eye, glm::vec3(0, 0, 3));
  EXPECT_TRUE(framed.orbit.has_value());
  const std::string unknown = dir.write("scenes/bad.json", R"({"mesh": "x.obj", "lights": 1})");
  EXPECT_TRUE(names_all(input_error([&] { load_scene_source(unknown); }, "lights"), {"unknown field", "mesh"}));
  const std::string missing = dir.write("scenes/missing.json", R"({"mesh": "nowhere.obj"})");
  EXPECT_TRUE(names_all(input_error([&] { load_scene_source(missing); }, "mesh"), {"nowhere.obj", "'" + missing + "'"}));
  // As strict as every scene file: a repeated key (the last would win unseen) is refused.
  const std::string twice = dir.write("scenes/twice.json", R"({"mesh": ")" + mesh + R"(", "mesh": "nowhere.obj"})");
  EXPECT_TRUE(names_all(input_error([&] { load_scene_source(twice); }, "scene"), {"'mesh'", "twice"}));
  EXPECT_TRUE(names_all(input_error([&] { load_scene_source("paper", sample("wave_lo.ptx")); }, "texture"), {".obj", "'paper'"}));
}

TEST(Assets, ImageFacesAreReadUprightRelativeToTheSceneFile) {
  TempDir dir;
  // 4x2 linear values, written as EXR so they come back exactly (half floats of these values).
  std::vector<glm::vec4> pixels;
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) pixels.push_back(glm::vec4(0.125f * x, 0.5f * y, 0.25f, 1.0f));
  fs::create_directories(dir.path() / "tiles");
  write_image((dir.path() / "tiles" / "tile.exr").string(), 4, 2, pixels);
  write_image((dir.path() / "tiles" / "odd.exr").string(), 3, 2, std::vector<glm::vec4>(6, glm::vec4(1)));
  auto scene_with = [&](const std::string& image) {
    return nlohmann::json{{"positions", {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}},
                          {"faces", {{{"vertices", {0, 1, 2, 3}}, {"texture", {{"image", image}}}}}},
                          {"camera", {{"eye", {0.5, 0.5, 2}}, {"target", {0.5, 0.5, 0}}}}};
  };
  const Scene scene = load_scene_source(dir.write("tiled.json", scene_with("tiles/tile.exr").dump()));
  const TextureLevel& level0 = scene.faces[0].texture.levels[0];
  ASSERT_EQ(level0.width, 4);
  ASSERT_EQ(level0.height, 2);
  // Texture row 0 (v = 0) is the image's bottom row.
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 4; ++i) EXPECT_EQ(level0.at(i, j), pixels[static_cast<size_t>(1 - j) * 4 + i]) << i << "," << j;
  EXPECT_EQ(scene.faces[0].texture.levels.size(), 3u);

  const std::string odd = input_error([&] { load_scene_source(dir.write("odd.json", scene_with("tiles/odd.exr").dump())); },
                                      "faces[0].texture.image");
  EXPECT_TRUE(names_all(odd, {"3 texels", "power of two"}));
  input_error([&] { load_scene_source(dir.write("gone.json", scene_with("tiles/gone.png").dump())); }, "faces[0].texture.image");
  // host/scene alone reads no file: an inline scene cannot name one.
  const std::string inline_message = input_error([&] { parse_scene_json(scene_with("tiles/tile.exr")); }, "faces[0].texture.image");
  EXPECT_TRUE(names_all(inline_message, {"inline"}));
  nlohmann::json both = scene_with("tiles/tile.exr");
  both["faces"][0]["texture"]["width"] = 4;
  input_error([&] { parse_scene_json(both); }, "faces[0].texture.width");
}

// A scene file of one face per image, on the faces of a unit cube (six at most), camera outside.
nlohmann::json image_cube_scene(const std::vector<std::string>& images) {
  const std::vector<std::array<int, 4>> quads{{4, 5, 6, 7}, {1, 0, 3, 2}, {5, 1, 2, 6}, {0, 4, 7, 3}, {7, 6, 2, 3}, {0, 1, 5, 4}};
  nlohmann::json faces = nlohmann::json::array();
  for (size_t f = 0; f < images.size(); ++f) faces.push_back({{"vertices", quads[f]}, {"texture", {{"image", images[f]}}}});
  return {{"positions", {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}}},
          {"faces", faces},
          {"camera", {{"eye", {3, 2.5, 4}}, {"target", {0, 0, 0}}, {"fov_y_degrees", 40}}}};
}

// Pixels that differ from texel to texel and from image to image (seed), in [0, 1].
std::vector<glm::vec4> varied_pixels(int width, int height, int seed) {
  std::vector<glm::vec4> pixels;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      pixels.emplace_back(static_cast<float>((x * 7 + y * 3 + seed * 5) % 17) / 16.0f,
                          static_cast<float>((x + 11 * y + seed) % 13) / 12.0f, static_cast<float>(seed % 6) / 5.0f, 1.0f);
  return pixels;
}

SceneSourceOptions deferring(bool tint = false) {
  SceneSourceOptions options;
  options.generator.defer_textures = true;
  options.generator.tint = tint;
  return options;
}

bool same_chains(const MipChain& a, const MipChain& b) {
  if (a.levels.size() != b.levels.size()) return false;
  for (size_t k = 0; k < a.levels.size(); ++k)
    if (a.levels[k].width != b.levels[k].width || a.levels[k].height != b.levels[k].height ||
        a.levels[k].texels != b.levels[k].texels)
      return false;
  return true;
}

TEST(Assets, DeferredImageFacesHoldSizesOnlyAndMakeTheEagerTexels) {
  TempDir dir;
  // PNG (sRGB, 8 bits), EXR (linear half) and grey faces of different, non-square sizes.
  write_image((dir.path() / "a.png").string(), 16, 8, varied_pixels(16, 8, 1));
  write_image((dir.path() / "b.exr").string(), 4, 32, varied_pixels(4, 32, 2));
  write_image((dir.path() / "c.png").string(), 8, 8, varied_pixels(8, 8, 3));
  nlohmann::json doc = image_cube_scene({"a.png", "b.exr", "c.png"});
  doc["faces"].push_back({{"vertices", {0, 1, 5, 4}}, {"texture", {{"width", 8}, {"height", 4}}}});
  const std::string file = dir.write("mixed.json", doc.dump());
  for (const bool tint : {false, true}) {
    SceneSourceOptions eager_options;
    eager_options.generator.tint = tint;
    const Scene eager = load_scene_source(file, "", eager_options);
    const Scene deferred = load_scene_source(file, "", deferring(tint));
    ASSERT_FALSE(has_deferred_textures(eager));
    ASSERT_EQ(deferred.faces.size(), 4u);
    EXPECT_EQ(deferred.stored_texel_count(), 0u) << "a deferred scene file holds no float texels";
    EXPECT_EQ(deferred.texel_count(), eager.texel_count());
    for (size_t f = 0; f < deferred.faces.size(); ++f) {
      EXPECT_TRUE(is_deferred(deferred.faces[f].texture)) << f;
      EXPECT_EQ(deferred.faces[f].texture.width(), eager.faces[f].texture.width()) << f;
      EXPECT_EQ(deferred.faces[f].texture.height(), eager.faces[f].texture.height()) << f;
      EXPECT_TRUE(same_chains(face_texture(deferred, f), eager.faces[f].texture)) << "face " << f << " tint " << tint;
    }
    // Packed alike, so rendered alike.
    const RenderOptions options = parse_render_options({{"method", "traverse"}, {"msaa", 4}, {"size", "48x40"}});
    Renderer from_eager(shared_runtime()), from_deferred(shared_runtime());
    from_eager.load_scene(eager);
    from_deferred.load_scene(deferred);
    EXPECT_EQ(from_eager.render(eager.camera, options).pixels, from_deferred.render(deferred.camera, options).pixels);
  }
  // No analytic content for image faces: their texels are the only statement of it.
  EXPECT_FALSE(load_scene_source(file).albedo);
  EXPECT_FALSE(load_scene_source(file, "", deferring()).albedo);
}

TEST(Assets, AnImageFaceThatChangedOrWentBeforeItIsPackedIsAnInputError) {
  TempDir dir;
  const std::string image = (dir.path() / "face.png").string();
  const std::string file = dir.write("one.json", image_cube_scene({"face.png"}).dump());
  auto fresh = [&] {
    write_image(image, 8, 8, varied_pixels(8, 8, 4));
    return load_scene_source(file, "", deferring());
  };
  const std::string field = "faces[0].texture.image";

  // Rewritten with other pixels of the same size: refused, not shown.
  Scene scene = fresh();
  write_image(image, 8, 8, varied_pixels(8, 8, 5));
  fs::last_write_time(image, fs::last_write_time(image) + std::chrono::seconds(2));
  EXPECT_TRUE(names_all(input_error([&] { face_texture(scene, 0); }, field), {"face.png", "changed"}));
  Renderer renderer(shared_runtime());
  EXPECT_TRUE(names_all(input_error([&] { renderer.load_scene(scene); }, field), {"face.png", "changed"}));

  // Only touched (same bytes, later time): refused as well; the stamp is all that is compared.
  scene = fresh();
  fs::last_write_time(image, fs::last_write_time(image) + std::chrono::seconds(2));
  EXPECT_TRUE(names_all(input_error([&] { face_texture(scene, 0); }, field), {"face.png", "modified"}));

  // Another size.
  scene = fresh();
  write_image(image, 16, 8, varied_pixels(16, 8, 4));
  EXPECT_TRUE(names_all(input_error([&] { face_texture(scene, 0); }, field), {"face.png", "changed", " bytes"}));

  // Gone.
  scene = fresh();
  fs::remove(image);
  EXPECT_TRUE(names_all(input_error([&] { face_texture(scene, 0); }, field), {"face.png", "gone"}));
  EXPECT_TRUE(names_all(input_error([&] { Renderer(shared_runtime()).load_scene(std::move(scene)); }, field), {"face.png", "gone"}));

  // Each of them names the scene file, as the errors found when it is parsed do.
  scene = fresh();
  fs::remove(image);
  const std::string in_file = " (in '" + file + "')";
  for (const std::string& message : {input_error([&] { face_texture(scene, 0); }, field),
                                     input_error([&] { Renderer(shared_runtime()).load_scene(scene); }, field)})
    EXPECT_TRUE(message.ends_with("is gone (it was there when the scene was read)" + in_file)) << message;
  const std::string parse_time = input_error([&] { load_scene_source(file, "", deferring()); }, field);
  EXPECT_TRUE(parse_time.ends_with(in_file)) << parse_time;

  // Unchanged: made as often as asked, the same each time.
  scene = fresh();
  EXPECT_TRUE(same_chains(face_texture(scene, 0), face_texture(scene, 0)));
}

// A face's image swapped, after the scene was read, for a larger one of the same size on disk and
// modification time (so the stamp check passes): refused at its header, in the file as opened for
// the read, before any pixel is decoded. The larger file's pixel data is cut off, so a decode of
// it would fail with a decoder's error instead of naming the sizes.
TEST(Assets, AnImageFaceSwappedForALargerOneIsRefusedAtItsHeaderBeforeAnyPixelIsDecoded) {
  TempDir dir;
  const fs::path image = dir.path() / "face.png";
  write_image(image.string(), 64, 64, varied_pixels(64, 64, 8));
  const Scene scene = load_scene_source(dir.write("one.json", image_cube_scene({"face.png"}).dump()), "", deferring());
  ASSERT_EQ(scene.faces[0].texture.width(), 64);

  // 128 x 128 noise, cut to the 64 x 64 file's length: a whole header, part of its pixel data.
  const fs::path larger = dir.path() / "larger.png";
  write_image(larger.string(), 128, 128, varied_pixels(128, 128, 9));
  const auto length = fs::file_size(image);
  ASSERT_GT(fs::file_size(larger), length + 100);
  fs::resize_file(larger, length);
  int width = 0, height = 0;
  try {
    read_image(larger.string(), width, height);
    ADD_FAILURE() << "the cut file decoded";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()).find("128x128"), std::string::npos) << error.what();
  }
  // The swap: renamed over the face's file, with the old file's modification time.
  fs::last_write_time(larger, fs::last_write_time(image));
  const auto stamp = fs::last_write_time(image);
  fs::rename(larger, image);
  ASSERT_EQ(fs::file_size(image), length);
  ASSERT_EQ(fs::last_write_time(image), stamp);

  const std::string field = "faces[0].texture.image";
  for (const std::string& message :
       {input_error([&] { face_texture(scene, 0); }, field), input_error([&] { Renderer(shared_runtime()).load_scene(scene); }, field)}) {
    EXPECT_TRUE(names_all(message, {"face.png", "64x64, 4 channels", "128x128, 4 channels"}));
  }
}

TEST(Assets, ImageFacesWithBadPixelsAreRefusedWhenParsedOrWhenDeferredWhenMade) {
  TempDir dir;
  // A PNG whose header is whole and whose pixel data is cut off: its size is readable, its pixels not.
  write_image((dir.path() / "whole.png").string(), 64, 64, varied_pixels(64, 64, 6));
  {
    std::ifstream in(dir.path() / "whole.png", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t data = bytes.find("IDAT");  // the first chunk of pixel data: cut 16 bytes into it
    ASSERT_NE(data, std::string::npos);
    ASSERT_GT(bytes.size(), data + 100);
    dir.write("cut.png", bytes.substr(0, data + 20));
  }
  const std::string cut = dir.write("cut.json", image_cube_scene({"cut.png"}).dump());
  input_error([&] { load_scene_source(cut); }, "faces[0].texture.image");
  const Scene deferred = load_scene_source(cut, "", deferring());
  input_error([&] { face_texture(deferred, 0); }, "faces[0].texture.image");
  input_error([&] { Renderer(shared_runtime()).load_scene(deferred); }, "faces[0].texture.image");

  // A NaN texel: refused by validate_scene when baked at once, by the source when deferred, with
  // the same field and message.
  std::vector<glm::vec4> pixels = varied_pixels(4, 4, 7);
  pixels[5].g = std::nanf("");
  write_image((dir.path() / "nan.exr").string(), 4, 4, pixels);
  const std::string nan = dir.write("nan.json", image_cube_scene({"nan.exr"}).dump());
  const std::string eager_message = input_error([&] { load_scene_source(nan); }, "faces[0].texture");
  EXPECT_TRUE(names_all(eager_message, {"level 0", "non-finite"}));
  const Scene with_nan = load_scene_source(nan, "", deferring());
  // The whole message, the scene file's name included (it is a pack-time error of a scene file).
  EXPECT_EQ(input_error([&] { face_texture(with_nan, 0); }, "faces[0].texture"), eager_message);
  EXPECT_TRUE(eager_message.ends_with(" (in '" + nan + "')")) << eager_message;
  input_error([&] { Renderer(shared_runtime()).load_scene(with_nan); }, "faces[0].texture");
}

// The one stamp the image faces and the asset cache tell a changed file by: size and modification
// time, none for what is not a regular file.
TEST(Assets, AFileStampIsItsSizeAndModificationTime) {
  TempDir dir;
  const std::string file = dir.write("a.txt", "four");
  const std::optional<FileStamp> first = file_stamp(file);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->bytes, 4u);
  EXPECT_EQ(first->modified, fs::last_write_time(file));
  EXPECT_EQ(file_stamp(file), first);
  fs::last_write_time(file, first->modified + std::chrono::seconds(2));
  EXPECT_NE(file_stamp(file), first) << "touched";
  dir.write("a.txt", "five!");
  fs::last_write_time(file, first->modified);
  EXPECT_NE(file_stamp(file), first) << "another size at the same time";
  EXPECT_EQ(file_stamp(file)->bytes, 5u);
  EXPECT_FALSE(file_stamp((dir.path() / "none.txt").string()));
  EXPECT_FALSE(file_stamp(dir.path().string())) << "a directory";
}

TEST(Assets, TheAssetCacheCountsKeptPtexBytesAndReloadsASceneWhoseImageChanged) {
  TempDir root;
  fs::copy_file(sample("plane.obj"), root.path() / "plane.obj");
  fs::create_directories(root.path() / "maps");
  fs::copy_file(sample("wave_lo.ptx"), root.path() / "maps" / "wave_lo.ptx");
  const size_t ptex_bytes = static_cast<size_t>(fs::file_size(root.path() / "maps" / "wave_lo.ptx"));
  root.write("wave.json", R"({"mesh": "plane.obj", "texture": "maps/wave_lo.ptx"})");
  write_image((root.path() / "face.png").string(), 8, 8, varied_pixels(8, 8, 1));
  root.write("image.json", image_cube_scene({"face.png"}).dump());
  AssetDirectory assets(root.path().string(), {size_t{64} << 20, 8});

  // A deferred .ptx named inside a scene file: its bytes are kept by the scene, and counted.
  const auto wave = assets.load("wave.json", "", deferring());
  EXPECT_EQ(wave->texture_source_bytes, ptex_bytes);
  EXPECT_EQ(assets.cached_bytes(), scene_host_bytes(scene_sizes(*wave)) + ptex_bytes);
  EXPECT_EQ(assets.load("wave.json", "", {})->texture_source_bytes, 0u) << "baked: nothing kept";

  // An image face changed after the scene was cached: the entry is stale, loaded again.
  const auto first = assets.load("image.json", "", deferring());
  const long long loads = assets.file_loads();
  EXPECT_EQ(assets.load("image.json", "", deferring()), first);
  EXPECT_EQ(assets.file_loads(), loads);
  const fs::path image = root.path() / "face.png";
  write_image(image.string(), 8, 8, varied_pixels(8, 8, 2));
  fs::last_write_time(image, fs::last_write_time(image) + std::chrono::seconds(2));
  const auto again = assets.load("image.json", "", deferring());
  EXPECT_NE(again, first);
  EXPECT_EQ(assets.file_loads(), loads + 1);
  EXPECT_NO_THROW(face_texture(*again, 0));
  // A holder of the old scene reads the file it was loaded from (its open descriptor: the asset
  // directory never reads a name twice), not the one now at that name.
  EXPECT_NO_THROW(face_texture(*first, 0));
}

// A cache hit stamps its files outside the cache's lock: while it looks at a file, another thread's
// call that takes the lock is answered (within a bound, 10 s; under the lock it would wait for
// the look to end).
TEST(Assets, TheAssetCacheStampsFilesOutsideItsLock) {
  TempDir root;
  fs::copy_file(sample("plane.obj"), root.path() / "plane.obj");
  fs::copy_file(sample("wave_lo.ptx"), root.path() / "wave_lo.ptx");
  std::atomic<bool> watching = false;
  AssetDirectory* watched = nullptr;
  std::vector<std::future<size_t>> callers;  // kept past the look: a caller blocked by the lock ends after it
  std::vector<bool> answered;
  AssetDirectory assets(root.path().string(), {size_t{64} << 20, 4}, [&](const std::string& path) {
    if (watching) {
      callers.push_back(std::async(std::launch::async, [&] { return watched->cached_entries(); }));
      answered.push_back(callers.back().wait_for(std::chrono::seconds(10)) == std::future_status::ready);
    }
    return file_stamp(path);
  });
  watched = &assets;
  const auto first = assets.load("plane.obj", "wave_lo.ptx", {});
  watching = true;
  EXPECT_EQ(assets.load("plane.obj", "wave_lo.ptx", {}), first);
  watching = false;
  EXPECT_EQ(assets.file_loads(), 1);
  ASSERT_GE(answered.size(), 4u) << "the key's two files and the entry's two";
  for (size_t k = 0; k < answered.size(); ++k) EXPECT_TRUE(answered[k]) << "look " << k << " held the cache's lock";
  for (auto& caller : callers) EXPECT_EQ(caller.get(), 1u);
}

TEST(Assets, TheAssetDirectoryRefusesNamesThatLeaveItAndCachesWhatItLoads) {
  TempDir outside;
  const std::string secret = outside.write("secret.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  TempDir root;
  fs::copy_file(sample("plane.obj"), root.path() / "plane.obj");
  fs::create_directories(root.path() / "maps");
  fs::copy_file(sample("wave_lo.ptx"), root.path() / "maps" / "wave_lo.ptx");
  root.write(".hidden/x.obj", "");
  root.write("notes.txt", "");
  fs::create_symlink(secret, root.path() / "escape.obj");
  fs::create_symlink(outside.path(), root.path() / "linked_dir");
  root.write("scenes/out.json", R"({"mesh": "../../)" + outside.path().filename().string() + R"(/secret.obj"})");

  AssetDirectory assets(root.path().string(), {size_t{64} << 20, 4});
  std::vector<std::string> listed;
  for (const AssetEntry& entry : assets.list()) listed.push_back(entry.name + ":" + to_string(entry.kind));
  EXPECT_EQ(listed, (std::vector<std::string>{"maps/wave_lo.ptx:ptex", "plane.obj:mesh", "scenes/out.json:scene"}));

  EXPECT_TRUE(names_all(input_error([&] { assets.resolve("../" + outside.path().filename().string() + "/secret.obj", "", "scene"); },
                                    "scene"), {"'..'"}));
  EXPECT_TRUE(names_all(input_error([&] { assets.resolve(secret, "", "scene"); }, "scene"), {"absolute"}));
  EXPECT_TRUE(names_all(input_error([&] { assets.resolve("escape.obj", "", "scene"); }, "scene"), {"'escape.obj'", "leads out"}));
  EXPECT_TRUE(names_all(input_error([&] { assets.resolve("linked_dir/secret.obj", "", "texture"); }, "texture"),
                        {"'linked_dir/secret.obj'", "leads out"}));
  EXPECT_TRUE(names_all(input_error([&] { assets.resolve("nothing.obj", "", "scene"); }, "scene"), {"'nothing.obj'", "no asset"}));
  // A scene file inside cannot reach out either.
  input_error([&] { assets.load("scenes/out.json", "", {}); }, "mesh");

  const auto first = assets.load("plane.obj", "maps/wave_lo.ptx", {});
  const auto again = assets.load("plane.obj", "maps/wave_lo.ptx", {});
  EXPECT_EQ(first, again);
  EXPECT_EQ(assets.file_loads(), 2);  // the refused scene file, then the pair once
  EXPECT_EQ(assets.cached_entries(), 1u);
  SceneSourceOptions tinted;
  tinted.generator.tint = true;
  EXPECT_NE(assets.load("plane.obj", "maps/wave_lo.ptx", tinted), first);
  EXPECT_EQ(assets.cached_entries(), 2u);
  // Deferred and baked are separate entries: neither is handed to a caller asking for the other.
  SceneSourceOptions deferred;
  deferred.generator.defer_textures = true;
  const size_t eager_bytes = assets.cached_bytes();
  const auto lazy = assets.load("plane.obj", "maps/wave_lo.ptx", deferred);
  EXPECT_NE(lazy, first);
  // The deferred scene's source keeps the .ptx's bytes: the cache counts them.
  EXPECT_EQ(assets.cached_bytes(), eager_bytes + scene_host_bytes(scene_sizes(*lazy)) +
                                       static_cast<size_t>(fs::file_size(root.path() / "maps" / "wave_lo.ptx")));
  EXPECT_TRUE(has_deferred_textures(*lazy));
  EXPECT_FALSE(has_deferred_textures(*assets.load("plane.obj", "maps/wave_lo.ptx", {})));
  EXPECT_EQ(assets.load("plane.obj", "maps/wave_lo.ptx", deferred), lazy);
  EXPECT_EQ(assets.cached_entries(), 3u);
  // Bounded: with room for nothing, nothing stays.
  AssetDirectory uncached(root.path().string(), {0, 4});
  uncached.load("plane.obj", "", {});
  EXPECT_EQ(uncached.cached_entries(), 0u);
}

// A mesh without a .ptx gets the surface pattern at 64 x 64 a face, fewer texels a face when its
// faces would hold more than kMaxMeshTexels in all (a 1.6 MB OBJ of 40,000 faces once packed 218 M
// texels and peaked at 1.1 GB), and is refused when even one texel a face is too many.
TEST(Assets, MeshTexturesStayWithinTheTexelBound) {
  EXPECT_EQ(mesh_texture_side(1, 64), 64);
  EXPECT_EQ(mesh_texture_side(16384, 64), 64);  // 2^14 faces x 2^12 texels = 2^26
  EXPECT_EQ(mesh_texture_side(16385, 64), 32);
  EXPECT_EQ(mesh_texture_side(40000, 64), 32);
  EXPECT_EQ(mesh_texture_side(kMaxMeshTexels, 64), 1);
  for (const size_t faces : {size_t{1}, size_t{1000}, size_t{40000}, kMaxMeshTexels / 4, kMaxMeshTexels}) {
    const size_t side = static_cast<size_t>(mesh_texture_side(faces, 64));
    EXPECT_LE(faces * side * side, kMaxMeshTexels) << faces;
    EXPECT_TRUE(side == 64 || faces * (2 * side) * (2 * side) > kMaxMeshTexels) << faces << ": the largest side that fits";
  }
  // A 200 x 100 grid of quads: 20,000 faces get 32 x 32 each.
  ObjMesh grid;
  constexpr int kColumns = 200, kRows = 100;
  for (int y = 0; y <= kRows; ++y)
    for (int x = 0; x <= kColumns; ++x) grid.positions.push_back(glm::vec3(x, y, 0));
  for (int y = 0; y < kRows; ++y)
    for (int x = 0; x < kColumns; ++x) {
      const uint32_t v = static_cast<uint32_t>(y * (kColumns + 1) + x);
      grid.faces.push_back({v, v + 1, v + kColumns + 2, v + kColumns + 1});
    }
  const Scene scene = scene_from_mesh(grid, 64, "grid.obj", /*defer_textures=*/true);
  ASSERT_EQ(scene.faces.size(), 20000u);
  EXPECT_EQ(scene.faces[0].texture.width(), 32);
  EXPECT_EQ(scene.faces.back().texture.height(), 32);
}
