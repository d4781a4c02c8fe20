// The paper's reference image (section 5): the same scene and camera rendered with the reference
// method at 8x the width and 8x the height, 1 sample per pixel, then downsampled by 8 with a
// Mitchell-Netravali filter, B = C = 1/3. Cached on disk as float EXR.
//
// The downsample is OpenImageIO's ImageBufAlgo::resize with filter "mitchell" at width 4 (in
// pixels of the *output* image). Checked in OIIO's source (src/libutil/filter.cpp,
// FilterMitchell1D::mitchell1d): B = C = 1/3 exactly, the classic formula evaluated on x rescaled
// so that the filter's full width maps to Mitchell's [-2, 2]. resize() (imagebufalgo_xform.cpp)
// takes the width in destination pixels and, when no width is given, uses the filter's default
// (4 for mitchell) times max(1, dst/src), i.e. 4 when shrinking: support radius 2 output pixels =
// 16 source pixels at 8x. The 2D filter is separable (product of the 1D ones), the weights are
// normalised to sum 1 and taps beyond the image edge read the edge pixel (clamp). We pass the
// width (4) explicitly; tests/test_metrics.cpp holds the result to a direct evaluation of the
// kernel and checks the installed library's default width.
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include <seamcl/cl/program_cache.h>
#include <seamcl/options/render_options.h>
#include <seamcl/pipeline/renderer.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

struct DownsampleTaps;

// The references an image can be measured against, each named in the results:
//   paper    - the reference method (traverse) at 8x width and height, 1 sample per pixel, then a
//              Mitchell-Netravali downsample (B = C = 1/3): the paper's;
//   box      - the same 8x render with a box downsample (the mean of each 8x8 block), as an MSAA
//              resolve filters (Mitchell rings at silhouettes);
//   analytic - the same 8x frame at 1 sample per pixel (its geometry and lighting), each of its
//              pixel centres (the subsamples) coloured by the function the textures were baked
//              from (Scene::albedo) at its surface point instead of any texture lookup, then the
//              Mitchell downsample: no seam method is favoured. Scenes without such a function
//              are refused;
//   seamless - for a planar grid of equal-resolution faces, which is one continuous texture:
//              the grid rendered as one face carrying the combined texture, at the measured
//              frame's own rate, filter and anisotropy. What a perfect seam method returns, so
//              any difference is the seam method's alone. Other scenes are refused.
enum class ReferenceKind { Paper, Box, Analytic, Seamless };
std::optional<ReferenceKind> parse_reference_kind(std::string_view name);
std::string to_string(ReferenceKind kind);
std::vector<std::string> reference_kind_names();
// "paper,box" -> kinds, in order, without repeats; InputError("reference") for an unknown name.
std::vector<ReferenceKind> parse_reference_kinds(const std::vector<std::string>& names);

inline constexpr int kReferenceScale = 8;             // 8x width and 8x height
inline constexpr float kMitchellWidth = 4.0f;         // full width in output pixels (radius 2)
inline constexpr double kMitchellB = 1.0 / 3.0;
inline constexpr double kMitchellC = 1.0 / 3.0;
inline constexpr long long kMaxReferencePixels = 1LL << 26;  // 8W x 8H; 64 Mpixel = 1 GiB of float RGBA

// The Mitchell-Netravali (1988) cubic, support |x| < 2, integral 1.
double mitchell_netravali(double x, double b = kMitchellB, double c = kMitchellC);

// The mean of each factor x factor block (width and height multiples of `factor`;
// std::invalid_argument otherwise).
std::vector<glm::vec4> downsample_box(const std::vector<glm::vec4>& pixels, int width, int height, int factor);

// Downsamples linear RGBA (width and height multiples of `factor`) by `factor` with OIIO's
// "mitchell" resize at kMitchellWidth output pixels. Throws std::invalid_argument on bad sizes and
// std::runtime_error if OIIO fails.
std::vector<glm::vec4> downsample_mitchell(const std::vector<glm::vec4>& pixels, int width, int height, int factor);

// "traverse" when parse_method accepts it, else "discard".
std::string default_reference_method();
// 1 sample per pixel for traverse (the paper's reference); 16 for the discard stand-in.
int default_reference_msaa(const std::string& method);

