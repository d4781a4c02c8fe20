// The references (host/eval/reference.h) on cases whose answer is known, and the seam metric's
// controls: black and clamp stand apart from traverse on the seam mask.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <seamcl/core/input_error.h>
#include <seamcl/eval/comparison.h>
#include <seamcl/eval/reference.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "test_support.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;

namespace {

RenderOptions frame_options(int size, int msaa) {
  RenderOptions o;
  o.width = size;
  o.height = size;
  o.msaa = msaa;
  return o;
}

ReferenceSettings uncached() {
  ReferenceSettings settings;
  settings.use_cache = false;
  return settings;
}

}  // namespace

TEST(References, NamesParseAndPrintBothWays) {
  for (const std::string& name : reference_kind_names()) EXPECT_EQ(to_string(*parse_reference_kind(name)), name);
  EXPECT_EQ(parse_reference_kinds({"seamless", "paper", "seamless"}),
            (std::vector<ReferenceKind>{ReferenceKind::Seamless, ReferenceKind::Paper}));
  try {
    parse_reference_kinds({"paper", "exact"});
    FAIL() << "unknown reference accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "reference");
    EXPECT_NE(std::string(e.what()).find("'exact'"), std::string::npos) << e.what();
  }
}

TEST(References, BoxDownsampleIsTheBlockMean) {
  std::vector<glm::vec4> pixels(4 * 2);
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = glm::vec4(static_cast<float>(i), 1.0f, 0.0f, 1.0f);
  const std::vector<glm::vec4> out = downsample_box(pixels, 4, 2, 2);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_FLOAT_EQ(out[0].r, (0 + 1 + 4 + 5) / 4.0f);
  EXPECT_FLOAT_EQ(out[1].r, (2 + 3 + 6 + 7) / 4.0f);
  EXPECT_THROW(downsample_box(pixels, 4, 2, 3), std::invalid_argument);
}

TEST(References, AllReferencesAgreeOnAConstantScene) {
  // One colour everywhere, one normal, every pixel covered: each reference is that colour lit,
  // whatever its filter (float texels, so no sRGB rounding separates the texture from the albedo).
  GeneratorOptions constant;
  constant.constant_color = glm::vec3(0.6f, 0.3f, 0.2f);
  const Scene scene = generate_scene("closeup-corner", constant);
  Renderer renderer(shared_runtime());
  RenderOptions frame = frame_options(16, 4);
  frame.texels = TexelFormat::Rgba32f;
  renderer.load_scene(scene, frame.texels);
  const std::vector<ReferenceImage> images =
      reference_images(renderer, scene.camera, frame, uncached(),
                       {ReferenceKind::Paper, ReferenceKind::Box, ReferenceKind::Analytic});
  ASSERT_EQ(images.size(), 3u);
  EXPECT_EQ(images[0].kind, ReferenceKind::Paper);
  EXPECT_EQ(images[1].kind, ReferenceKind::Box);
  EXPECT_EQ(images[2].kind, ReferenceKind::Analytic);
  Renderer seamless(shared_runtime());
  seamless.load_scene(seamless_scene(scene), frame.texels);
  const ReferenceImage ideal = seamless_reference(seamless, scene.camera, frame);
  const glm::vec4 lit = renderer.render(scene.camera, frame).pixels[0];
  for (const std::vector<glm::vec4>* image : {&images[0].pixels, &images[1].pixels, &images[2].pixels, &ideal.pixels}) {
    ASSERT_EQ(image->size(), 16u * 16u);
    for (const glm::vec4& p : *image) ASSERT_LT(glm::length(glm::vec3(p - lit)), 2e-6f);
  }
}

