// Ptex's own filters in the renderer (render --filter ptex-*): the Ptex variant of the shading
// kernel against its twin for every filter and seam rule, the pixels of a render against the
// device lookups `seamcl ptx lookup` makes for the same (face, u, v, uw, vw), no NaN on any sample,
// and the errors for a scene without a .ptx and for the methods Ptex's filters cannot take.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <memory>
#include <string>

#include <seamcl/assets/scene_source.h>
#include <seamcl/core/input_error.h>
#include <seamcl/jobs/render_job.h>
#include <seamcl/ptexfilter/ptex_lookup.h>

#include "pipeline/stages/ptex_filter_twin.h"
#include "pipeline/stages/shade_resolve_twin.h"
#include "ptex_test_writer.h"
#include "ptexfilter/ptex_filter_texture.h"
#include "test_support.h"

namespace seamcl {
namespace {

using nlohmann::json;
using seamcl_tests::ptex_assets_dir;
using seamcl_tests::shared_runtime;

std::string sample(const std::string& name) { return ptex_assets_dir() + "/" + name; }

struct PtexScene {
  Scene scene;
  std::shared_ptr<const PtexFilterData> data;
};

PtexScene ptex_scene(const std::string& mesh, const std::string& texture) {
  PtexScene out{load_scene_source(sample(mesh), sample(texture)), nullptr};
  out.data = std::make_shared<const PtexFilterData>(build_ptex_filter_data(read_ptex_stored(out.scene.ptex_file)));
  return out;
}

RenderOptions small(Filter filter, Method method, int msaa) {
  RenderOptions o;
  o.filter = filter;
  o.method = method;
  o.msaa = msaa;
  o.width = 64;
  o.height = 48;
  return o;
}

template <typename F>
std::string input_error_field(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.field();
  }
  return "(no InputError)";
}

// The kernel against its twin: every Ptex filter under every seam rule, at 1x and at 4x (pixel
// shading), on cube_text (rotated neighbours, valence-3 corners) and cellnoise (valence 3 to 9,
// neighbours of other resolutions, 3 channels).
TEST(PtexRender, ShadeKernelMatchesTwinForEveryFilterAndSeamRule) {
  for (const auto& [mesh, texture] : {std::pair{"cube.obj", "cube_text.ptx"}, std::pair{"ptex_test_object.obj", "cellnoise.ptx"}}) {
    const PtexScene s = ptex_scene(mesh, texture);
    Renderer renderer(shared_runtime());
    renderer.load_scene(s.scene);
    renderer.set_ptex_texture(s.data, s.scene.ptex_file);
    for (Filter filter : {Filter::PtexPoint, Filter::PtexBilinear, Filter::PtexBox, Filter::PtexGaussian,
                          Filter::PtexBicubic, Filter::PtexCatmullrom}) {
      for (Method method : {Method::Traverse, Method::Clamp, Method::Black, Method::Discard}) {
        for (int msaa : {1, 4}) {
          SCOPED_TRACE(std::string(texture) + " " + to_string(filter) + " " + to_string(method) + " msaa " +
                       std::to_string(msaa));
          const RenderResult result = renderer.render(s.scene.camera, small(filter, method, msaa));
          const PtexRenderTexture ptex{s.data.get(), renderer.ptex_shading()};
          EXPECT_EQ(ptex.shading.texture.seams, ptex_seam_rule(method));
          const ResolveReference twin =
              shade_resolve_reference(renderer.packed_scene(), renderer.last_frame_params(), renderer.read_setups(),
                                      renderer.read_sample_triangles(), nullptr, &ptex);
          ASSERT_EQ(twin.pixels.size(), result.pixels.size());
          float worst = 0.0f;
          int lit = 0, apart = 0;
          for (size_t i = 0; i < twin.pixels.size(); ++i) {
            const float d = glm::length(twin.pixels[i] - result.pixels[i]);
            worst = std::max(worst, d);
            apart += d > 2e-5f;
            lit += result.pixels[i].x > 0.05f;
          }
          // The device's uv may differ from the host's in the last bit (contracted multiply-adds),
          // which moves a bilinear tap's weight by up to 512 texels per unit times that; the
          // gaussian's exp differs by a few ulps. A width at a power of two can pick another level.
          EXPECT_LE(apart, static_cast<int>(twin.pixels.size() / 200)) << "worst " << worst;
          EXPECT_LT(worst, 0.05f);
          EXPECT_GT(lit, 100) << "the mesh covers part of the frame (cellnoise's object: about 180 of 3072 pixels)";
          EXPECT_EQ(twin.fragments, result.stats.fragments);
        }
      }
    }
  }
}

// At msaa 1 with pixel shading every covered pixel is one fragment shaded at its centre: its colour
// is the device lookup of `seamcl ptx lookup` (PtexFilterFile::lookup_device) at that point with
// uw = |du/dx| + |du/dy|, vw = |dv/dx| + |dv/dy|, times the light colour and the face's Lambert
// term. Traverse is the Ptex library's own rule, so this is the library's value.
TEST(PtexRender, PixelsAreTheDeviceLookupsOfPtxLookupTimesTheLighting) {
  const PtexScene s = ptex_scene("cube.obj", "cube_text.ptx");
  Renderer renderer(shared_runtime());
  renderer.load_scene(s.scene);
  renderer.set_ptex_texture(s.data, s.scene.ptex_file);
  for (Filter filter : {Filter::PtexBilinear, Filter::PtexGaussian}) {
    SCOPED_TRACE(to_string(filter));
    RenderOptions options = small(filter, Method::Traverse, 1);
    options.width = 96;
    options.height = 80;
    const RenderResult result = renderer.render(s.scene.camera, options);
    const FrameParams frame = renderer.last_frame_params();
    const std::vector<TriangleSetup> setups = renderer.read_setups();
    const std::vector<uint32_t> winners = renderer.read_sample_triangles();
    std::vector<PtexLookup> lookups;
    std::vector<size_t> pixel;
    std::vector<float> lighting;
    for (int y = 0; y < options.height; ++y) {
      for (int x = 0; x < options.width; ++x) {
        const size_t i = static_cast<size_t>(y) * options.width + x;
        if (winners[i] == SEAMCL_NO_TRIANGLE) continue;
        const TriangleSetup& t = setups.at(winners[i]);
        const SurfaceUv uv = interpolate_uv(t, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
        PtexLookup l;
        l.face = static_cast<int>(t.face);
        l.u = uv.u;
        l.v = uv.v;
        l.uw = std::fabs(uv.dudx) + std::fabs(uv.dudy);
        l.vw = std::fabs(uv.dvdx) + std::fabs(uv.dvdy);
        l.filter = to_string(filter);
        lookups.push_back(l);
        pixel.push_back(i);
        const FaceGpu& face = renderer.packed_scene().faces.at(t.face);
        const float n_dot_l =
            face.normal[0] * frame.light_dir[0] + face.normal[1] * frame.light_dir[1] + face.normal[2] * frame.light_dir[2];
        lighting.push_back(frame.ambient + (1.0f - frame.ambient) * std::fmax(n_dot_l, 0.0f));
      }
    }
    ASSERT_GT(lookups.size(), 1000u);
    const PtexFilterFile file(s.scene.ptex_file);
    const std::vector<std::vector<float>> values = file.lookup_device(shared_runtime(), lookups);
    float worst = 0.0f, lo = 1.0f, hi = 0.0f;
    int near_edge = 0, apart = 0;
    for (size_t k = 0; k < lookups.size(); ++k) {
      const glm::vec4& p = result.pixels[pixel[k]];
      const float grey = values[k][0];  // one channel: grey
      lo = std::min(lo, grey);
      hi = std::max(hi, grey);
      float d = 0.0f;
      for (int c = 0; c < 3; ++c) d = std::max(d, std::fabs(p[c] - grey * frame.light_color[c] * lighting[k]));
      worst = std::max(worst, d);
      apart += d > 2e-5f;
      const PtexLookup& l = lookups[k];
      near_edge += std::min({l.u, l.v, 1.0f - l.u, 1.0f - l.v}) < std::max(l.uw, l.vw);
    }
    // uv here is the host's (interpolate_uv), which may differ from the device's in the last bit.
    EXPECT_LE(apart, static_cast<int>(lookups.size() / 200)) << "worst " << worst;
    EXPECT_LT(worst, 0.05f);
    EXPECT_GT(hi - lo, 0.1f) << "the text shows";
    EXPECT_GT(near_edge, 20) << "footprints that reach into neighbours are among them";
  }
}

// No NaN and nothing outside the texture's range, on every sample file, every Ptex filter and seam
// rule, at 8x with every shading mode; a frame of the orbit seen from the side too.
TEST(PtexRender, NoNanOnAnySampleFilterOrSeamRule) {
  for (const auto& [mesh, texture] :
       {std::pair{"cube.obj", "cube_text.ptx"}, std::pair{"ptex_test_object.obj", "cellnoise.ptx"},
        std::pair{"plane.obj", "rand_lo.ptx"}, std::pair{"plane.obj", "wave_lo.ptx"}}) {
    const PtexScene s = ptex_scene(mesh, texture);
    Renderer renderer(shared_runtime());
    renderer.load_scene(s.scene);
    renderer.set_ptex_texture(s.data, s.scene.ptex_file);
    for (const std::string& name : filter_names()) {
      const Filter filter = *parse_filter(name);
      if (!is_ptex_filter(filter)) continue;
      for (Method method : {Method::Traverse, Method::Clamp, Method::Black, Method::Discard}) {
        for (ShadingMode shading : {ShadingMode::Pixel, ShadingMode::Centroid, ShadingMode::Sample}) {
          RenderOptions options = small(filter, method, 8);
          options.shading = shading;
          options.width = options.height = 32;
          const RenderResult result = renderer.render(s.scene.camera, options);
          for (const glm::vec4& p : result.pixels) {
            ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
                << texture << " " << name << " " << to_string(method) << " " << to_string(shading);
            ASSERT_LE(std::max({p.x, p.y, p.z}), 1.5f) << texture << " " << name;
            ASSERT_GE(std::min({p.x, p.y, p.z}), -0.5f) << texture << " " << name << " (bicubic rings a little)";
          }
        }
      }
    }
  }
}

TEST(PtexRender, RefusesSceneWithoutPtexSeamMaskAndMethodsItCannotTake) {
  // Methods: refused when the job is made, naming "method".
  for (const char* method : {"traverse-edges", "guardband"}) {
    EXPECT_EQ(input_error_field([&] { RenderJob job(json{{"filter", "ptex-bilinear"}, {"method", method}}); }), "method")
        << method;
  }
  // A built-in scene has no .ptx: refused naming "filter".
  const Scene paper = load_scene_source("quad2");
  Renderer renderer(shared_runtime());
  renderer.load_scene(paper);
  const RenderJob job(json{{"scene", "quad2"}, {"filter", "ptex-gaussian"}, {"method", "traverse"}, {"size", "32x32"}});
  EXPECT_EQ(input_error_field([&] { job.run(shared_runtime(), renderer, paper, JobControl{}); }), "filter");
  try {
    renderer.render(paper.camera, job.options());
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(".ptx"), std::string::npos) << e.what();
  }
  // The seam mask reads the packed texture's footprints.
  const PtexScene s = ptex_scene("cube.obj", "cube_text.ptx");
  renderer.load_scene(s.scene);
  renderer.set_ptex_texture(s.data, s.scene.ptex_file);
  EXPECT_EQ(input_error_field([&] { renderer.render(s.scene.camera, small(Filter::PtexBox, Method::Black, 1), true); }),
            "filter");
  // Through the job, the .ptx is read for the filters and the render goes through.
  Renderer fresh(shared_runtime());
  fresh.load_scene(s.scene);
  const RenderJob cube(json{{"filter", "ptex-bilinear"}, {"method", "traverse"}, {"size", "32x32"}});
  const RenderRun run = cube.run(shared_runtime(), fresh, s.scene, JobControl{});
  EXPECT_EQ(fresh.ptex_texture_file(), s.scene.ptex_file);
  EXPECT_EQ(run.last.pixels.size(), 32u * 32u);
}

}  // namespace
}  // namespace seamcl
