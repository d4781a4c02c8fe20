// The bench, cube-metrics and displacement-metrics jobs as a front end drives them: bad input names
// its field, the plan is made from the scene alone, a tiny run returns the documented keys, and
// the stop hook ends a run with Cancelled.
#include <cmath>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <seamcl/assets/scene_source.h>
#include <seamcl/core/cancelled.h>
#include <seamcl/core/input_error.h>
#include <seamcl/jobs/bench_job.h>
#include <seamcl/jobs/cube_metrics_job.h>
#include <seamcl/jobs/displacement_metrics_job.h>
#include "test_support.h"

namespace {

using nlohmann::json;
using namespace seamcl;

// The field of the InputError that `make` throws, or "" when it throws none.
template <typename Make>
std::string refused_field(Make make) {
  try {
    make();
  } catch (const InputError& error) {
    return error.field();
  }
  return "";
}

void expect_finite_numbers(const json& value, const std::string& where) {
  if (value.is_number()) {
    EXPECT_TRUE(std::isfinite(value.get<double>())) << where;
  } else if (value.is_structured()) {
    for (const auto& [key, item] : value.items()) expect_finite_numbers(item, where + "/" + key);
  }
}

void expect_keys(const json& out, const std::vector<std::string>& keys) {
  for (const std::string& key : keys) EXPECT_TRUE(out.contains(key)) << key << " missing in " << out.dump().substr(0, 400);
}

void expect_plan(const JobPlan& plan) {
  EXPECT_GT(plan.device.total(), 0u) << plan.what;
  EXPECT_GT(plan.host.total(), 0u) << plan.what;
}

JobControl stop_at_once() {
  JobControl control;
  control.should_stop = [] { return true; };
  return control;
}

const json kTinyBench = {{"scene", "quad2"}, {"size", "16x16"}, {"frames", 2}, {"msaa", "1"}};

Scene scene_of(const RenderOptions& frame, const GeneratorOptions& generator = {}) {
  SceneSourceOptions source;
  source.generator = generator;
  return load_scene_source(frame.scene, frame.texture, source);
}

TEST(JobsBench, BadInputNamesTheField) {
  EXPECT_EQ(refused_field([] { BenchJob(json{{"frames", 0}}); }), "frames");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"methods", "discard,nope"}}); }), "methods");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"shard", "3/2"}}); }), "shard");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"seam_mask", "wide"}}); }), "seam_mask");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"colour", 1}}); }), "colour");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"method", "discard"}}); }), "method");
  // An option the chosen mode would ignore.
  EXPECT_EQ(refused_field([] { BenchJob(json{{"sweep_repeats", 3}}); }), "sweep_repeats");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"sweep", "msaa"}, {"frames", 2}}); }), "frames");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"no_errors", true}, {"reference_frames", 2}}); }), "reference_frames");
  EXPECT_EQ(refused_field([] { BenchJob(json{{"sweep", "pixels"}, {"size", "64x64"}}); }), "size");
  // A boolean left at its default changes nothing, so it is not refused as ignored.
  EXPECT_EQ(refused_field([] { BenchJob(json{{"sweep", "msaa"}, {"no_errors", false}, {"scene", "quad2"}}); }), "");
}

TEST(JobsBench, PlanAndTinyRun) {
  BenchJob job(kTinyBench);
  job.reference_settings().use_cache = false;
  const Scene scene = scene_of(job.frame(), job.generator_options());
  expect_plan(job.plan(scene));
  const json out = job.run(seamcl_tests::shared_runtime(), scene, JobControl{});
  expect_keys(out, {"scene", "size", "device", "frames", "shard", "reference_frames", "errors", "error_frames", "order",
                    "seam_mask", "seam_radius", "seam_pixels_per_frame", "options", "wall_s", "results", "differences",
                    "reference"});
  ASSERT_EQ(out["results"].size(), 2u);  // discard and traverse at 1x
  for (const json& r : out["results"]) {
    expect_keys(r, {"method", "msaa", "ms", "ms_per_frame", "nan_pixels", "temporal", "texture_bytes", "error", "curve"});
    EXPECT_EQ(r["ms_per_frame"].size(), 2u);
  }
  EXPECT_EQ(out["differences"].size(), 1u);
  expect_finite_numbers(out, "bench");
}

TEST(JobsBench, StopHookCancels) {
  BenchJob job(kTinyBench);
  job.reference_settings().use_cache = false;
  const Scene scene = scene_of(job.frame(), job.generator_options());
  EXPECT_THROW(job.run(seamcl_tests::shared_runtime(), scene, stop_at_once()), Cancelled);
}

