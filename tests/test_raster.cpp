// The raster kernel against its twin on hand-made triangle setups, winner for winner at every
// sample rate: the cases built-in scenes rarely reach. Edges too long for the kernel's 32-bit
// steps (it switches to 64-bit ones), front faces overlapping (depths compared, ties going to the
// lower slot), planes whose 1/w is NaN or infinite (NaN never wins), boxes smaller than the edges
// (only pixels inside the box count), and an image whose size is not a multiple of the tile.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <seamcl/cl/cl_runtime.h>
#include "test_support.h"
#include "pipeline/stages/raster_twin.h"
#include "pipeline/stages/sample_pattern.h"
#include "pipeline/stages/triangle_setup_twin.h"

using namespace seamcl;
using seamcl_tests::shared_runtime;
using seamcl_tests::uniform;

namespace {

constexpr int kWidth = 70;   // not a multiple of SEAMCL_TILE_SIZE: the last tile column is partial
constexpr int kHeight = 37;

// Edge functions through three fixed-point vertices, inside >= 0 whatever their winding; the
// top-left bias (-1) on a random subset of edges. Vertices `reach` pixels around the image.
TriangleSetup random_setup(std::mt19937& rng, float reach) {
  int64_t x[3], y[3];
  for (int i = 0; i < 3; ++i) {
    x[i] = static_cast<int64_t>(uniform(rng, -reach, kWidth + reach) * SEAMCL_SUBPIXEL_ONE);
    y[i] = static_cast<int64_t>(uniform(rng, -reach, kHeight + reach) * SEAMCL_SUBPIXEL_ONE);
  }
  const int64_t area = (x[1] - x[0]) * (y[2] - y[0]) - (y[1] - y[0]) * (x[2] - x[0]);
  TriangleSetup t{};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    int64_t a = y[i] - y[j], b = x[j] - x[i], c = x[i] * y[j] - y[i] * x[j];
    if (area < 0) a = -a, b = -b, c = -c;
    t.edge_a[i] = static_cast<cl_int>(a);
    t.edge_b[i] = static_cast<cl_int>(b);
    t.edge_c[i] = c - static_cast<int64_t>(rng() % 2);
  }
  // A random box inside the image (the kernel and the twin visit only its pixels).
  t.bbox_min_x = static_cast<cl_int>(rng() % (kWidth / 2));
  t.bbox_min_y = static_cast<cl_int>(rng() % (kHeight / 2));
  t.bbox_max_x = std::min<cl_int>(kWidth - 1, t.bbox_min_x + 10 + static_cast<cl_int>(rng() % kWidth));
  t.bbox_max_y = std::min<cl_int>(kHeight - 1, t.bbox_min_y + 8 + static_cast<cl_int>(rng() % kHeight));
  t.ref_x = uniform(rng, 0.0f, kWidth);
  t.ref_y = uniform(rng, 0.0f, kHeight);
  // Nearly parallel planes, so that overlaps change winner inside a pixel.
  t.inv_w[0] = uniform(rng, 0.5f, 0.6f);
  t.inv_w[1] = uniform(rng, -0.004f, 0.004f);
  t.inv_w[2] = uniform(rng, -0.004f, 0.004f);
  return t;
}

struct RasterCase {
  std::string name;
  std::vector<TriangleSetup> setups;
};

