// The option parser shared by the CLI and the HTTP service: defaults, accepted forms, and every
// refusal naming its field.
#include <gtest/gtest.h>

#include <seamcl/core/input_error.h>
#include <seamcl/options/render_options.h>

#include <tuple>

using nlohmann::json;
using namespace seamcl;

TEST(RenderOptions, DefaultsWhenEmpty) {
  const RenderOptions o = parse_render_options(json::object());
  EXPECT_EQ(o.scene, "paper");
  EXPECT_EQ(o.method, Method::Discard);
  EXPECT_EQ(o.filter, Filter::Aniso);
  EXPECT_EQ(o.zero_coverage, ZeroCoverage::Clamp);
  EXPECT_EQ(o.texels, TexelFormat::Rgba8);
  EXPECT_EQ(o.msaa, 1);
  EXPECT_EQ(o.aniso, 16);
  EXPECT_EQ(o.width, 480);
  EXPECT_EQ(o.height, 540);
  EXPECT_EQ(o.shading, ShadingMode::Pixel);
  EXPECT_FALSE(o.frame.has_value());
}

TEST(RenderOptions, ReadsEveryKey) {
  const RenderOptions o = parse_render_options(json{{"scene", "quad2"}, {"method", "black"}, {"msaa", 8}, {"aniso", 4},
                                                    {"size", "64x32"}, {"centroid", true}, {"frame", 3}, {"frames", 10},
                                                    {"filter", "ewa"}, {"zero_coverage", "nan"}, {"texels", "rgba32f"}});
  EXPECT_EQ(o.scene, "quad2");
  EXPECT_EQ(o.method, Method::Black);
  EXPECT_EQ(o.filter, Filter::Ewa);
  EXPECT_EQ(o.zero_coverage, ZeroCoverage::Nan);
  EXPECT_EQ(o.texels, TexelFormat::Rgba32f);
  EXPECT_EQ(o.msaa, 8);
  EXPECT_EQ(o.aniso, 4);
  EXPECT_EQ(o.width, 64);
  EXPECT_EQ(o.height, 32);
  EXPECT_EQ(o.shading, ShadingMode::Centroid);
  EXPECT_EQ(o.frame, 3);
  EXPECT_EQ(o.frames, 10);
  // Round trip through to_json gives the same options.
  const RenderOptions again = parse_render_options(to_json(o));
  EXPECT_EQ(to_json(again), to_json(o));
}

TEST(RenderOptions, EnumNamesRoundTrip) {
  for (const std::string& name : method_names()) EXPECT_EQ(to_string(*parse_method(name)), name);
  for (const std::string& name : shading_mode_names()) EXPECT_EQ(to_string(*parse_shading_mode(name)), name);
  for (const std::string& name : filter_names()) EXPECT_EQ(to_string(*parse_filter(name)), name);
  for (const std::string& name : zero_coverage_names()) EXPECT_EQ(to_string(*parse_zero_coverage(name)), name);
  for (const std::string& name : texel_format_names()) EXPECT_EQ(to_string(*parse_texel_format(name)), name);
  EXPECT_EQ(method_names(),
            (std::vector<std::string>{"clamp", "black", "discard", "traverse", "traverse-edges", "guardband"}));
  EXPECT_EQ(filter_names(),
            (std::vector<std::string>{"bilinear", "trilinear", "aniso", "ewa", "ptex-point", "ptex-bilinear", "ptex-box",
                                      "ptex-gaussian", "ptex-bicubic", "ptex-bspline", "ptex-catmullrom", "ptex-mitchell"}));
  EXPECT_FALSE(parse_method("Clamp").has_value());
  EXPECT_FALSE(parse_shading_mode("").has_value());
}

