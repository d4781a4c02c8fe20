#include <seamcl/jobs/overlay_job.h>

#include <algorithm>

#include <seamcl/core/cancelled.h>
#include <seamcl/core/input_error.h>
#include <seamcl/eval/cube_metrics.h>
#include <seamcl/eval/displacement_metrics.h>
#include <seamcl/memory/render_memory.h>
#include <seamcl/pipeline/stage_stop.h>

namespace seamcl {
namespace {

using nlohmann::json;

std::string base64(const std::vector<uint8_t>& bytes) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t n = uint32_t{bytes[i]} << 16 | (i + 1 < bytes.size() ? uint32_t{bytes[i + 1]} << 8 : 0) |
                       (i + 2 < bytes.size() ? uint32_t{bytes[i + 2]} : 0);
    out += kDigits[(n >> 18) & 63];
    out += kDigits[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
  }
  return out;
}

}  // namespace

std::vector<uint8_t> face_edge_pixels(const FrameParams& frame, const std::vector<TriangleSetup>& setups,
                                      const std::vector<uint32_t>& sample_triangles) {
  const size_t pixels = static_cast<size_t>(frame.width) * frame.height;
  const int samples = frame.sample_count;
  std::vector<int64_t> face(pixels, -1);
  std::vector<uint8_t> out(pixels, 0);
  for (size_t p = 0; p < pixels; ++p) {
    for (int s = 0; s < samples; ++s) {
      const uint32_t slot = sample_triangles.at(p * samples + s);
      if (slot == SEAMCL_NO_TRIANGLE) continue;
      const int64_t f = setups.at(slot).face;
      if (face[p] < 0) face[p] = f;
      if (f != face[p]) out[p] = kOverlayFaceEdge;
    }
  }
  auto differ = [&](size_t a, size_t b) { return face[a] >= 0 && face[b] >= 0 && face[a] != face[b]; };
  for (int y = 0; y < frame.height; ++y) {
    for (int x = 0; x < frame.width; ++x) {
      const size_t p = static_cast<size_t>(y) * frame.width + x;
      if ((x + 1 < frame.width && differ(p, p + 1)) || (y + 1 < frame.height && differ(p, p + frame.width)))
        out[p] = kOverlayFaceEdge;
    }
  }
  return out;
}

OverlayJob::OverlayJob(const json& request) : render_(request) {
  for (const char* key : {"repeat", "crack_orbit", "export_mesh"})
    if (request.contains(key)) throw InputError(key, "is for renders; overlays are of one frame");
  if (render_.options().method == Method::Guardband)
    throw InputError("method", "the seam mask is measured on the faces' own texels; guardband's bands would count as "
                               "inside (any other method gives the same overlays)");
}

bool OverlayJob::crack_pixels_apply(const Scene& scene) const {
  return options().displacement && scene.displacement && is_closed_mesh(scene);
}

JobPlan OverlayJob::plan(const Scene& scene, size_t held_scene_bytes) const {
  JobPlan plan = render_.plan(scene, held_scene_bytes);
  if (!crack_pixels_apply(scene)) return plan;
  // The crack render's scene: (T+1)^2 vertices and 2 T^2 one-texel faces a patch.
  const auto t = static_cast<size_t>(std::max(options().tessellation, 1));
  SceneSizes flagged;
  flagged.vertices = scene.faces.size() * (t + 1) * (t + 1);
  flagged.faces.assign(2 * scene.faces.size() * t * t, {1, 1});
  const RenderOptions crack_options = crack_render_options(options());
  const RenderMemory cracks = render_memory(flagged, crack_options);
  plan.device.add(cracks.device_shares(frame_buffers_field(crack_options.msaa)));
  plan.host.add(cracks.host_shares());
  if (plan.unified.total() > 0) plan.unified.add(cracks.process_shares(frame_buffers_field(crack_options.msaa), true));
  return plan;
}

json OverlayJob::run(ClRuntime& runtime, Renderer& renderer, const Scene& scene, const JobControl& control) const {
  const StageStopScope stage_stop(control.should_stop);
  const Camera camera = render_.camera(scene);
  throw_if_stopped(control.should_stop, "before the frame");
  const RenderResult frame = renderer.render(camera, render_.options(), true);
  throw_if_stopped(control.should_stop, "before the face edges");
  std::vector<uint8_t> flags =
      face_edge_pixels(renderer.last_frame_params(), renderer.read_setups(), renderer.read_sample_triangles());
  size_t seam = 0, boundary = 0, edges = 0, cracks = 0, cube_edges = 0;
  for (size_t p = 0; p < flags.size(); ++p) {
    edges += flags[p] != 0;
    const uint8_t m = frame.seam_mask.at(p);
    if (m == SEAMCL_MASK_SEAM) flags[p] |= kOverlaySeam, ++seam;
    if (m == SEAMCL_MASK_BOUNDARY) flags[p] |= kOverlayBoundary, ++boundary;
  }
  if (cube_edges_apply(scene)) {
    throw_if_stopped(control.should_stop, "before the cube edges");
    const std::vector<uint8_t> crossed =
        cube_edge_pixels(lookup_directions(renderer, camera, options()), frame.width, frame.height);
    for (size_t p = 0; p < flags.size(); ++p)
      if (crossed.at(p)) flags[p] |= kOverlayCubeEdge, ++cube_edges;
  }
  if (crack_pixels_apply(scene)) {
    throw_if_stopped(control.should_stop, "before the crack pixels");
    const std::vector<uint8_t> open = frame_crack_pixels(runtime, scene, camera, options(), control.device_byte_limit);
    for (size_t p = 0; p < flags.size(); ++p)
      if (open.at(p)) flags[p] |= kOverlayCrack, ++cracks;
  }
  return {{"width", frame.width},
          {"height", frame.height},
          {"layers",
           {{"seam", kOverlaySeam},
            {"boundary", kOverlayBoundary},
            {"face_edge", kOverlayFaceEdge},
            {"crack", kOverlayCrack},
            {"cube_edge", kOverlayCubeEdge}}},
          {"counts",
           {{"seam", seam}, {"boundary", boundary}, {"face_edge", edges}, {"crack", cracks}, {"cube_edge", cube_edges}}},
          {"pixels", base64(flags)}};
}

}  // namespace seamcl
