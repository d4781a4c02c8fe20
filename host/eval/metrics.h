// Image error metrics: how far a rendered frame is from a reference frame of the same size, as in
// the paper's Figure 5 (the fraction of pixels whose 2-norm distance in linear RGB is at least x),
// with summary numbers over the whole frame and over the pixels near texture seams.
//
// Definitions (the tests hold these exactly):
// - distance of a pixel: ||test.rgb - reference.rgb||_2 in linear RGB (alpha ignored);
// - a pixel is non-finite when any of its six rgb values (test or reference) is NaN or Inf; it is
//   counted in nan_pixels and left out of every other statistic;
// - mean: the arithmetic mean over the finite pixels; max: their largest distance;
// - p99: the nearest-rank 99th percentile, the ceil(0.99 n)-th smallest distance (1-based);
// - curve: for x_i = 10^(-4 + i/10), i = 0..40 (1e-4 .. 1, 41 steps, 10 per decade), the fraction
//   of the finite pixels with distance >= x_i;
// - seam mask (the default, footprint_seam_mask), from the shade stage itself
//   (kernels/shade_resolve.cl), per pixel: SEAMCL_MASK_SEAM (1) where some fragment's texture
//   footprint, at the rate, shading, filter and anisotropy rendered, crosses an edge shared by two
//   faces; SEAMCL_MASK_BOUNDARY (2) where footprints cross mesh boundary edges only (silhouette
//   rims, whose error is mostly geometry); SEAMCL_MASK_NONE (0) elsewhere, and there every seam
//   method returns the same colour. `seam` statistics are over the value 1, `off_seam` over 0:
//   errors over the seams are the methods' own, errors off them what all methods share
//   (silhouettes, filtering, the reference). A 0/1 mask (the boundary band) works the same way.
// - boundary band (seam_mask(FaceMap), the earlier mask, kept for bench's temporal measure):
//   pixels within Chebyshev distance kSeamRadius (2, i.e. a 5x5 square) of a pixel that has a
//   4-neighbour covered by a *different face*, or whose samples mix faces (FaceMap::mixed).
//   Face-to-background edges (silhouettes) are not seams there.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

class Renderer;

inline constexpr int kCurveSteps = 41;
inline constexpr int kSeamRadius = 2;

// The curve's x values: 10^(-4 + i/10), i = 0..kCurveSteps-1.
std::vector<double> error_curve_thresholds();

// The face visible at each pixel (-1 for background) of a frame at its own resolution.
struct FaceMap {
  int width = 0;
  int height = 0;
  std::vector<int32_t> face;    // row-major, row 0 at the top
  std::vector<uint8_t> mixed;   // 1 where the pixel's samples cover more than one face; empty = none
};

// From the raster stage's winners (slot per sample, SEAMCL_NO_TRIANGLE for none) and the setups
// (setups[slot].face). With one sample per pixel the face is the one at the pixel centre; with
// more, the face of the first covered sample, and `mixed` marks pixels whose samples differ
// (background counts as a face of its own there).
FaceMap face_map_from_winners(const std::vector<uint32_t>& winners, const std::vector<uint32_t>& slot_faces, int width,
                              int height, int samples);

// Renders `options` (scene already loaded) with 1 sample per pixel and reads the winners: the
// face id map of that frame at its own size.
FaceMap render_face_map(Renderer& renderer, const Camera& camera, RenderOptions options);

// The boundary band (see above): 1 for the pixels near a face boundary, 0 elsewhere.
std::vector<uint8_t> seam_mask(const FaceMap& faces, int radius = kSeamRadius);

// The footprint seam mask of a frame (see above): `options` rendered with the seam mask output.
// The mask does not depend on the seam method, so it is rendered with black (border-addressed,
// without guard bands) whatever options.method says; the rate, shading, filter and anisotropy are
// the options'.
std::vector<uint8_t> footprint_seam_mask(Renderer& renderer, const Camera& camera, RenderOptions options);

// Which of the two masks above a measurement uses: `footprint` (footprint_seam_mask, per rate;
// compare's) or `band` (seam_mask of the frame's face map, one for every rate).
enum class SeamMaskKind { Footprint, Band };
std::optional<SeamMaskKind> parse_seam_mask_kind(std::string_view name);
std::string to_string(SeamMaskKind kind);
std::vector<std::string> seam_mask_kind_names();

// The seam pixels of a mask as 0/1: footprint_seam_mask's value 1 (SEAMCL_MASK_SEAM) only.
std::vector<uint8_t> seam_pixels_only(const std::vector<uint8_t>& mask);
// The pixels off every edge as 0/1: the mask's value 0 (SEAMCL_MASK_NONE).
std::vector<uint8_t> off_seam_pixels_only(const std::vector<uint8_t>& mask);
// A mask drawn for viewing and for tools that read it back (examples/accuracy_study.py): seam
// pixels white, mesh-boundary rims grey (0.2 linear), the rest black. Opaque linear RGBA.
std::vector<glm::vec4> seam_mask_image(const std::vector<uint8_t>& mask);

struct ErrorStats {
  size_t pixels = 0;  // finite pixels counted (inside the mask, if any)
  double mean = 0;
  double p99 = 0;
  double max = 0;
  std::vector<double> curve;  // fraction of `pixels` with distance >= error_curve_thresholds()[i]
};

struct ImageErrors {
  ErrorStats all;
  ErrorStats seam;            // over the seam pixels (mask 1; all zero and pixels = 0 without a mask)
  ErrorStats off_seam;        // over the pixels off every edge (mask 0; equal to `all` without a mask)
  double seam_coverage = 0;   // seam pixels / all pixels (0 without a mask)
  size_t nan_pixels = 0;      // non-finite pixels, whole frame
  size_t seam_nan_pixels = 0; // non-finite pixels inside the seam mask
  std::vector<float> distance;  // per pixel; NaN where non-finite
};

// Per-pixel distances; NaN for non-finite pixels. Sizes must match (std::invalid_argument).
std::vector<float> pixel_distances(const std::vector<glm::vec4>& test, const std::vector<glm::vec4>& reference);

// Statistics over the finite distances, restricted to mask[i] != 0 when `mask` is given.
ErrorStats error_stats(const std::vector<float>& distance, const std::vector<uint8_t>* mask = nullptr);

// Everything above in one call; `mask` (optional) is a seam mask of the same size.
ImageErrors compare_images(const std::vector<glm::vec4>& test, const std::vector<glm::vec4>& reference,
                           const std::vector<uint8_t>* mask = nullptr);

// A heat map of the distances for viewing: log10 scale from 1e-4 (black) through blue, red and
// yellow to 1 and above (white); exactly 0 is black, non-finite pixels magenta. Opaque linear RGBA.
std::vector<glm::vec4> error_heatmap(const std::vector<float>& distance);

}  // namespace seamcl