TEST(References, SeamlessSceneIsTheGridAsOneTexture) {
  const Scene grid = generate_scene("closeup-corner", {});
  const Scene one = seamless_scene(grid);
  ASSERT_EQ(one.faces.size(), 1u);
  const TextureLevel& combined = one.faces[0].texture.levels.front();
  ASSERT_EQ(combined.width, 32);
  ASSERT_EQ(combined.height, 32);
  // Faces 0..3 are (column, row) (0,0), (1,0), (0,1), (1,1); row 0 at v = 0 in both.
  for (size_t f = 0; f < 4; ++f) {
    const TextureLevel& level = grid.faces[f].texture.levels.front();
    const int column = static_cast<int>(f % 2), row = static_cast<int>(f / 2);
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 16; ++i) ASSERT_EQ(combined.at(16 * column + i, 16 * row + j), level.at(i, j));
  }
  // Each coarser level is the grid's same level side by side (a box never straddles two faces).
  const TextureLevel& level2 = one.faces[0].texture.levels[2];
  EXPECT_EQ(level2.at(4, 0), grid.faces[1].texture.levels[2].at(0, 0));
  EXPECT_EQ(one.positions.front(), glm::vec3(-1.0f, -1.0f, 0.0f));
  EXPECT_EQ(one.positions[2], glm::vec3(1.0f, 1.0f, 0.0f));
}

TEST(References, SeamlessEqualsTheGridWhereNoFootprintCrossesAnEdge) {
  // Off the seam mask a face's filter reads only its own texels, which are the combined texture's:
  // the grid and the seamless reference agree there; on the mask traverse is far closer to it
  // than clamp.
  const Scene grid = generate_scene("closeup-corner", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(grid);
  Renderer seamless(shared_runtime());
  seamless.load_scene(seamless_scene(grid));
  RenderOptions frame = frame_options(40, 4);
  const ReferenceImage ideal = seamless_reference(seamless, grid.camera, frame);
  const std::vector<uint8_t> mask = footprint_seam_mask(renderer, grid.camera, frame);
  frame.method = Method::Traverse;
  const ImageErrors traverse = compare_images(renderer.render(grid.camera, frame).pixels, ideal.pixels, &mask);
  frame.method = Method::Clamp;
  const ImageErrors clamp = compare_images(renderer.render(grid.camera, frame).pixels, ideal.pixels, &mask);
  EXPECT_GT(traverse.seam.pixels, 0u);
  // The same texels read, at uv computed over another triangle (float rounding of the weights).
  EXPECT_LT(traverse.off_seam.max, 1e-3);
  EXPECT_LT(clamp.off_seam.max, 1e-3);
  EXPECT_GT(clamp.seam.mean, 2.0 * traverse.seam.mean);
}

TEST(References, SeamlessAndAnalyticRefuseScenesWithoutOne) {
  for (const char* name : {"quad2", "cube", "mixed"}) {
    try {
      seamless_scene(generate_scene(name, {}));
      ADD_FAILURE() << name << " has no seamless reference";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "reference");
      EXPECT_NE(std::string(e.what()).find("planar grid of equal-resolution faces"), std::string::npos) << e.what();
    }
  }
  Scene scene = generate_scene("quad2", {});
  scene.albedo = nullptr;
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  try {
    prepare_targets(shared_runtime(), renderer, scene.camera, frame_options(8, 1), {}, uncached(),
                    {ReferenceKind::Analytic});
    FAIL() << "analytic without an albedo function";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "reference");
    EXPECT_NE(std::string(e.what()).find("textures came from files"), std::string::npos) << e.what();
  }
}