inline constexpr std::uintmax_t kDefaultReferenceCacheBytes = std::uintmax_t{256} << 20;  // 256 MiB

struct ReferenceSettings {
  ReferenceKind kind = ReferenceKind::Paper;  // paper or box here; analytic and seamless below
  std::string method;      // empty: default_reference_method()
  int msaa = 0;            // 0: default_reference_msaa(method)
  std::string cache_dir;   // empty: default_cache_dir()
  bool use_cache = true;
  // The cache's bound, applied after every write (trim_reference_cache): at most this many bytes
  // and this many entries. 0: unbounded. An entry is one zip float EXR of the compare's size.
  std::uintmax_t cache_max_bytes = kDefaultReferenceCacheBytes;
  size_t cache_max_entries = 0;
  // scene_content_hash of the scene the references are of, when the caller has it; trusted as
  // given, so it must be that scene's (a settings object reused for another scene must clear it). Hashing bakes
  // every face's texels, so a caller keying several references of one scene (bench's reference
  // frames, a request's key and its render) computes it once. Empty: computed for each key.
  std::string scene_hash;
};

// A hash of everything in a scene that a render reads: geometry, level-0 texels (a deferred
// face's are made to be hashed, one face at a time, so deferring does not change it), light and
// background. Costs one bake of every face.
std::string scene_content_hash(const Scene& scene);

// default_cache_dir() (host/cl/program_cache.h): $SEAMCL_CACHE_DIR, else $HOME/.cache/seamcl.

// InputError(field) when `dir` (empty: default_cache_dir()) exists and is not a directory: for a
// front end to refuse, as it starts, a cache that can never be written, instead of every
// reference being left uncached (a failed write is no error of a compare, so the jobs go on
// without it: a service's directory replaced after its start must not become a client's error).
void check_reference_cache_dir(const std::string& dir, const std::string& field);

// The options of the high-resolution render for a measured frame: the frame's options with the
// reference method and msaa, 8x the size, pixel shading. InputError("size", ...) when that is
// too large, InputError("reference_method"/"reference_msaa", ...) for bad settings.
RenderOptions reference_render_options(const RenderOptions& frame, const ReferenceSettings& settings);

// Everything the reference depends on, as one canonical JSON string: the scene's content hash
// (settings.scene_hash, else scene_content_hash(scene)), the camera, the reference render options
// (scene name, frame, frames, size, method, msaa, filter, aniso, texels, ...), the kernel
// sources, the scale and the downsample filter.
std::string reference_cache_key(const Scene& scene, const Camera& camera, const RenderOptions& frame,
                                const ReferenceSettings& settings);

struct ReferenceImage {
  int width = 0;
  int height = 0;
  std::vector<glm::vec4> pixels;  // linear RGBA at the frame's size
  ReferenceKind kind = ReferenceKind::Paper;
  std::string method;             // the reference method used
  int msaa = 1;                   // its samples per pixel at 8x
  bool from_cache = false;
  std::string cache_path;         // empty when not cached
  double render_ms = 0;           // wall time of the 8x render + downsample (0 from cache)
  double kernel_ms = 0;           // the device time in it: every stage, the downsample, the read-back
  bool shared = false;            // another request's render of the same reference, waited for
};

// Renders a high-resolution frame (the options come from reference_render_options); the host
// then downsamples it (downsample_mitchell or downsample_box).
using HighResRender = std::function<RenderResult(const RenderOptions&)>;

// The reference filters as taps of the device downsample (kernels/downsample.cl): Mitchell at
// kMitchellWidth output pixels (32 taps a side at 8x) and the box (8 taps of 1/8). The device's
// result stays within 5e-6 of downsample_mitchell / downsample_box relative to the image's largest
// value (OIIO sums the 2D filter in one pass, the device in two separable float passes;
// tests/test_downsample.cpp holds both to this).
DownsampleTaps mitchell_taps();
DownsampleTaps box_taps();

