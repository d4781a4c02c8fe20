// The options of one render, with their defaults, declared once in render_option_table() (key,
// type, bounds, default, help) and parsed from one JSON object by the same code for the CLI
// (which gathers its flags into such an object), the HTTP service and the Python module, so they
// all use the same names, value forms and error messages.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include <seamcl/kernels/seamcl_types.h>
#include <seamcl/options/displacement_method.h>
#include <seamcl/options/option_table.h>
#include <seamcl/options/texel_format.h>

namespace seamcl {

// How a lookup treats taps outside the face (the seam method):
//   clamp   - taps read the nearest edge texel (seams show);
//   black   - taps outside weigh zero, no renormalisation (Ptex's black border: edges darken);
//   discard - taps outside weigh zero and the rest are renormalised (Toth 2013);
//   traverse - discard, plus the same lookup on the four edge neighbours and, past a valence-4
//              corner, on the diagonal face, through their uv transforms, all summed and then
//              renormalised (McDonald 2013, with the corners of Ptex's filter);
//   traverse-edges - traverse without the corners: the edge neighbours only (the paper's
//              McDonald 2013, as Toth compares against);
//   guardband - clamp, on textures whose every level carries a band of guard_band texels
//               filled from the neighbours at build time (McDonald and Burley 2011).
enum class Method { Clamp, Black, Discard, Traverse, TraverseEdges, Guardband };
// The filter of one lookup: bilinear (level 0), trilinear, aniso (hardware-style probes), ewa; or
// one of Ptex's own filters (ptex-*, docs/ptex-filters.md), which read a .ptx scene's faces as the
// Ptex library does: ptex-point, ptex-bilinear, ptex-box, ptex-gaussian, ptex-bicubic (sharpness
// 0, as ptex-bspline), ptex-bspline, ptex-catmullrom (sharpness 1), ptex-mitchell (2/3).
enum class Filter {
  Bilinear,
  Trilinear,
  Aniso,
  Ewa,
  PtexPoint,
  PtexBilinear,
  PtexBox,
  PtexGaussian,
  PtexBicubic,
  PtexBspline,
  PtexCatmullrom,
  PtexMitchell
};
// Discard with every tap outside: a clamped lookup (the paper's fix) or the raw 0/0 (NaN).
enum class ZeroCoverage { Clamp, Nan };
// Where a fragment is shaded: the pixel centre, the centroid of its covered samples, or every
// sample (supersampling).
enum class ShadingMode { Pixel, Centroid, Sample };
// Displacement renders: the normal lighting reads, the displaced surface's at the micro-triangle's
// vertices interpolated (kernels/tessellate.cl's displaced_normals), or the patch's flat face normal.
enum class DisplacementNormals { Displaced, Face };
enum class ImageFormat { Png, Exr };
// How a cube-map lookup (reflective faces and the skybox of scenes with an environment) treats
// the cube's edges; a setting of its own, since patch methods and cube methods never meet in one
// lookup (see kernels/seamcl_types.h, SEAMCL_CUBE_*):
//   cube-clamp    - per-face clamp (the seams of D3D9 and old consoles);
//   cube-seamless - taps past an edge read the adjacent face, corners the mean of three texels;
//   cube-stretch  - faces baked with map_2 (edge texels on the cube edge), clamp;
//   cube-warp     - faces baked with the cubic warp of the texel centres, clamp;
//   cube-fixup    - stretch-baked faces, lookup coordinates scaled by 1 - exp2(lod)/n;
//   cube-discard  - taps outside the face weigh zero, the rest renormalised (Toth 2013 where its
//                   assumption, a geometric edge under the seam, fails);
//   cube-fixup-level - fixup with each trilinear level's own scale (m - 1) / m;
//   cube-fov      - faces baked with the post's FOV 2 atan(m / (m - 0.5)) per level, lookups scaled
//                   to match, clamp;
//   cube-average  - texel-centre faces whose edge texels are averaged across each edge and corner
//                   after the bake (CubeMapGen), clamp;
//   cube-border   - faces stored with a one-texel border of their neighbours' texels (the texture
//                   borders the post starts from): seamless within a texel of the edge.
enum class CubeMethod { Clamp, Seamless, Stretch, Warp, Fixup, Discard, FixupLevel, Fov, Average, Border };

std::optional<Method> parse_method(std::string_view name);
std::string to_string(Method method);
std::vector<std::string> method_names();
// Whether the method reads neighbouring faces through the adjacency (traverse, traverse-edges).
bool reads_adjacency(Method method);
// Whether the method needs the adjacency: the methods that read it, and guardband, whose bands are
// copied from the neighbours while packing (a Renderer keeps it only for those that read it, and
// for seam-mask renders: 48 bytes a face). A mesh without shared edges
// refuses them.
bool needs_adjacency(Method method);
std::optional<ShadingMode> parse_shading_mode(std::string_view name);
std::string to_string(ShadingMode mode);
std::vector<std::string> shading_mode_names();
std::optional<DisplacementNormals> parse_displacement_normals(std::string_view name);
std::string to_string(DisplacementNormals normals);
std::vector<std::string> displacement_normals_names();
std::optional<ImageFormat> parse_image_format(std::string_view name);
std::string to_string(ImageFormat format);
std::optional<Filter> parse_filter(std::string_view name);
std::string to_string(Filter filter);
std::vector<std::string> filter_names();
// Whether the filter is one of Ptex's own (ptex-*).
bool is_ptex_filter(Filter filter);
// A Ptex filter's SEAMCL_PTEX_* and sharpness (bicubic's B-spline to Catmull-Rom blend).
int ptex_filter_code(Filter filter, float& sharpness);
// The rule a Ptex filter applies at face edges under `method` (SEAMCL_PTEX_SEAMS_*): traverse, the
// library's own (neighbours and corners); clamp, black and discard, every face edge a boundary of
// that rule. InputError("method") for traverse-edges (Ptex's filter always takes the corners) and
// guardband (its bands belong to the packed texture, which Ptex filters do not read).
int ptex_seam_rule(Method method);
std::optional<ZeroCoverage> parse_zero_coverage(std::string_view name);
std::string to_string(ZeroCoverage mode);
std::vector<std::string> zero_coverage_names();
std::optional<TexelFormat> parse_texel_format(std::string_view name);
std::string to_string(TexelFormat format);
std::vector<std::string> texel_format_names();
std::optional<CubeMethod> parse_cube_method(std::string_view name);
std::string to_string(CubeMethod method);
std::vector<std::string> cube_method_names();

inline constexpr int kMaxImageSide = 16384;
inline constexpr long long kMaxSamplesPerImage = 1LL << 28;  // width * height * msaa
inline constexpr int kMaxDisplacementLevel = 16;              // displacement_level's bound
inline constexpr double kMinTessellationPixels = 0.25;        // tessellation_pixels' bounds
inline constexpr double kMaxTessellationPixels = 4096.0;
inline constexpr int kMaxFrames = 1000000;                    // frames' bound (an orbit of 1..kMaxFrames)
inline constexpr int kMaxBandTexels = 16;                     // guard_band's bound (kMaxGuardBand of packing)
inline constexpr float kMaxLodBias = 4.0f;                    // lod_bias's bound, either sign

struct RenderOptions {
  std::string scene = "paper";  // built-in name or scene file (.json, .obj mesh, .ptx with its mesh)
  std::string texture;          // a .ptx for an .obj scene; empty: none
  // A 1-channel .ptx whose faces displace the scene's (face i takes face i), replacing its own
  // maps; empty: the scene's own, if any. Needs `displacement`.
  std::string displacement_map;
  Method method = Method::Discard;
  Filter filter = Filter::Aniso;
  ZeroCoverage zero_coverage = ZeroCoverage::Clamp;
  TexelFormat texels = TexelFormat::Rgba8;
  int msaa = 1;                 // 1, 2, 4, 8 or 16 samples per pixel
  int aniso = 16;               // maximum anisotropy, 1..16 (aniso and ewa filters)
  int guard_band = 4;           // guardband: band texels per side, 1..kMaxGuardBand (16)
  int width = 480;
  int height = 540;
  ShadingMode shading = ShadingMode::Pixel;
  std::optional<int> frame;     // orbit frame, with `frames`
  int frames = 60;
  bool tint = false;            // built-in scenes: a base colour per face
  CubeMethod cube_method = CubeMethod::Seamless;  // scenes with an environment only
  // Displacement (docs/displacement.md): off unless a method is asked for; then every patch is
  // tessellated into a (T+1)^2 grid displaced by the scene's maps at displacement_level.
  std::optional<DisplacementMethod> displacement;
  int tessellation = 8;         // T, 1..64
  int displacement_level = 0;   // the maps' level sampled, 0..16
  // Absent: uniform, every edge at T. Given: screen-space adaptive factors, each patch edge's
  // from its projected length over this many pixels a segment, clamped to 1..T.
  std::optional<float> tessellation_pixels;
  DisplacementNormals displacement_normals = DisplacementNormals::Displaced;  // what lights the displaced surface
  float lod_bias = 0.0f;        // added to every lookup's mip level (-kMaxLodBias..kMaxLodBias)
};

// Every render option: its key, type, bounds, default (RenderOptions' own) and help. The parser
// below, to_json, the command line's flags, the methods document and the OpenAPI document all read
// it. `centroid` is an input alias of shading=centroid, never written.
const OptionTable& render_option_table();

// Reads the keys present in `request` over the defaults. Throws InputError naming the key on a
// wrong type, an out-of-range value or an unknown key (render_option_table's keys only), and on
// combinations that cannot be rendered (frame >= frames, centroid with shading=sample, more than
// kMaxSamplesPerImage samples).
RenderOptions parse_render_options(const nlohmann::json& request);
nlohmann::json to_json(const RenderOptions& options);

// The sampler settings a method stands for (see SamplerParams in kernels/seamcl_types.h).
// guard_band is used by Method::Guardband only (0 otherwise).
SamplerParams sampler_params(Method method, Filter filter, int max_aniso, ZeroCoverage zero_coverage,
                             int guard_band = 4, float lod_bias = 0.0f);
inline SamplerParams sampler_params(const RenderOptions& o) {
  return sampler_params(o.method, o.filter, o.aniso, o.zero_coverage, o.guard_band, o.lod_bias);
}

// "480x540" -> {480, 540}; throws InputError(field) unless both are integers in 1..kMaxImageSide.
std::pair<int, int> parse_size(const std::string& text, const std::string& field = "size");

}  // namespace seamcl