std::vector<RasterCase> raster_cases() {
  std::mt19937 rng(14);
  std::vector<RasterCase> out;
  RasterCase short_edges{"short edges", {}}, long_edges{"long edges", {}}, odd_planes{"ties, NaN and infinite planes", {}};
  for (int k = 0; k < 24; ++k) short_edges.setups.push_back(random_setup(rng, 20.0f));
  // Edges of ~2^15 pixels: |a| + |b| past both 32-bit bounds (2^17 by lanes, 2^22 by pixels).
  for (int k = 0; k < 12; ++k) long_edges.setups.push_back(random_setup(rng, 40000.0f));
  for (int k = 0; k < 6; ++k) long_edges.setups.push_back(random_setup(rng, 20.0f));
  for (int k = 0; k < 16; ++k) odd_planes.setups.push_back(random_setup(rng, 30.0f));
  for (int k = 0; k < 4; ++k) {
    TriangleSetup copy = odd_planes.setups[k];  // the same plane on another slot: equal depths
    copy.edge_c[0] += 3000;
    odd_planes.setups.push_back(copy);
  }
  odd_planes.setups[5].inv_w[1] = std::numeric_limits<float>::quiet_NaN();
  odd_planes.setups[6].inv_w[2] = std::numeric_limits<float>::infinity();
  odd_planes.setups[7].inv_w[0] = -std::numeric_limits<float>::infinity();
  odd_planes.setups[8].inv_w[0] = 3e38f;  // finite, but not below the kernel's 2^100 bound
  odd_planes.setups[9].bbox_max_x = odd_planes.setups[9].bbox_min_x - 1;  // an empty slot
  out.push_back(short_edges);
  out.push_back(long_edges);
  out.push_back(odd_planes);
  return out;
}

// Every tile lists every slot (in reverse, so the list order is not the slot order). Each entry's
// rows are binning's (the box clipped to the tile) where the box meets the tile, else the whole
// tile: the kernel's own box test must then reject it. `setups` and the winners returned are in
// the device's slot numbering (slot-major: k * frame.input_triangles + t).
std::vector<uint32_t> run_raster_kernel(const std::vector<TriangleSetup>& setups, const FrameParams& frame) {
  const cl::Context& context = shared_runtime().context();
  cl::CommandQueue& queue = shared_runtime().queue();
  const size_t tiles = static_cast<size_t>(frame.tiles_x) * frame.tiles_y;
  const uint32_t n = static_cast<uint32_t>(setups.size());
  std::vector<cl_uint> counts(tiles, n), offsets(tiles), lists;
  std::vector<cl_ushort> rows;
  for (size_t tile = 0; tile < tiles; ++tile) {
    offsets[tile] = static_cast<cl_uint>(tile * n);
    const int x0 = static_cast<int>(tile % frame.tiles_x) * SEAMCL_TILE_SIZE;
    const int y0 = static_cast<int>(tile / frame.tiles_x) * SEAMCL_TILE_SIZE;
    for (uint32_t k = 0; k < n; ++k) {
      const TriangleSetup& s = setups[n - 1 - k];
      lists.push_back(n - 1 - k);
      const bool meets = s.bbox_min_x <= x0 + SEAMCL_TILE_SIZE - 1 && s.bbox_max_x >= x0 &&
                         s.bbox_min_y <= y0 + SEAMCL_TILE_SIZE - 1 && s.bbox_max_y >= y0 && !setup_is_empty(s);
      rows.push_back(meets ? static_cast<cl_ushort>(std::max(s.bbox_min_y - y0, 0) |
                                                    std::min(s.bbox_max_y - y0, SEAMCL_TILE_SIZE - 1) << 4 |
                                                    std::max(s.bbox_min_x - x0, 0) << 8 |
                                                    std::min(s.bbox_max_x - x0, SEAMCL_TILE_SIZE - 1) << 12)
                           : cl_ushort{0xF0F0});
    }
  }
  auto input = [&](const void* data, size_t bytes) {
    return cl::Buffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(data));
  };
  cl::Buffer frame_buffer = input(&frame, sizeof(FrameParams));
  cl::Buffer setup_buffer = input(setups.data(), setups.size() * sizeof(TriangleSetup));
  cl::Buffer count_buffer = input(counts.data(), counts.size() * sizeof(cl_uint));
  cl::Buffer offset_buffer = input(offsets.data(), offsets.size() * sizeof(cl_uint));
  cl::Buffer list_buffer = input(lists.data(), lists.size() * sizeof(cl_uint));
  cl::Buffer rows_buffer = input(rows.data(), rows.size() * sizeof(cl_ushort));
  const size_t samples = static_cast<size_t>(frame.width) * frame.height * frame.sample_count;
  cl::Buffer winners(context, CL_MEM_WRITE_ONLY, samples * sizeof(cl_uint));
  cl::Kernel kernel(shared_runtime().program(KernelProgram::Geometry), "raster");
  kernel.setArg(0, frame_buffer);
  kernel.setArg(1, setup_buffer);
  kernel.setArg(2, count_buffer);
  kernel.setArg(3, offset_buffer);
  kernel.setArg(4, list_buffer);
  kernel.setArg(5, rows_buffer);
  kernel.setArg(6, winners);
  // The renderer's launch: one work-item per tile.
  queue.enqueueNDRangeKernel(kernel, cl::NullRange,
                             cl::NDRange(static_cast<size_t>(frame.tiles_x), static_cast<size_t>(frame.tiles_y)),
                             cl::NDRange(1, 1));
  std::vector<uint32_t> out(samples);
  queue.enqueueReadBuffer(winners, CL_TRUE, 0, samples * sizeof(cl_uint), out.data());
  return out;
}

}  // namespace