// Every ptex-* filter of the render options is a filter `seamcl ptx lookup` takes by the same name,
// with the same filter code and sharpness; the patch filters are not Ptex's.
TEST(RenderOptions, PtexFiltersAreTheLookupsFiltersByName) {
  int ptex = 0;
  for (const std::string& name : filter_names()) {
    const Filter filter = *parse_filter(name);
    EXPECT_EQ(is_ptex_filter(filter), name.rfind("ptex-", 0) == 0) << name;
    if (!is_ptex_filter(filter)) continue;
    ++ptex;
    float sharpness = -1.0f;
    const int code = ptex_filter_code(filter, sharpness);
    EXPECT_EQ(sampler_params(Method::Traverse, filter, 16, ZeroCoverage::Clamp).filter, SEAMCL_FILTER_PTEX) << name;
    if (name == "ptex-catmullrom") EXPECT_EQ(sharpness, 1.0f);
    if (name == "ptex-mitchell") EXPECT_FLOAT_EQ(sharpness, 2.0f / 3.0f);
    if (name == "ptex-bicubic" || name == "ptex-bspline") EXPECT_EQ(sharpness, 0.0f);
    EXPECT_EQ(code, name == "ptex-point" ? SEAMCL_PTEX_POINT
                    : name == "ptex-bilinear" ? SEAMCL_PTEX_BILINEAR
                    : name == "ptex-box" ? SEAMCL_PTEX_BOX
                    : name == "ptex-gaussian" ? SEAMCL_PTEX_GAUSSIAN
                                              : SEAMCL_PTEX_BICUBIC)
        << name;
  }
  EXPECT_EQ(ptex, 8);
  // One program variant for all of them, whatever the method (the seam rule is a run-time setting).
  const SamplerParams a = sampler_params(Method::Traverse, Filter::PtexBox, 16, ZeroCoverage::Nan);
  const SamplerParams b = sampler_params(Method::Clamp, Filter::PtexGaussian, 4, ZeroCoverage::Clamp);
  EXPECT_EQ(std::tie(a.address, a.renormalize, a.traverse, a.guard_band, a.zero_coverage),
            std::tie(b.address, b.renormalize, b.traverse, b.guard_band, b.zero_coverage));
  EXPECT_EQ(ptex_seam_rule(Method::Traverse), SEAMCL_PTEX_SEAMS_PTEX);
  EXPECT_EQ(ptex_seam_rule(Method::Discard), SEAMCL_PTEX_SEAMS_DISCARD);
  for (Method refused : {Method::TraverseEdges, Method::Guardband}) {
    try {
      ptex_seam_rule(refused);
      ADD_FAILURE() << to_string(refused) << " is taken";
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), "method");
      EXPECT_NE(std::string(e.what()).find(to_string(refused)), std::string::npos) << e.what();
    }
  }
}

struct BadOption {
  json request;
  std::string field;
  std::string message_part;
};

TEST(RenderOptions, MethodsAreSamplerSettings) {
  const SamplerParams clamp = sampler_params(Method::Clamp, Filter::Aniso, 16, ZeroCoverage::Clamp);
  EXPECT_EQ(clamp.address, SEAMCL_ADDRESS_CLAMP);
  EXPECT_EQ(clamp.renormalize, 0);
  const SamplerParams black = sampler_params(Method::Black, Filter::Trilinear, 4, ZeroCoverage::Clamp);
  EXPECT_EQ(black.address, SEAMCL_ADDRESS_BORDER);
  EXPECT_EQ(black.renormalize, 0);
  EXPECT_EQ(black.filter, SEAMCL_FILTER_TRILINEAR);
  const SamplerParams discard = sampler_params(Method::Discard, Filter::Ewa, 8, ZeroCoverage::Nan);
  EXPECT_EQ(discard.address, SEAMCL_ADDRESS_BORDER);
  EXPECT_EQ(discard.renormalize, 1);
  EXPECT_EQ(discard.filter, SEAMCL_FILTER_EWA);
  EXPECT_EQ(discard.max_aniso, 8);
  EXPECT_EQ(discard.zero_coverage, SEAMCL_ZERO_COVERAGE_NAN);
  EXPECT_EQ(discard.traverse, 0);
  const SamplerParams traverse = sampler_params(Method::Traverse, Filter::Aniso, 16, ZeroCoverage::Clamp);
  EXPECT_EQ(traverse.address, SEAMCL_ADDRESS_BORDER);
  EXPECT_EQ(traverse.renormalize, 1);
  EXPECT_EQ(traverse.traverse, SEAMCL_TRAVERSE_CORNERS);
  EXPECT_EQ(traverse.guard_band, 0);
  const SamplerParams edges = sampler_params(Method::TraverseEdges, Filter::Aniso, 16, ZeroCoverage::Clamp);
  EXPECT_EQ(edges.address, SEAMCL_ADDRESS_BORDER);
  EXPECT_EQ(edges.renormalize, 1);
  EXPECT_EQ(edges.traverse, SEAMCL_TRAVERSE_EDGES);
  EXPECT_TRUE(reads_adjacency(Method::Traverse) && reads_adjacency(Method::TraverseEdges));
  EXPECT_FALSE(reads_adjacency(Method::Discard) || reads_adjacency(Method::Guardband));
  const SamplerParams guardband = sampler_params(Method::Guardband, Filter::Aniso, 16, ZeroCoverage::Clamp, 3);
  EXPECT_EQ(guardband.address, SEAMCL_ADDRESS_CLAMP);
  EXPECT_EQ(guardband.renormalize, 0);
  EXPECT_EQ(guardband.guard_band, 3);
  EXPECT_EQ(parse_render_options(json{{"method", "guardband"}, {"guard_band", 2}}).guard_band, 2);
}