TEST(References, ControlsStandApartFromTraverseOnTheSeamMask) {
  // The seam metric works when the controls fail it: on a magnified seam with texel-scale detail,
  // black (edges darkened) and clamp (edge texels repeated) have at least twice traverse's seam
  // error, against the seamless ideal and against the paper's reference.
  const Scene scene = generate_scene("closeup-seam", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const RenderOptions frame = frame_options(32, 1);
  const std::vector<MethodEntry> entries =
      method_entries(to_json(frame), {"traverse", "clamp", "black"}, {frame.msaa});
  const ComparisonTargets targets = prepare_targets(shared_runtime(), renderer, scene.camera, frame, entries,
                                                    uncached(), {ReferenceKind::Seamless, ReferenceKind::Paper});
  const TargetsFor targets_for = [&](const MethodEntry& entry) { return targets.for_entry(entry); };
  std::vector<std::string> progress;
  const std::vector<EntryResult> results =
      compare_methods(renderer, scene, scene.camera, entries, targets_for, 1, {},
                      [&](const std::string& line) { progress.push_back(line); });
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(progress, (std::vector<std::string>{"entry 1/3: traverse at msaa 1", "entry 2/3: clamp at msaa 1",
                                                "entry 3/3: black at msaa 1"}));
  for (size_t r = 0; r < 2; ++r) {
    auto seam_mean = [&](size_t entry) { return results[entry].errors_by_reference.at(r).second.seam.mean; };
    const std::string reference = results[0].errors_by_reference.at(r).first;
    EXPECT_GT(seam_mean(1), 2.0 * seam_mean(0)) << "clamp vs traverse against " << reference;
    EXPECT_GT(seam_mean(2), 2.0 * seam_mean(0)) << "black vs traverse against " << reference;
    EXPECT_GT(results[0].errors_by_reference.at(r).second.seam_coverage, 0.0);
  }
  EXPECT_EQ(results[0].errors_by_reference.at(0).first, "seamless");
  const nlohmann::json item = compare_result_json(results[0]);
  EXPECT_TRUE(item.at("errors").contains("paper"));
  EXPECT_EQ(item.at("error"), item.at("errors").at("seamless"));
}

TEST(References, CompareMethodsMeasureWithTheTargetsPackingNotAReload) {
  // The targets' renderer keeps its packing (the traverse reference added the adjacency, which a
  // reload would drop and a bake would make again); a renderer holding no scene loads it. Both
  // measure the same: the pixels and errors match bit for bit.
  const Scene scene = generate_scene("closeup-seam", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const RenderOptions frame = frame_options(32, 1);
  const std::vector<MethodEntry> entries = method_entries(to_json(frame), {"discard", "clamp"}, {frame.msaa});
  ReferenceSettings settings = uncached();
  settings.method = "traverse";
  const ComparisonTargets targets =
      prepare_targets(shared_runtime(), renderer, scene.camera, frame, entries, settings, {ReferenceKind::Paper});
  ASSERT_EQ(renderer.packed_scene().neighbors.size(), scene.faces.size());
  const TargetsFor targets_for = [&](const MethodEntry& entry) { return targets.for_entry(entry); };
  const std::vector<EntryResult> kept = compare_methods(renderer, scene, scene.camera, entries, targets_for, 1, {}, {});
  EXPECT_EQ(renderer.packed_scene().neighbors.size(), scene.faces.size()) << "the scene was loaded again";

  Renderer empty(shared_runtime());
  const std::vector<EntryResult> loaded = compare_methods(empty, scene, scene.camera, entries, targets_for, 1, {}, {});
  ASSERT_TRUE(empty.has_scene());
  ASSERT_EQ(kept.size(), 2u);
  ASSERT_EQ(loaded.size(), 2u);
  for (size_t i = 0; i < kept.size(); ++i) {
    ASSERT_TRUE(kept[i].errors && loaded[i].errors);
    EXPECT_TRUE(kept[i].last.pixels == loaded[i].last.pixels) << entries[i].method_name;
    EXPECT_EQ(kept[i].errors->all.mean, loaded[i].errors->all.mean);
    EXPECT_EQ(kept[i].errors->seam.mean, loaded[i].errors->seam.mean);
    EXPECT_EQ(kept[i].errors->seam.pixels, loaded[i].errors->seam.pixels);
    EXPECT_GT(kept[i].errors->seam.pixels, 0u);
    EXPECT_EQ(kept[i].texture_bytes, loaded[i].texture_bytes);
  }
}
