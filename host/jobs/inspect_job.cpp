#include <seamcl/jobs/inspect_job.h>

#include <algorithm>
#include <bit>

#include <seamcl/core/cancelled.h>
#include <seamcl/core/input_error.h>

namespace seamcl {
namespace {

using nlohmann::json;

const OptionTable& inspect_own_options() {
  static const OptionTable table = [] {
    OptionSpec x = make_option("x", OptionType::Integer, "Pixel column to inspect, 0 at the left (required)");
    x.minimum = 0;
    x.maximum = 16383;
    OptionSpec y = make_option("y", OptionType::Integer, "Pixel row to inspect, 0 at the top (required)");
    y.minimum = 0;
    y.maximum = 16383;
    OptionSpec window = make_option("window", OptionType::Integer,
                                    "Inspect window x window pixels from (x, y), cut at the image's edges");
    window.minimum = 1;
    window.maximum = 8;
    window.default_value = 1;
    return OptionTable{x, y, window};
  }();
  return table;
}

json render_request_of(const json& request) {
  if (!request.is_object()) throw InputError("request", "must be a JSON object");
  json rest = json::object();
  for (const auto& [key, value] : request.items())
    if (!find_option(inspect_own_options(), key)) rest[key] = value;
  return rest;
}

// Edge k of a face: v = 0, u = 1, v = 1, u = 0; corner k lies between edges k - 1 and k.
constexpr const char* kEdgeNames[4] = {"v=0", "u=1", "v=1", "u=0"};
constexpr const char* kCornerNames[4] = {"(0,0)", "(1,0)", "(1,1)", "(0,1)"};

}  // namespace

const OptionTable& inspect_job_option_table() { return inspect_own_options(); }

InspectJob::InspectJob(const json& request) : render_(render_request_of(request)) {
  for (const char* key : {"repeat", "crack_orbit", "export_mesh"})
    if (request.contains(key)) throw InputError(key, "is for renders; an inspection renders one frame");
  for (const OptionSpec& spec : inspect_own_options()) {
    if (!request.contains(spec.key)) {
      if (spec.default_value.is_null()) throw InputError(spec.key, "is required: the pixel to inspect");
      continue;
    }
    const int value = checked_option(spec, request.at(spec.key)).get<int>();
    (spec.key == "x" ? x_ : spec.key == "y" ? y_ : window_) = value;
  }
}

json InspectJob::sample_json(int sample, const InspectSample& r, bool renormalize) {
  json coverage = json::array();
  for (int s = 0; s < 32; ++s)
    if ((r.coverage >> s) & 1u) coverage.push_back(s);
  json out = {{"sample", sample}, {"coverage", coverage}};
  if (r.triangle == SEAMCL_NO_TRIANGLE) {
    out["triangle"] = nullptr;
    out["face"] = nullptr;
    out["color"] = {r.color[0], r.color[1], r.color[2]};
    return out;
  }
  out["triangle"] = r.triangle;
  out["face"] = r.face;
  out["point"] = {r.x, r.y};
  out["uv"] = {r.u, r.v};
  out["derivatives"] = {{"dudx", r.dudx}, {"dvdx", r.dvdx}, {"dudy", r.dudy}, {"dvdy", r.dvdy}};
  out["color"] = {r.color[0], r.color[1], r.color[2]};
  out["reflective"] = r.reflective != 0;
  if (r.reflective) return out;
  out["footprint"] = {{"axis_x", r.axis_x}, {"axis_y", r.axis_y}, {"probes", r.probes}};
  out["lod"] = r.lod;
  out["levels"] = r.level0 == r.level1 ? json::array({r.level0}) : json::array({r.level0, r.level1});
  // The faces the lookup's taps came from: its own, then the edge neighbours and diagonal faces
  // (those traverse reads weigh; the others are listed with weight 0 for orientation).
  float total = r.own_weight;
  for (int k = 0; k < 4; ++k) total += r.edge_weight[k] + r.corner_weight[k];
  auto share = [&](float weight) -> json {
    if (!renormalize) return weight;
    return total > 0.0f ? json(weight / total) : json(nullptr);
  };
  json taps = json::array();
  taps.push_back({{"face", r.face}, {"from", "own"}, {"weight", r.own_weight}, {"share", share(r.own_weight)}});
  for (int k = 0; k < 4; ++k) {
    if (r.edge_face[k] < 0) continue;
    taps.push_back({{"face", r.edge_face[k]}, {"from", "edge"}, {"edge", kEdgeNames[k]}, {"weight", r.edge_weight[k]},
                    {"share", share(r.edge_weight[k])}});
  }
  for (int k = 0; k < 4; ++k) {
    if (r.corner_face[k] < 0) continue;
    taps.push_back({{"face", r.corner_face[k]}, {"from", "diagonal"}, {"corner", kCornerNames[k]},
                    {"weight", r.corner_weight[k]}, {"share", share(r.corner_weight[k])}});
  }
  out["taps"] = taps;
  out["weight"] = total;
  return out;
}

json InspectJob::run(Renderer& renderer, const Scene& scene, const JobControl& control) const {
  const RenderOptions& options = render_.options();
  if (x_ >= options.width) throw InputError("x", "must be below the image's width " + std::to_string(options.width));
  if (y_ >= options.height) throw InputError("y", "must be below the image's height " + std::to_string(options.height));
  const int width = std::min(window_, options.width - x_);
  const int height = std::min(window_, options.height - y_);
  throw_if_stopped(control.should_stop, "before the frame");
  // Adjacency packed for every method (the seam mask reads it), so the faces around are named
  // even where the method reads none of them; guardband's bands leave it out.
  const bool with_adjacency = options.method != Method::Guardband;
  const RenderResult frame = renderer.render(render_.camera(scene), options, with_adjacency);
  throw_if_stopped(control.should_stop, "before the inspection");
  control.report("inspect " + std::to_string(width) + "x" + std::to_string(height) + " from (" + std::to_string(x_) + ", " +
                 std::to_string(y_) + ")");
  const std::vector<InspectSample> records = renderer.inspect_last_frame(x_, y_, width, height);
  const FrameParams params = renderer.last_frame_params();
  const bool renormalize = params.sampler.renormalize != 0;
  const int samples = params.sample_count;
  json pixels = json::array();
  for (int wy = 0; wy < height; ++wy) {
    for (int wx = 0; wx < width; ++wx) {
      const size_t first = (static_cast<size_t>(wy) * width + wx) * samples;
      json items = json::array();
      int fragments = 0;
      for (int s = 0; s < samples; ++s) {
        const InspectSample& r = records[first + s];
        items.push_back(sample_json(s, r, renormalize));
        // A fragment per distinct triangle (per sample with sample shading), as shading counts.
        const bool first_of_triangle = std::countr_zero(r.coverage) == s;
        if (r.triangle != SEAMCL_NO_TRIANGLE && (first_of_triangle || params.shading_mode == SEAMCL_SHADE_SAMPLE)) ++fragments;
      }
      const int x = x_ + wx, y = y_ + wy;
      const glm::vec4& c = frame.pixels.at(static_cast<size_t>(y) * options.width + x);
      json pixel = {{"x", x}, {"y", y}, {"color", {c.r, c.g, c.b}}, {"fragments", fragments}, {"samples", items}};
      if (!frame.seam_mask.empty()) {
        const uint8_t m = frame.seam_mask[static_cast<size_t>(y) * options.width + x];
        pixel["seam_mask"] = m == SEAMCL_MASK_SEAM ? "seam" : m == SEAMCL_MASK_BOUNDARY ? "boundary" : "none";
      }
      pixels.push_back(pixel);
    }
  }
  return {{"x", x_},
          {"y", y_},
          {"width", width},
          {"height", height},
          {"options", to_json(options)},
          {"samples", samples},
          {"shading", to_string(options.shading)},
          {"method", to_string(options.method)},
          {"filter", to_string(options.filter)},
          {"renormalize", renormalize},
          {"pixels", pixels}};
}

}  // namespace seamcl