TEST(RenderOptions, RefusalsNameTheField) {
  const std::vector<BadOption> cases = {
      {{{"msaa", 3}}, "msaa", "1, 2, 4, 8 or 16"},
      {{{"msaa", 0}}, "msaa", "1, 2, 4, 8 or 16"},
      {{{"msaa", 32}}, "msaa", "1, 2, 4, 8 or 16"},
      {{{"msaa", "4"}}, "msaa", "integer"},
      {{{"msaa", 4.5}}, "msaa", "integer"},
      {{{"aniso", 17}}, "aniso", "1..16"},
      {{{"size", "0x0"}}, "size", "WIDTHxHEIGHT"},
      {{{"size", "480"}}, "size", "WIDTHxHEIGHT"},
      {{{"size", "-4x4"}}, "size", "WIDTHxHEIGHT"},
      {{{"size", "16385x4"}}, "size", "WIDTHxHEIGHT"},
      {{{"size", "4x4x"}}, "size", "WIDTHxHEIGHT"},
      {{{"size", 480}}, "size", "string"},
      {{{"size", "16384x16384"}, {"msaa", 16}}, "size", "exceeds"},
      {{{"method", "bogus"}}, "method", "unknown method 'bogus'"},
      {{{"method", 1}}, "method", "string"},
      {{{"shading", "quad"}}, "shading", "unknown shading mode"},
      {{{"centroid", "yes"}}, "centroid", "true or false"},
      {{{"shading", "sample"}, {"centroid", true}}, "centroid", "cannot be combined"},
      {{{"frame", 5}, {"frames", 5}}, "frame", "less than frames"},
      {{{"frame", -1}}, "frame", "0.."},
      {{{"frames", 0}}, "frames", "1.."},
      {{{"scene", ""}}, "scene", "empty"},
      {{{"colour", "red"}}, "colour", "unknown option"},
      {{{"filter", "box"}}, "filter", "unknown filter 'box'"},
      {{{"zero_coverage", "zero"}}, "zero_coverage", "unknown zero_coverage mode"},
      {{{"texels", "rgba16"}}, "texels", "unknown texel format"},
      {{{"guard_band", 0}}, "guard_band", "1..16"},
      {{{"guard_band", 17}}, "guard_band", "1..16"},
  };
  for (const BadOption& c : cases) {
    try {
      parse_render_options(c.request);
      ADD_FAILURE() << "accepted " << c.request.dump();
    } catch (const InputError& e) {
      EXPECT_EQ(e.field(), c.field) << c.request.dump();
      EXPECT_NE(std::string(e.what()).find(c.message_part), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parse_render_options(json::array()), InputError);
}
