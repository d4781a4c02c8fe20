// The downsample stage (kernels/downsample.cl): the kernel against its twin bit for bit, the twin
// against the host's reference filters (OIIO's Mitchell resize, the box mean) within a float
// tolerance, and a render reduced on the device against the same render read back and reduced.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include <seamcl/eval/reference.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/stages/downsample_launcher.h"
#include "pipeline/stages/downsample_twin.h"
#include "test_support.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;

namespace {

std::vector<glm::vec4> random_image(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<glm::vec4> image(static_cast<size_t>(width) * height);
  for (glm::vec4& p : image) {
    p = glm::vec4(seamcl_tests::uniform(rng, 0, 4), seamcl_tests::uniform(rng, 0, 1), seamcl_tests::uniform(rng, 0, 0.01f),
                  1.0f);
  }
  return image;
}

std::vector<glm::vec4> on_device(const std::vector<glm::vec4>& image, int width, int height, const DownsampleTaps& taps) {
  ClRuntime& runtime = shared_runtime();
  DownsampleLauncher launcher(runtime);
  cl::Buffer buffer(runtime.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, image.size() * sizeof(glm::vec4),
                    const_cast<glm::vec4*>(image.data()));
  std::vector<glm::vec4> out;
  std::vector<cl::Event> passes, readback;
  launcher.enqueue(buffer, width, height, taps, out, passes, readback);
  runtime.queue().finish();
  EXPECT_EQ(passes.size(), 2u);
  EXPECT_EQ(readback.size(), 1u);
  return out;
}

bool same_bits(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(glm::vec4)) == 0;
}

// The largest channel difference relative to the largest channel value of `b`.
double relative_difference(const std::vector<glm::vec4>& a, const std::vector<glm::vec4>& b) {
  double worst = 0, largest = 0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 4; ++c) {
      worst = std::max(worst, std::fabs(static_cast<double>(a[i][c]) - b[i][c]));
      largest = std::max(largest, std::fabs(static_cast<double>(b[i][c])));
    }
  return worst / largest;
}

}  // namespace

TEST(Downsample, TapsOfTheReferenceFilters) {
  const DownsampleTaps m = mitchell_taps();
  EXPECT_EQ(m.factor, 8);
  ASSERT_EQ(m.weights.size(), 32u);  // radius 2 output pixels = 16 source pixels each side
  EXPECT_EQ(m.first, -12);           // output pixel 0's centre is at source 4.0
  double sum = 0;
  for (size_t k = 0; k < m.weights.size(); ++k) {
    sum += m.weights[k];
    EXPECT_EQ(m.weights[k], m.weights[m.weights.size() - 1 - k]) << "not symmetric at " << k;
  }
  EXPECT_NEAR(sum, 1.0, 1e-6);
  EXPECT_LT(m.weights.front(), 0.0f);  // Mitchell's negative lobe near the edge of its support
  const DownsampleTaps b = box_taps();
  EXPECT_EQ(b.first, 0);
  EXPECT_EQ(b.weights, std::vector<float>(8, 0.125f));
  EXPECT_THROW(separable_taps(0, 2.0, [](double) { return 1.0; }), std::invalid_argument);
  EXPECT_THROW(separable_taps(8, 5.0, [](double) { return 1.0; }), std::invalid_argument);  // 80 taps
}

TEST(Downsample, KernelMatchesTwinBitForBit) {
  const int w = 96, h = 64;  // edges clamp on every side
  const std::vector<glm::vec4> image = random_image(w, h, 7);
  for (const DownsampleTaps& taps : {mitchell_taps(), box_taps()}) {
    SCOPED_TRACE(taps.weights.size());
    const std::vector<glm::vec4> device = on_device(image, w, h, taps);
    const std::vector<glm::vec4> twin = downsample_twin(image, w, h, taps);
    ASSERT_EQ(device.size(), static_cast<size_t>(w / 8 * h / 8));
    EXPECT_TRUE(same_bits(device, twin));
  }
}

TEST(Downsample, TwinWithinFloatToleranceOfTheHostFilters) {
  // OIIO's resize weighs the 2D footprint in one pass; the stage runs two separable passes in
  // float: the sums round differently, by a few float ulps of the largest value.
  const int w = 160, h = 120;
  const std::vector<glm::vec4> image = random_image(w, h, 11);
  const double mitchell = relative_difference(downsample_twin(image, w, h, mitchell_taps()),
                                              downsample_mitchell(image, w, h, 8));
  const double box = relative_difference(downsample_twin(image, w, h, box_taps()), downsample_box(image, w, h, 8));
  EXPECT_LT(mitchell, 5e-6);
  EXPECT_LT(box, 5e-6);
  // And the tolerance is not vacuous: a shifted filter is far outside it.
  DownsampleTaps shifted = mitchell_taps();
  shifted.first += 1;
  EXPECT_GT(relative_difference(downsample_twin(image, w, h, shifted), downsample_mitchell(image, w, h, 8)), 1e-3);
}

TEST(Downsample, RenderReducedOnTheDeviceEqualsTheReadBackReduced) {
  Renderer renderer(shared_runtime());
  renderer.load_scene(generate_scene("quad2", GeneratorOptions{}));
  RenderOptions options;
  options.method = Method::Traverse;
  options.msaa = 1;
  options.width = 128;
  options.height = 96;
  const RenderResult full = renderer.render(renderer.scene().camera, options);
  const RenderResult reduced = renderer.render_downsampled(renderer.scene().camera, options, mitchell_taps());
  EXPECT_EQ(reduced.width, 16);
  EXPECT_EQ(reduced.height, 12);
  EXPECT_GT(reduced.ms.downsample, 0.0);
  EXPECT_TRUE(same_bits(reduced.pixels, downsample_twin(full.pixels, 128, 96, mitchell_taps())));
  const RenderResult box = renderer.downsample_last_frame(box_taps());
  EXPECT_TRUE(same_bits(box.pixels, downsample_twin(full.pixels, 128, 96, box_taps())));
  options.width = 100;  // not a multiple of 8
  EXPECT_THROW(renderer.render_downsampled(renderer.scene().camera, options, mitchell_taps()), std::invalid_argument);
}
