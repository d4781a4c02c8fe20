// The footprint seam mask (kernels/shade_resolve.cl built with SEAMCL_SEAM_MASK): the pixels where
// some fragment's texture footprint crosses its face's edge. Held to its twin, to what it must
// cover and leave out, and to what it is for: outside it every seam method returns the same
// colour, so the errors over it are the seam methods' own.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/metrics.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "test_support.h"
#include "pipeline/stages/shade_resolve_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;

namespace {

RenderOptions small_frame(int msaa, Filter filter = Filter::Aniso, ShadingMode shading = ShadingMode::Pixel) {
  RenderOptions o;
  o.method = Method::Black;
  o.width = 48;
  o.height = 40;
  o.msaa = msaa;
  o.filter = filter;
  o.shading = shading;
  return o;
}

size_t count_set(const std::vector<uint8_t>& mask, uint8_t value = SEAMCL_MASK_SEAM) {
  return static_cast<size_t>(std::count(mask.begin(), mask.end(), value));
}

// One big face (20 x 20 units, 64x64 texels) filling the view from 3 units away: every footprint
// stays far from its edges.
Scene single_big_face() {
  Scene scene;
  scene.name = "big-face";
  scene.positions = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}};
  TextureLevel level{64, 64, {}};
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i) level.texels.push_back(surface_pattern(glm::vec3(i * 0.3f, j * 0.3f, 0.0f)));
  scene.faces.push_back({{0, 1, 2, 3}, build_mip_chain(std::move(level))});
  scene.camera.eye = {0.3f, 0.2f, 3.0f};
  scene.camera.target = {0.0f, 0.0f, 0.0f};
  return scene;
}

}  // namespace

TEST(SeamMask, KernelEqualsItsTwin) {
  Renderer renderer(shared_runtime());
  for (const char* name : {"quad2", "closeup-corner", "mixed"}) {
    const Scene scene = generate_scene(name, {});
    renderer.load_scene(scene);
    const std::vector<RenderOptions> frames = {small_frame(1), small_frame(4), small_frame(4, Filter::Ewa),
                                               small_frame(2, Filter::Trilinear),
                                               small_frame(4, Filter::Aniso, ShadingMode::Sample),
                                               small_frame(8, Filter::Aniso, ShadingMode::Centroid)};
    for (const RenderOptions& options : frames) {
      const std::string where = std::string(name) + " msaa " + std::to_string(options.msaa) + " " +
                                to_string(options.filter) + " " + to_string(options.shading);
      const RenderResult result = renderer.render(scene.camera, options, true);
      ASSERT_EQ(result.seam_mask.size(), result.pixels.size()) << where;
      const ResolveReference twin = shade_resolve_reference(renderer.packed_scene(), renderer.last_frame_params(),
                                                            renderer.read_setups(), renderer.read_sample_triangles());
      ASSERT_EQ(twin.seam_mask.size(), result.seam_mask.size()) << where;
      size_t mismatches = 0;
      for (size_t p = 0; p < twin.seam_mask.size(); ++p) mismatches += twin.seam_mask[p] != result.seam_mask[p];
      EXPECT_EQ(mismatches, 0u) << where;
      EXPECT_GT(count_set(result.seam_mask), 0u) << where << ": every one of these frames shows a seam";
      for (uint8_t m : result.seam_mask) ASSERT_LE(m, SEAMCL_MASK_BOUNDARY) << where;
    }
  }
}

