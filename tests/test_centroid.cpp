// Centroid shading as D3D and GL define it: a triangle that covers every sample of a pixel is
// shaded at the pixel centre, at every MSAA rate; only a partly covered pixel moves its shading
// point to the centroid of its covered samples. (The centroid of a full pattern is not the centre:
// at 16x it is (-1/32, -1/32), so shading there would make 16x less accurate than 8x.)
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "test_support.h"
#include "pipeline/stages/sample_pattern.h"
#include "pipeline/stages/shade_resolve_twin.h"

using namespace seamcl;

namespace {

// A setup whose 1/w plane is positive everywhere, so only the coverage decides the point.
TriangleSetup flat_setup() {
  TriangleSetup t{};
  t.inv_w[0] = 1.0f;
  t.u_over_w[1] = 0.01f;
  t.v_over_w[2] = 0.01f;
  return t;
}

}  // namespace

TEST(Centroid, FullPatternsCentroidIsOffCentreAt16x) {
  // What makes the rule matter: the mean of the 16x positions is (-1/32, -1/32) of a pixel.
  float mean_x = 0.0f, mean_y = 0.0f;
  for (const SampleOffset& s : sample_pattern(16)) {
    mean_x += static_cast<float>(s.x) / 16.0f;
    mean_y += static_cast<float>(s.y) / 16.0f;
  }
  EXPECT_FLOAT_EQ(mean_x / 16.0f, -1.0f / 32.0f);
  EXPECT_FLOAT_EQ(mean_y / 16.0f, -1.0f / 32.0f);
}

TEST(Centroid, TwinShadesAFullyCoveredPixelAtItsCentreAtEveryRate) {
  const TriangleSetup setup = flat_setup();
  for (int msaa : {1, 2, 4, 8, 16}) {
    SCOPED_TRACE(msaa);
    FrameParams frame{};
    frame.sample_count = msaa;
    frame.shading_mode = SEAMCL_SHADE_CENTROID;
    const std::vector<uint32_t> all(static_cast<size_t>(msaa), 7u);
    const PixelFragment full = pixel_fragment(frame, setup, all.data(), 7u, 3, 5);
    EXPECT_EQ(full.covered, msaa);
    EXPECT_EQ(full.x, 3.5f);
    EXPECT_EQ(full.y, 5.5f);
    if (msaa == 1) continue;
    // One sample left to another triangle: the centroid of the rest, which is not the centre.
    std::vector<uint32_t> partial = all;
    partial[0] = 8u;
    const PixelFragment part = pixel_fragment(frame, setup, partial.data(), 7u, 3, 5);
    EXPECT_EQ(part.covered, msaa - 1);
    EXPECT_TRUE(part.x != 3.5f || part.y != 5.5f) << part.x << "," << part.y;
  }
}

TEST(Centroid, KernelMatchesPixelShadingOnFullyCoveredPixels) {
  // A textured scene: a moved shading point changes the colour. Pixels whose samples are all
  // won by one triangle must come out identical under pixel and centroid shading; partly
  // covered pixels may differ (and some do).
  const Scene scene = generate_scene("quad2", {});
  Renderer renderer(seamcl_tests::shared_runtime());
  renderer.load_scene(scene);
  for (int msaa : {2, 4, 8, 16}) {
    SCOPED_TRACE(msaa);
    RenderOptions options;
    options.width = 48;
    options.height = 40;
    options.msaa = msaa;
    options.shading = ShadingMode::Pixel;
    const RenderResult centre = renderer.render(scene.camera, options);
    options.shading = ShadingMode::Centroid;
    const RenderResult centroid = renderer.render(scene.camera, options);
    const std::vector<uint32_t> winners = renderer.read_sample_triangles();
    size_t full = 0, full_differing = 0, partial_differing = 0;
    for (size_t pixel = 0; pixel < centre.pixels.size(); ++pixel) {
      const uint32_t* ids = &winners[pixel * static_cast<size_t>(msaa)];
      const bool one_triangle = ids[0] != SEAMCL_NO_TRIANGLE && std::all_of(ids, ids + msaa, [&](uint32_t id) { return id == ids[0]; });
      const bool same = centre.pixels[pixel] == centroid.pixels[pixel];
      if (one_triangle) {
        ++full;
        full_differing += !same;
      } else {
        partial_differing += !same;
      }
    }
    EXPECT_GT(full, centre.pixels.size() / 4);
    EXPECT_EQ(full_differing, 0u);
    EXPECT_GT(partial_differing, 0u);
  }
}
