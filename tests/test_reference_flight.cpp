// One reference for many requests: concurrent requests for the same reference (the same
// reference_cache_key) wait for one render of it and share its image; different references
// do not wait for each other; a failed render reaches every waiter and is not remembered.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>
#include <unistd.h>

#include <seamcl/eval/reference.h>
#include <seamcl/scene/scene_generators.h>
#include "test_support.h"

using namespace seamcl;
namespace fs = std::filesystem;

namespace {

struct Fixture {
  Scene scene = generate_scene("quad2", GeneratorOptions{});
  RenderOptions frame;
  ReferenceSettings settings;
  Fixture() {
    frame.scene = "quad2";
    frame.width = 16;
    frame.height = 16;
    settings.msaa = 1;
    settings.use_cache = false;  // the sharing is in memory: no file to meet at
    settings.scene_hash = scene_content_hash(scene);
  }
};

// A high-resolution "render" that takes long enough for every thread to arrive meanwhile.
RenderResult slow_flat_render(const RenderOptions& high, std::atomic<int>& renders, float value) {
  ++renders;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  RenderResult r;
  r.width = high.width;
  r.height = high.height;
  r.pixels.assign(static_cast<size_t>(high.width) * high.height, glm::vec4(value, value, value, 1));
  return r;
}

}  // namespace

TEST(ReferenceFlight, ConcurrentRequestsForOneReferenceRenderItOnce) {
  Fixture f;
  std::atomic<int> renders{0};
  constexpr int kThreads = 6;
  std::vector<ReferenceImage> got(kThreads);
  std::vector<std::thread> threads;
  for (int i = 0; i < kThreads; ++i) {
    threads.emplace_back([&, i] {
      got[static_cast<size_t>(i)] = reference_image(f.scene, f.scene.camera, f.frame, f.settings, [&](const RenderOptions& high) {
        return slow_flat_render(high, renders, 0.5f);
      });
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(renders.load(), 1);
  int shared = 0;
  for (const ReferenceImage& r : got) {
    shared += r.shared ? 1 : 0;
    ASSERT_EQ(r.pixels.size(), 16u * 16u);
    EXPECT_EQ(r.pixels, got.front().pixels);
    EXPECT_NEAR(r.pixels[100].x, 0.5f, 1e-6f);
  }
  EXPECT_EQ(shared, kThreads - 1) << "exactly one request renders; the others wait for it";

  // Once answered, the key is free again: a later request renders anew (the cache is off).
  reference_image(f.scene, f.scene.camera, f.frame, f.settings,
                  [&](const RenderOptions& high) { return slow_flat_render(high, renders, 0.5f); });
  EXPECT_EQ(renders.load(), 2);
}

TEST(ReferenceFlight, DifferentReferencesDoNotShare) {
  Fixture f;
  ReferenceSettings box = f.settings;
  box.kind = ReferenceKind::Box;
  EXPECT_NE(reference_cache_key(f.scene, f.scene.camera, f.frame, box),
            reference_cache_key(f.scene, f.scene.camera, f.frame, f.settings));
  std::atomic<int> renders{0};
  ReferenceImage a, b;
  std::thread first([&] {
    a = reference_image(f.scene, f.scene.camera, f.frame, f.settings,
                        [&](const RenderOptions& high) { return slow_flat_render(high, renders, 0.25f); });
  });
  std::thread second([&] {
    b = reference_image(f.scene, f.scene.camera, f.frame, box,
                        [&](const RenderOptions& high) { return slow_flat_render(high, renders, 0.75f); });
  });
  first.join();
  second.join();
  EXPECT_EQ(renders.load(), 2);
  EXPECT_FALSE(a.shared);
  EXPECT_FALSE(b.shared);
  EXPECT_NEAR(a.pixels[0].x, 0.25f, 1e-6f);
  EXPECT_NEAR(b.pixels[0].x, 0.75f, 1e-6f);
}

TEST(ReferenceFlight, AFailedRenderReachesEveryWaiterAndIsNotKept) {
  Fixture f;
  std::atomic<int> renders{0};
  std::atomic<int> failures{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i) {
    threads.emplace_back([&] {
      try {
        reference_image(f.scene, f.scene.camera, f.frame, f.settings, [&](const RenderOptions&) -> RenderResult {
          ++renders;
          std::this_thread::sleep_for(std::chrono::milliseconds(300));
          throw std::runtime_error("device lost");
        });
      } catch (const std::runtime_error& e) {
        if (std::string(e.what()) == "device lost") ++failures;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(renders.load(), 1);
  EXPECT_EQ(failures.load(), 4);
  std::atomic<int> later{0};
  const ReferenceImage ok = reference_image(f.scene, f.scene.camera, f.frame, f.settings,
                                            [&](const RenderOptions& high) { return slow_flat_render(high, later, 1.0f); });
  EXPECT_EQ(later.load(), 1);
  EXPECT_FALSE(ok.shared);
}
