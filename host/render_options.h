// The options of one render, with their defaults, parsed from one JSON object by the same code
// for the CLI (which gathers its flags into such an object) and the HTTP service, so the two use
// the same names, value forms and error messages.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

namespace seamcl {

// How a lookup treats taps outside the face. The sampler issue adds black, discard, traverse and
// guardband; until then every lookup is a trilinear one with clamp.
enum class Method { Clamp };
// Where a fragment is shaded: the pixel centre, the centroid of its covered samples, or every
// sample (supersampling).
enum class ShadingMode { Pixel, Centroid, Sample };
enum class ImageFormat { Png, Exr };

std::optional<Method> parse_method(std::string_view name);
std::string to_string(Method method);
std::vector<std::string> method_names();
std::optional<ShadingMode> parse_shading_mode(std::string_view name);
std::string to_string(ShadingMode mode);
std::vector<std::string> shading_mode_names();
std::optional<ImageFormat> parse_image_format(std::string_view name);
std::string to_string(ImageFormat format);

inline constexpr int kMaxImageSide = 16384;
inline constexpr long long kMaxSamplesPerImage = 1LL << 28;  // width * height * msaa

struct RenderOptions {
  std::string scene = "paper";  // built-in name or scene file
  Method method = Method::Clamp;
  int msaa = 1;                 // 1, 2, 4, 8 or 16 samples per pixel
  int aniso = 16;               // maximum anisotropy, 1..16 (used by the aniso filter)
  int width = 480;
  int height = 540;
  ShadingMode shading = ShadingMode::Pixel;
  std::optional<int> frame;     // orbit frame, with `frames`
  int frames = 60;
  bool tint = false;            // built-in scenes: a base colour per face
};

// Reads the keys present in `request` over the defaults. Throws InputError naming the key on a
// wrong type, an out-of-range value or an unknown key. Keys: scene, method, msaa, aniso,
// size ("WxH"), shading, centroid (bool, same as shading=centroid), frame, frames, tint.
RenderOptions parse_render_options(const nlohmann::json& request);
nlohmann::json to_json(const RenderOptions& options);

// "480x540" -> {480, 540}; throws InputError(field) unless both are integers in 1..kMaxImageSide.
std::pair<int, int> parse_size(const std::string& text, const std::string& field = "size");

}  // namespace seamcl