TEST(Raster, KernelMatchesTwinOnLongEdgesOverlapsAndOddPlanesAtEveryRate) {
  for (const RasterCase& c : raster_cases()) {
    for (const int samples : {1, 2, 4, 8, 16}) {
      SCOPED_TRACE(c.name + ", " + std::to_string(samples) + " samples");
      FrameParams frame{};
      frame.width = kWidth;
      frame.height = kHeight;
      frame.tiles_x = (kWidth + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE;
      frame.tiles_y = (kHeight + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE;
      frame.sample_count = samples;
      frame.input_triangles = static_cast<cl_int>(c.setups.size());  // every record is slot 0 of its triangle
      frame.bin_capacity = static_cast<cl_uint>(c.setups.size()) * frame.tiles_x * frame.tiles_y;
      const std::vector<uint32_t> twin = raster_reference(c.setups, frame);
      const std::vector<uint32_t> kernel = run_raster_kernel(c.setups, frame);
      ASSERT_EQ(kernel.size(), twin.size());
      // The case must reach what it is named for: samples covered by two or more slots.
      const std::vector<SampleOffset>& pattern = sample_pattern(samples);
      size_t mismatches = 0, covered = 0, contested = 0;
      for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
          for (int s = 0; s < samples; ++s) {
            const size_t i = (static_cast<size_t>(y) * kWidth + x) * samples + s;
            mismatches += kernel[i] != twin[i];
            covered += twin[i] != SEAMCL_NO_TRIANGLE;
            int covering = 0;
            for (const TriangleSetup& t : c.setups) {
              covering += !setup_is_empty(t) && x >= t.bbox_min_x && x <= t.bbox_max_x && y >= t.bbox_min_y &&
                          y <= t.bbox_max_y && setup_covers(t, sample_fixed_x(x, pattern[s]), sample_fixed_y(y, pattern[s]));
            }
            contested += covering >= 2;
          }
        }
      }
      EXPECT_EQ(mismatches, 0u);
      EXPECT_GT(covered, 0u);
      EXPECT_GT(contested, 0u);
    }
  }
  // The long-edge case has edges past the 2^22 bound (else it tests nothing new).
  int64_t longest = 0;
  for (const TriangleSetup& t : raster_cases()[1].setups) {
    for (int i = 0; i < 3; ++i) longest = std::max<int64_t>(longest, std::abs(int64_t{t.edge_a[i]}) + std::abs(int64_t{t.edge_b[i]}));
  }
  EXPECT_GE(longest, int64_t{1} << 22);
}