const json kTinyCube = {{"cube_sizes", "16"}, {"cube_methods", "cube-clamp,cube-seamless"}, {"size", "16x16"},
                        {"repeat", 1},       {"reference_scale", 2}};

TEST(JobsCube, BadInputNamesTheField) {
  EXPECT_EQ(refused_field([] { CubeMetricsJob(json{{"cube_sizes", "12"}}); }), "cube_sizes");
  EXPECT_EQ(refused_field([] { CubeMetricsJob(json{{"cube_methods", "cube-nope"}}); }), "cube_methods");
  EXPECT_EQ(refused_field([] { CubeMetricsJob(json{{"repeat", 0}}); }), "repeat");
  EXPECT_EQ(refused_field([] { CubeMetricsJob(json{{"reference_scale", 17}}); }), "reference_scale");
  EXPECT_EQ(refused_field([] { CubeMetricsJob(json{{"sizes", "16"}}); }), "sizes");
  // A scene without an environment is refused by the plan.
  const CubeMetricsJob job(json{{"scene", "quad2"}});
  const Scene scene = scene_of(job.frame());
  EXPECT_EQ(refused_field([&] { (void)job.plan(scene); }), "scene");
}

TEST(JobsCube, PlanAndTinyRun) {
  const CubeMetricsJob job(kTinyCube);
  const Scene scene = scene_of(job.frame());
  expect_plan(job.plan(scene));
  const json out = job.run(seamcl_tests::shared_runtime(), scene, JobControl{});
  expect_keys(out, {"scene", "size", "filter", "msaa", "reference_scale", "edge_pixels", "device", "results"});
  ASSERT_EQ(out["results"].size(), 2u);
  for (const json& r : out["results"])
    expect_keys(r, {"cube_size", "cube_method", "bake", "seam_step", "seam_step_max", "first_order_jump",
                    "environment_first_order_jump", "first_order_band", "environment_band_slope", "seam_step_half_lod", "ms",
                    "cube_bytes", "bake_ms", "edges_averaged", "border", "error", "edge_error"});
  expect_finite_numbers(out, "cube-metrics");
}

TEST(JobsCube, StopHookCancels) {
  const CubeMetricsJob job(kTinyCube);
  const Scene scene = scene_of(job.frame());
  EXPECT_THROW(job.run(seamcl_tests::shared_runtime(), scene, stop_at_once()), Cancelled);
}

const json kTinyDisplacement = {{"tessellation", "1,2"}, {"methods", "naive,fixed"}, {"size", "16x16"},
                                {"frames", 1},           {"repeat", 1}};

TEST(JobsDisplacement, BadInputNamesTheField) {
  EXPECT_EQ(refused_field([] { DisplacementMetricsJob(json{{"tessellation", "0"}}); }), "tessellation");
  EXPECT_EQ(refused_field([] { DisplacementMetricsJob(json{{"methods", "nope"}}); }), "methods");
  EXPECT_EQ(refused_field([] { DisplacementMetricsJob(json{{"frames", -1}}); }), "frames");
  EXPECT_EQ(refused_field([] { DisplacementMetricsJob(json{{"level", 17}}); }), "level");
  EXPECT_EQ(refused_field([] { DisplacementMetricsJob(json{{"msaa", 3}}); }), "msaa");
  // A scene without displacement maps is refused by the plan.
  const DisplacementMetricsJob job(json{{"scene", "quad2"}, {"frames", 0}});
  const Scene scene = scene_of(job.frame());
  EXPECT_EQ(refused_field([&] { (void)job.plan(scene); }), "scene");
}

TEST(JobsDisplacement, PlanAndTinyRun) {
  const DisplacementMetricsJob job(kTinyDisplacement);
  const Scene scene = scene_of(job.frame());
  expect_plan(job.plan(scene));
  const json out = job.run(seamcl_tests::shared_runtime(), scene, JobControl{});
  expect_keys(out, {"scene", "size", "msaa", "level", "crack_frames", "closed_mesh", "repeat", "device", "results"});
  ASSERT_EQ(out["results"].size(), 4u);
  for (const json& r : out["results"])
    expect_keys(r, {"method", "tessellation", "max_gap", "differing_pairs", "crack_pixels", "samples", "extra_bytes",
                    "tessellate_ms", "frame_ms"});
  expect_finite_numbers(out, "displacement-metrics");
}

TEST(JobsDisplacement, StopHookCancels) {
  const DisplacementMetricsJob job(kTinyDisplacement);
  const Scene scene = scene_of(job.frame());
  EXPECT_THROW(job.run(seamcl_tests::shared_runtime(), scene, stop_at_once()), Cancelled);
}

}  // namespace