// The reference for `frame` of `scene` seen from `camera`. Requests for the same reference at
// the same time (the same key, reference_cache_key: scene content hash, camera, size and the
// rest of the reference render's options, reference method and rate, texels, scale, filter,
// kernel sources and version) make it once: the first renders, the others wait and get its
// image (shared = true), in this process. Keyed when the cache is used or settings.scene_hash is
// given (a key costs a hash of every face otherwise). With use_cache, a cache entry whose
// stored key matches is returned without calling `render` (and its last use set to now); a
// missing, unreadable or mismatched entry is rendered again and rewritten (atomically: temporary
// file and rename), then the cache is trimmed to the settings' bound. cache_path is empty when
// the entry was not kept (not writable, or alone over the bound).
ReferenceImage reference_image(const Scene& scene, const Camera& camera, const RenderOptions& frame,
                               const ReferenceSettings& settings, const HighResRender& render);

// What trim_reference_cache did.
struct CacheTrim {
  size_t kept_entries = 0;
  std::uintmax_t kept_bytes = 0;
  size_t removed_entries = 0;
  std::uintmax_t removed_bytes = 0;
};

// Bounds the reference files (reference-*.exr) in `dir`, least recently used first: an entry's
// last use is its modification time, which a cache hit sets to now. Keeps the most recently used
// entries while they fit in max_bytes and max_entries (0: no bound on that count) and removes the
// rest, also the newest one when it alone is over max_bytes. Leftover temporary files of writers
// that died (older than an hour) are removed; others' files are never touched. Errors (a file
// removed meanwhile, a missing directory) are ignored: the cache is an optimisation.
CacheTrim trim_reference_cache(const std::string& dir, std::uintmax_t max_bytes, size_t max_entries);

// The usual way: `renderer` (with `scene` loaded) renders `camera` at 8x and downsamples on the
// device (Renderer::render_downsampled: only the small image is read back), then releases its
// frame buffers (Renderer::release_frame_buffers): the 8x frame's are not kept.
ReferenceImage reference_image(Renderer& renderer, const Camera& camera, const RenderOptions& frame,
                               const ReferenceSettings& settings);

// The paper, box and analytic references of one frame from one 8x render (the analytic one
// evaluates Scene::albedo over that render's own fragments, so the three share their geometry
// exactly). Paper and box go through the cache as reference_image does; analytic is never
// cached. Throws InputError("reference") for seamless (see seamless_reference) and for analytic
// on a scene without an albedo function. The results come in the order of `kinds`.
std::vector<ReferenceImage> reference_images(Renderer& renderer, const Camera& camera, const RenderOptions& frame,
                                             const ReferenceSettings& settings, const std::vector<ReferenceKind>& kinds);

// The analytic image of a frame already rendered by `renderer` (its last render, 1 sample per
// pixel): per pixel, background where nothing is covered, else albedo(face, the surface point at
// the pixel centre) times the face's lighting. Exposed for the tests.
std::vector<glm::vec4> analytic_image(Renderer& renderer, const Scene& scene);

// The seamless reference's scene: `scene` when its faces form a planar grid (each face's right
// and upper neighbours share its edge's two vertices in the same orientation, the corners lie
// on a regular parallelogram lattice) of equal texture sizes whose combined size is a power of
// two per side; then one face over the grid's outline whose texture is the faces' level 0 side
// by side (its mip chain rebuilt: each level is the faces' same level side by side). Same
// camera, orbit, light and background. InputError("reference", why) for any other scene.
Scene seamless_scene(const Scene& scene);
// The level-0 width and height of seamless_scene(scene)'s one face, found from the grid alone,
// before any texel is copied: what a budget needs (seamless_scene_sizes, compare_memory.h).
// Refuses as seamless_scene does.
std::pair<int, int> seamless_texture_size(const Scene& scene);

// The seamless reference of one measured frame: `seamless` (a Renderer with seamless_scene
// loaded) renders `frame`'s options (rate, filter, anisotropy, shading, texels) with discard: on
// a single face, at the grid's outline, the same as traverse.
ReferenceImage seamless_reference(Renderer& seamless, const Camera& camera, const RenderOptions& frame);

// How a reference was made, as compare, bench and the HTTP service report it: method, msaa,
// scale, filter and its width, B, C, whether it came from the cache, ms; with_cache_path adds
// the file (the HTTP service leaves it out: clients never see server paths).
nlohmann::json reference_json(const ReferenceImage& reference, bool with_cache_path);

}  // namespace seamcl