TEST(Raster, TiesFollowInputOrderWithSlotMajorRecords) {
  // The device keeps slot k of input triangle t at k * triangles + t, so slot numbers do not run
  // in input order (t, then k), which the twin's tie rule follows. The case with equal depths,
  // laid out as input triangles of SEAMCL_CLIP_SLOTS slots each, placed slot-major for the kernel:
  // its winners, translated back, must be the twin's, and some ties must be decided by the order
  // (a later input triangle on a lower slot number).
  const RasterCase c = raster_cases()[2];
  const uint32_t triangles = static_cast<uint32_t>((c.setups.size() + SEAMCL_CLIP_SLOTS - 1) / SEAMCL_CLIP_SLOTS);
  std::vector<TriangleSetup> input_order(static_cast<size_t>(triangles) * SEAMCL_CLIP_SLOTS);
  for (TriangleSetup& s : input_order) s.bbox_max_x = s.bbox_max_y = -1;  // padding: empty slots
  std::copy(c.setups.begin(), c.setups.end(), input_order.begin());
  std::vector<TriangleSetup> slot_major(input_order.size());
  for (uint32_t t = 0; t < triangles; ++t) {
    for (uint32_t k = 0; k < SEAMCL_CLIP_SLOTS; ++k) slot_major[k * triangles + t] = input_order[t * SEAMCL_CLIP_SLOTS + k];
  }
  for (const int samples : {1, 4, 16}) {
    SCOPED_TRACE(std::to_string(samples) + " samples");
    FrameParams frame{};
    frame.width = kWidth;
    frame.height = kHeight;
    frame.tiles_x = (kWidth + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE;
    frame.tiles_y = (kHeight + SEAMCL_TILE_SIZE - 1) / SEAMCL_TILE_SIZE;
    frame.sample_count = samples;
    frame.input_triangles = static_cast<cl_int>(triangles);
    frame.bin_capacity = static_cast<cl_uint>(slot_major.size()) * frame.tiles_x * frame.tiles_y;
    const std::vector<uint32_t> twin = raster_reference(input_order, frame);
    std::vector<uint32_t> kernel = run_raster_kernel(slot_major, frame);
    for (uint32_t& slot : kernel) {
      if (slot != SEAMCL_NO_TRIANGLE) slot = (slot % triangles) * SEAMCL_CLIP_SLOTS + slot / triangles;
    }
    ASSERT_EQ(kernel.size(), twin.size());
    size_t mismatches = 0, order_decides = 0;
    const std::vector<SampleOffset>& pattern = sample_pattern(samples);
    for (size_t i = 0; i < twin.size(); ++i) {
      mismatches += kernel[i] != twin[i];
      if (twin[i] == SEAMCL_NO_TRIANGLE) continue;
      // Another slot as near at this sample whose slot-major number is lower, yet it loses.
      const size_t pixel = i / samples;
      const int x = static_cast<int>(pixel % kWidth), y = static_cast<int>(pixel / kWidth);
      const SampleOffset& o = pattern[i % samples];
      const TriangleSetup& w = input_order[twin[i]];
      const float depth = plane_inv_w(w, static_cast<float>(sample_fixed_x(x, o)) / SEAMCL_SUBPIXEL_ONE,
                                      static_cast<float>(sample_fixed_y(y, o)) / SEAMCL_SUBPIXEL_ONE);
      const uint32_t winner_device = (twin[i] % SEAMCL_CLIP_SLOTS) * triangles + twin[i] / SEAMCL_CLIP_SLOTS;
      for (uint32_t other = 0; other < input_order.size(); ++other) {
        const TriangleSetup& t = input_order[other];
        if (other == twin[i] || setup_is_empty(t) || x < t.bbox_min_x || x > t.bbox_max_x || y < t.bbox_min_y ||
            y > t.bbox_max_y || !setup_covers(t, sample_fixed_x(x, o), sample_fixed_y(y, o))) {
          continue;
        }
        const float other_depth = plane_inv_w(t, static_cast<float>(sample_fixed_x(x, o)) / SEAMCL_SUBPIXEL_ONE,
                                              static_cast<float>(sample_fixed_y(y, o)) / SEAMCL_SUBPIXEL_ONE);
        const uint32_t other_device = (other % SEAMCL_CLIP_SLOTS) * triangles + other / SEAMCL_CLIP_SLOTS;
        order_decides += other_depth == depth && other_device < winner_device;
      }
    }
    EXPECT_EQ(mismatches, 0u);
    EXPECT_GT(order_decides, 0u) << "no tie where slot-major numbers and input order disagree";
  }
}
