// The environment a scene's reflective faces and skybox show: an analytic function of direction
// (a sun-like spot, a sharp horizon line, a coloured sky gradient) that the cube maps are baked
// from and the metrics integrate exactly, or a constant.
#pragma once
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

namespace seamcl {

// Linear RGBA of a unit direction.
using DirectionFunction = std::function<glm::vec4(glm::vec3)>;

struct AnalyticEnvironment {
  // On the +X/+Z cube edge, above the horizon: the sharpest smooth feature crosses a seam.
  glm::vec3 sun_direction = glm::normalize(glm::vec3(1.0f, 0.45f, 1.0f));
  float sun_radius = 0.1f;                 // radians: the spot's Gaussian width
  glm::vec3 sun_color{1.0f, 0.85f, 0.55f};
  glm::vec3 zenith{0.08f, 0.22f, 0.65f};
  glm::vec3 horizon{0.65f, 0.72f, 0.85f};  // the sky just above the horizon line
  glm::vec3 ground{0.30f, 0.24f, 0.16f};   // below it: a sharp step at y = 0
};

// Linear RGB in [0, 1], alpha 1, of unit direction d.
glm::vec4 environment_radiance(const AnalyticEnvironment& environment, glm::vec3 d);

// How an environment image file maps to directions. Equirect: a width = 2 height longitude /
// latitude map, row 0 at +Y, the centre column towards -Z, +X at three quarters of the width
// (u = 1/2 + atan2(x, -z) / 2 pi, v = acos(y) / pi). Cross: a horizontal 4 x 3 cross
// (row 1: -X +Z +X -Z; +Y above and -Y below +Z) or a vertical 3 x 4 one (+Y; -X +Z +X; -Y; -Z
// below -Y, turned by 180 degrees), told apart by the aspect. Faces: six square images +X, -X,
// +Y, -Y, +Z, -Z. Every face (in a cross too) is in the orientation of cube_map.h: column i at
// s = (i + .5) / n, the image's top row at t = 0.
enum class EnvironmentLayout { Equirect, Cross, Faces };
std::optional<EnvironmentLayout> parse_environment_layout(std::string_view name);  // "equirect", ...
std::string to_string(EnvironmentLayout layout);
std::vector<std::string> environment_layout_names();

inline constexpr int kMaxEnvironmentImageSide = 16384;
// All texels of an environment's image(s): 8192 x 4096, 384 MB as float RGB.
inline constexpr size_t kMaxEnvironmentTexels = size_t(1) << 25;

// An environment image in linear RGB, looked up bilinearly by direction. Made by
// environment_image_from_pixels, so its sizes and texels have been checked.
struct EnvironmentImage {
  bool cube = false;           // false: an equirect map width x height; true: six faces
  int width = 0, height = 0;   // cube: each face is width x width (height = 6 width)
  std::vector<glm::vec3> texels;  // row-major, row 0 first; a cube's faces one after another
};

// The image files a scene names for its environment (JSON "file"/"layout" or "faces"), as
// written: host/assets resolves and reads them (load_environment_files) since host/scene reads
// no files.
struct EnvironmentFiles {
  EnvironmentLayout layout = EnvironmentLayout::Equirect;
  std::vector<std::string> names;  // one file, or six for Faces
  std::string field;               // the JSON path of the environment object, for errors
};

// Checks the sizes against the layout and the limits and arranges the texels: `images` holds one
// image (Equirect, Cross) or six (Faces), linear RGBA row 0 at the top, alpha ignored. Errors are
// InputError naming `fields[k]` (the file's JSON path) and saying what the layout needs; texels
// must be finite (InputError naming the file field and the texel).
struct DecodedImage {
  int width = 0, height = 0;
  std::vector<glm::vec4> pixels;
};
EnvironmentImage environment_image_from_pixels(EnvironmentLayout layout, const std::vector<DecodedImage>& images,
                                               const std::vector<std::string>& fields);

// Bilinear in the image: an equirect map wraps in longitude and clamps in latitude; a cube face
// clamps at its edges. Alpha 1.
glm::vec4 environment_image_radiance(const EnvironmentImage& image, glm::vec3 d);

struct Environment {
  AnalyticEnvironment analytic;
  std::optional<glm::vec3> constant;  // set: the environment is this colour everywhere
  std::optional<EnvironmentFiles> files;        // set: the environment is an image from these files
  std::shared_ptr<const EnvironmentImage> image;  // the files' pixels once read (shared: it is large)
  int cube_size = 64;                 // level-0 face size of the baked cube maps (cube_map.h)
  int bake_samples = 2;               // samples x samples per texel when baking (see bake_cube_map)
  bool skybox = true;                 // samples no triangle covers show the environment
};

// The environment as a function of (unit) direction: the image when there is one, else the
// constant, else the analytic function. Files named but not read (a scene that did not come
// through host/assets, such as an inline request) are InputError(files->field + ".file").
DirectionFunction environment_function(const Environment& environment);

// Checks cube_size, bake_samples and the analytic colours; throws InputError naming the field
// (environment.cube_size, ...).
void validate_environment(const Environment& environment);

}  // namespace seamcl