TEST(SeamMask, MaskedRenderGivesTheSameImage) {
  // The mask variant adds an output, nothing else.
  const Scene scene = generate_scene("quad2", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const RenderOptions options = small_frame(4);
  const RenderResult plain = renderer.render(scene.camera, options);
  const RenderResult masked = renderer.render(scene.camera, options, true);
  EXPECT_TRUE(plain.seam_mask.empty());
  ASSERT_EQ(plain.pixels.size(), masked.pixels.size());
  for (size_t p = 0; p < plain.pixels.size(); ++p) ASSERT_EQ(plain.pixels[p], masked.pixels[p]) << "pixel " << p;
}

TEST(SeamMask, MaskAloneIsTheShadedRendersMask) {
  // render_seam_mask leaves the fragments unshaded (what footprint_seam_mask wants); the mask is
  // the one a shaded render with the mask output gives.
  const Scene scene = generate_scene("closeup-corner", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  for (const RenderOptions& options : {small_frame(1), small_frame(4, Filter::Ewa), small_frame(4, Filter::Aniso, ShadingMode::Sample)}) {
    const std::vector<uint8_t> alone = renderer.render_seam_mask(scene.camera, options);
    EXPECT_EQ(renderer.last_frame_params().mask_only, 1);
    const RenderResult shaded = renderer.render(scene.camera, options, true);
    EXPECT_EQ(renderer.last_frame_params().mask_only, 0);
    EXPECT_EQ(alone, shaded.seam_mask) << to_string(options.filter) << " msaa " << options.msaa;
    EXPECT_GT(count_set(alone), 0u);
  }
}

TEST(SeamMask, EmptyOnASingleFaceFarFromItsEdges) {
  const Scene scene = single_big_face();
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  for (int msaa : {1, 4, 16}) {
    for (Filter filter : {Filter::Aniso, Filter::Ewa, Filter::Bilinear}) {
      const RenderResult result = renderer.render(scene.camera, small_frame(msaa, filter), true);
      EXPECT_EQ(count_set(result.seam_mask, SEAMCL_MASK_NONE), result.seam_mask.size())
          << "msaa " << msaa << " " << to_string(filter);
      // The face covers every pixel (pixels on its diagonal have a fragment of each triangle).
      EXPECT_GE(result.stats.fragments, result.pixels.size());
    }
  }
}

TEST(SeamMask, CoversTheSeamPixelsOfACloseUp) {
  const Scene scene = generate_scene("closeup-seam", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  const RenderOptions options = small_frame(4);
  const RenderResult result = renderer.render(scene.camera, options, true);
  const std::vector<uint32_t> winners = renderer.read_sample_triangles();
  const std::vector<TriangleSetup> setups = renderer.read_setups();
  // Every pixel whose samples see both faces is in the mask (its fragments are shaded at the
  // pixel centre, on one side of the seam or the other, within a texel of it)...
  size_t mixed = 0;
  for (size_t p = 0; p < result.pixels.size(); ++p) {
    std::set<uint32_t> faces;
    for (int s = 0; s < options.msaa; ++s) {
      const uint32_t slot = winners[p * static_cast<size_t>(options.msaa) + static_cast<size_t>(s)];
      if (slot != SEAMCL_NO_TRIANGLE) faces.insert(setups[slot].face);
    }
    if (faces.size() < 2) continue;
    ++mixed;
    EXPECT_EQ(result.seam_mask[p], SEAMCL_MASK_SEAM) << "pixel " << p << " straddles the seam";
  }
  std::set<uint32_t> all_faces;
  for (uint32_t slot : winners)
    if (slot != SEAMCL_NO_TRIANGLE) all_faces.insert(setups[slot].face);
  EXPECT_EQ(all_faces.size(), 2u);
  EXPECT_GT(mixed, 0u) << "the seam is in view";
  // ... and so is the band of half a texel on either side, which at this magnification (texels
  // of several pixels) is wider than the straddling pixels alone; the rest is not. The grid's
  // outer edges are in view too: their rims are boundary, not seam.
  const size_t covered = count_set(result.seam_mask);
  EXPECT_GE(covered, 2 * mixed);
  EXPECT_LT(covered, result.pixels.size() / 3);
  EXPECT_GT(count_set(result.seam_mask, SEAMCL_MASK_BOUNDARY), 0u);
}

TEST(SeamMask, OutsideTheMaskEveryMethodAgrees) {
  // The mask's point: where no footprint crosses an edge, the methods only differ in what they do
  // with taps outside the face, and there are none.
  for (const char* name : {"mixed", "closeup-corner"}) {
    const Scene scene = generate_scene(name, {});
    Renderer renderer(shared_runtime());
    renderer.load_scene(scene);
    RenderOptions options = small_frame(4);
    const std::vector<uint8_t> mask = footprint_seam_mask(renderer, scene.camera, options);
    std::vector<std::vector<glm::vec4>> images;
    // traverse (with the diagonal faces past corners) is the base; the mask reads those faces too.
    for (Method method : {Method::Traverse, Method::TraverseEdges, Method::Clamp, Method::Black, Method::Discard,
                          Method::Guardband}) {
      options.method = method;
      images.push_back(renderer.render(scene.camera, options).pixels);
    }
    for (size_t m = 1; m < images.size(); ++m) {
      float off_mask = 0.0f, on_mask = 0.0f;
      for (size_t p = 0; p < mask.size(); ++p) {
        const float d = glm::length(glm::vec3(images[m][p]) - glm::vec3(images[0][p]));
        float& worst = mask[p] == SEAMCL_MASK_NONE ? off_mask : on_mask;
        worst = std::max(worst, d);
      }
      // Taps outside that weigh under SEAMCL_SEAM_WEIGHT_TOLERANCE, and float rounding, only.
      EXPECT_LT(off_mask, 1e-4f) << name << " method " << m;
      EXPECT_GT(on_mask, 1e-3f) << name << " method " << m << " differs from traverse somewhere on the mask";
    }
  }
}

TEST(SeamMask, GuardbandIsRefusedWithTheReason) {
  const Scene scene = generate_scene("quad2", {});
  Renderer renderer(shared_runtime());
  renderer.load_scene(scene);
  RenderOptions options = small_frame(1);
  options.method = Method::Guardband;
  try {
    renderer.render(scene.camera, options, true);
    FAIL() << "guardband's mask was not refused";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "method");
    EXPECT_NE(std::string(e.what()).find("same mask"), std::string::npos) << e.what();
  }
  // footprint_seam_mask renders with black whatever the method.
  EXPECT_EQ(footprint_seam_mask(renderer, scene.camera, options),
            footprint_seam_mask(renderer, scene.camera, small_frame(1)));
}

TEST(SeamMask, TraversesBoundChangesNoPixel) {
  // The mask skips each evaluation that traverse's bound (neighbor_may_contribute) shows would
  // weigh nothing, and the own filter where every edge's bound rules its mirror out; built without
  // the bound (SEAMCL_TRAVERSE_EARLY_OUT=0) it evaluates all 12 mirrors and neighbours per fragment,
  // and the own filter wherever no mirror crossed, and every mask must be the same. Paper's faces have textures of 16 to 128 texels a
  // side, so coarser neighbours (whose taps reach further) are met.
  struct Frame {
    const char* scene;
    RenderOptions options;
    std::vector<uint8_t> mask;
  };
  std::vector<Frame> frames;
  for (const char* name : {"paper", "closeup-corner", "mixed"}) {
    const Scene scene = generate_scene(name, {});
    Renderer bounded(shared_runtime());
    bounded.load_scene(scene);
    for (Filter filter : {Filter::Aniso, Filter::Ewa, Filter::Bilinear}) {
      for (int msaa : {1, 4}) {
        RenderOptions options = small_frame(msaa, filter);
        options.width = 96;
        options.height = 80;
        frames.push_back({name, options, footprint_seam_mask(bounded, scene.camera, options)});
      }
    }
  }
  // A runtime of its own, whose programs are all built while the variable asks for every evaluation.
  const char* saved = std::getenv("SEAMCL_EXTRA_BUILD_OPTIONS");
  const std::string previous = saved ? saved : "";
  ::setenv("SEAMCL_EXTRA_BUILD_OPTIONS", "-DSEAMCL_TRAVERSE_EARLY_OUT=0", 1);
  struct Restore {
    bool had;
    std::string value;
    ~Restore() { had ? ::setenv("SEAMCL_EXTRA_BUILD_OPTIONS", value.c_str(), 1) : ::unsetenv("SEAMCL_EXTRA_BUILD_OPTIONS"); }
  } restore{saved != nullptr, previous};
  ClRuntime every_evaluation;
  size_t seam_pixels = 0;
  std::string loaded;
  Renderer unbounded(every_evaluation);
  for (const Frame& frame : frames) {
    if (loaded != frame.scene) {
      const Scene scene = generate_scene(frame.scene, {});
      unbounded.load_scene(scene);
      loaded = frame.scene;
    }
    const std::vector<uint8_t> without = footprint_seam_mask(unbounded, unbounded.scene().camera, frame.options);
    ASSERT_EQ(frame.mask.size(), without.size());
    size_t differing = 0;
    for (size_t p = 0; p < without.size(); ++p) differing += frame.mask[p] != without[p];
    EXPECT_EQ(differing, 0u) << frame.scene << " " << to_string(frame.options.filter) << " msaa " << frame.options.msaa;
    seam_pixels += count_set(without);
  }
  EXPECT_GT(seam_pixels, 0u);
}
