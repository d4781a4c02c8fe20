#include <seamcl/jobs/overlay_job.h>

#include <seamcl/core/cancelled.h>
#include <seamcl/core/input_error.h>

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

json OverlayJob::run(Renderer& renderer, const Scene& scene, const JobControl& control) const {
  throw_if_stopped(control.should_stop, "before the frame");
  const RenderResult frame = renderer.render(render_.camera(scene), render_.options(), true);
  throw_if_stopped(control.should_stop, "before the face edges");
  std::vector<uint8_t> flags =
      face_edge_pixels(renderer.last_frame_params(), renderer.read_setups(), renderer.read_sample_triangles());
  size_t seam = 0, boundary = 0, edges = 0;
  for (size_t p = 0; p < flags.size(); ++p) {
    edges += flags[p] != 0;
    const uint8_t m = frame.seam_mask.at(p);
    if (m == SEAMCL_MASK_SEAM) flags[p] |= kOverlaySeam, ++seam;
    if (m == SEAMCL_MASK_BOUNDARY) flags[p] |= kOverlayBoundary, ++boundary;
  }
  return {{"width", frame.width},
          {"height", frame.height},
          {"layers", {{"seam", kOverlaySeam}, {"boundary", kOverlayBoundary}, {"face_edge", kOverlayFaceEdge}}},
          {"counts", {{"seam", seam}, {"boundary", boundary}, {"face_edge", edges}}},
          {"pixels", base64(flags)}};
}

}  // namespace seamcl
