#include <seamcl/scene/scene_json.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <seamcl/core/json_document.h>
#include <string_view>
#include <variant>
#include <vector>

#include <seamcl/core/input_error.h>
#include <seamcl/core/regular_file.h>
#include <seamcl/scene/cube_map.h>

namespace seamcl {
namespace {

using nlohmann::json;

constexpr int kMaxTextureSide = 4096;
// Level-0 texels over all faces (a full scene then takes ~1.4 GB): a bound that keeps a small
// file from asking for more memory than the machine has.
constexpr size_t kMaxSceneTexels = size_t{1} << 26;

std::string member_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

std::string element_path(const std::string& parent, size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

std::string describe_type(const json& value) { return value.type_name(); }

template <typename Names>
std::string join(const Names& names) {
  std::string joined;
  for (const auto& name : names) joined += (joined.empty() ? "" : ", ") + std::string(name);
  return joined;
}

std::string known_generator_names() {
  std::vector<std::string> names;
  for (const GeneratorInfo& info : scene_generators()) names.push_back(info.name);
  return join(names);
}

bool is_generator_name(const std::string& name) {
  const auto& known = scene_generators();
  return std::any_of(known.begin(), known.end(),
                     [&](const GeneratorInfo& info) { return info.name == name; });
}

// The fields of one JSON object. Fields not named in `known` are rejected up front, so that a
// misspelt optional field is an error instead of a silently applied default.
class ObjectFields {
 public:
  ObjectFields(const json& value, std::string path, std::initializer_list<std::string_view> known)
      : value_(value), path_(std::move(path)) {
    if (!value.is_object())
      throw InputError(path_.empty() ? "scene" : path_,
                       "must be an object, got " + describe_type(value));
    for (const auto& [key, unused] : value.items()) {
      if (std::find(known.begin(), known.end(), key) == known.end())
        throw InputError(path_of(key), "unknown field (known: " + join(known) + ")");
    }
  }

  std::string path_of(std::string_view key) const { return member_path(path_, key); }

  const json* optional(std::string_view key) const {
    const auto it = value_.find(key);
    return it == value_.end() ? nullptr : &*it;
  }

  const json& required(std::string_view key) const {
    const json* field = optional(key);
    if (!field) throw InputError(path_of(key), "is required");
    return *field;
  }

 private:
  const json& value_;
  std::string path_;
};

float read_float(const json& value, const std::string& path) {
  if (!value.is_number()) throw InputError(path, "must be a number, got " + describe_type(value));
  const auto number = static_cast<float>(value.get<double>());
  if (!std::isfinite(number)) throw InputError(path, "must be a finite number (as a float)");
  return number;
}

int read_int(const json& value, const std::string& path, int min, int max) {
  if (!value.is_number_integer())
    throw InputError(path, "must be an integer, got " +
                               (value.is_number() ? value.dump() : describe_type(value)));
  // Checked first, so that the signed read below cannot wrap.
  const bool too_large =
      value.is_number_unsigned() && value.get<uint64_t>() > static_cast<uint64_t>(max);
  if (too_large || value.get<int64_t>() < min || value.get<int64_t>() > max)
    throw InputError(path, "must be in [" + std::to_string(min) + ", " + std::to_string(max) +
                               "], got " + value.dump());
  return static_cast<int>(value.get<int64_t>());
}

bool read_bool(const json& value, const std::string& path) {
  if (!value.is_boolean())
    throw InputError(path, "must be true or false, got " + describe_type(value));
  return value.get<bool>();
}

std::string read_string(const json& value, const std::string& path) {
  if (!value.is_string()) throw InputError(path, "must be a string, got " + describe_type(value));
  return value.get<std::string>();
}

const json& read_array(const json& value, const std::string& path) {
  if (!value.is_array()) throw InputError(path, "must be an array, got " + describe_type(value));
  return value;
}

glm::vec3 read_vec3(const json& value, const std::string& path) {
  if (!value.is_array() || value.size() != 3)
    throw InputError(path, "must be an array of 3 numbers, got " +
                               (value.is_array() ? std::to_string(value.size()) + " elements"
                                                 : describe_type(value)));
  return {read_float(value[0], element_path(path, 0)), read_float(value[1], element_path(path, 1)),
          read_float(value[2], element_path(path, 2))};
}

glm::vec3 read_color(const json& value, const std::string& path) {
  const glm::vec3 color = read_vec3(value, path);
  for (int c = 0; c < 3; ++c) {
    if (color[c] < 0.0f) throw InputError(element_path(path, static_cast<size_t>(c)), "must not be negative");
    if (color[c] > kMaxColorMagnitude) throw InputError(element_path(path, static_cast<size_t>(c)), "must be at most 1e9");
  }
  return color;
}

// The environment of reflective faces and the skybox (Environment, environment.h).
Environment read_environment(const json& value, const std::string& path) {
  const ObjectFields fields(value, path,
                            {"cube_size", "bake_samples", "skybox", "constant", "sun_direction", "sun_radius",
                             "sun_color", "zenith", "horizon", "ground", "file", "layout", "faces"});
  Environment e;
  // An image environment: the names only; host/assets reads the files (load_environment_files).
  const json* file = fields.optional("file");
  const json* layout = fields.optional("layout");
  const json* faces = fields.optional("faces");
  if (file && faces) throw InputError(fields.path_of("faces"), "cannot go with file (one image or six faces)");
  if (layout && !file) throw InputError(fields.path_of("layout"), "goes with file");
  if (file) {
    EnvironmentFiles files{EnvironmentLayout::Equirect, {read_string(*file, fields.path_of("file"))}, path};
    if (files.names[0].empty()) throw InputError(fields.path_of("file"), "must be a file name (a non-empty string)");
    if (layout) {
      const std::string name = read_string(*layout, fields.path_of("layout"));
      const std::optional<EnvironmentLayout> parsed = parse_environment_layout(name);
      if (!parsed || *parsed == EnvironmentLayout::Faces)
        throw InputError(fields.path_of("layout"), "unknown layout '" + name + "' (known: equirect, cross; six "
                                                   "face images go in \"faces\")");
      files.layout = *parsed;
    }
    e.files = std::move(files);
  }
  if (faces) {
    const json& names = read_array(*faces, fields.path_of("faces"));
    if (names.size() != 6)
      throw InputError(fields.path_of("faces"), "must name 6 files (+X, -X, +Y, -Y, +Z, -Z), got " +
                                                    std::to_string(names.size()));
    EnvironmentFiles files{EnvironmentLayout::Faces, {}, path};
    for (size_t k = 0; k < names.size(); ++k) {
      const std::string element = element_path(fields.path_of("faces"), k);
      files.names.push_back(read_string(names[k], element));
      if (files.names.back().empty()) throw InputError(element, "must be a file name (a non-empty string)");
    }
    e.files = std::move(files);
  }
  if (const json* v = fields.optional("cube_size")) e.cube_size = read_int(*v, fields.path_of("cube_size"), 1, kMaxCubeSize);
  if (const json* v = fields.optional("bake_samples")) e.bake_samples = read_int(*v, fields.path_of("bake_samples"), 1, 8);
  if (const json* v = fields.optional("skybox")) e.skybox = read_bool(*v, fields.path_of("skybox"));
  if (const json* v = fields.optional("constant")) e.constant = read_color(*v, fields.path_of("constant"));
  AnalyticEnvironment& a = e.analytic;
  const json* sun_direction = fields.optional("sun_direction");
  if (sun_direction) a.sun_direction = read_vec3(*sun_direction, fields.path_of("sun_direction"));
  if (const json* v = fields.optional("sun_radius")) a.sun_radius = read_float(*v, fields.path_of("sun_radius"));
  if (const json* v = fields.optional("sun_color")) a.sun_color = read_color(*v, fields.path_of("sun_color"));
  if (const json* v = fields.optional("zenith")) a.zenith = read_color(*v, fields.path_of("zenith"));
  if (const json* v = fields.optional("horizon")) a.horizon = read_color(*v, fields.path_of("horizon"));
  if (const json* v = fields.optional("ground")) a.ground = read_color(*v, fields.path_of("ground"));
  try {
    validate_environment(e);
  } catch (const InputError& error) {
    // validate_environment names "environment.FIELD"; here the field lives at `path`.
    const std::string prefix = "environment";
    const std::string sub = error.field().substr(std::min(error.field().size(), prefix.size()));
    throw InputError(path + sub, std::string(error.what()).substr(error.field().size() + 2));
  }
  // Only a given direction: the default is unit already, and normalising it again can move its last bit.
  if (sun_direction) a.sun_direction = glm::normalize(a.sun_direction);
  return e;
}

GeneratorOptions read_generator_options(const json& value, const std::string& path) {
  const ObjectFields fields(value, path,
                            {"tint", "constant_color", "content", "environment", "roughness", "faces", "texture_scale_log2"});
  GeneratorOptions options;
  if (const json* content = fields.optional("content")) {
    const std::string name = read_string(*content, fields.path_of("content"));
    options.content = parse_texture_content(name);
    if (!options.content) {
      std::string known;
      for (const std::string& n : texture_content_names()) known += (known.empty() ? "" : ", ") + n;
      throw InputError(fields.path_of("content"), "unknown content '" + name + "' (known: " + known + ")");
    }
  }
  if (const json* environment = fields.optional("environment"))
    options.environment = read_environment(*environment, fields.path_of("environment"));
  if (const json* roughness = fields.optional("roughness")) {
    const glm::vec3 r = read_vec3(*roughness, fields.path_of("roughness"));
    for (int k = 0; k < 3; ++k) {
      if (!(r[k] >= 0.0f && r[k] <= 4.0f))
        throw InputError(element_path(fields.path_of("roughness"), static_cast<size_t>(k)), "must be in 0..4");
    }
    options.roughness = r;
  }
  if (const json* tint = fields.optional("tint"))
    options.tint = read_bool(*tint, fields.path_of("tint"));
  if (const json* color = fields.optional("constant_color"))
    options.constant_color = read_color(*color, fields.path_of("constant_color"));
  // The ranges are checked against the generator's name (check_paper_scaling), which the caller knows.
  const int int_max = std::numeric_limits<int>::max(), int_min = std::numeric_limits<int>::min();
  if (const json* faces = fields.optional("faces")) options.faces = read_int(*faces, fields.path_of("faces"), int_min, int_max);
  if (const json* scale = fields.optional("texture_scale_log2"))
    options.texture_scale_log2 = read_int(*scale, fields.path_of("texture_scale_log2"), int_min, int_max);
  return options;
}

struct GeneratorRequest {
  std::string name;
  GeneratorOptions options;
};

GeneratorRequest read_generator_request(const json& doc) {
  const ObjectFields fields(doc, "", {"generator", "options"});
  GeneratorRequest request;
  request.name = read_string(fields.required("generator"), "generator");
  if (!is_generator_name(request.name))
    throw InputError("generator", "unknown generator '" + request.name +
                                      "' (known: " + known_generator_names() + ")");
  if (const json* options = fields.optional("options")) {
    request.options = read_generator_options(*options, "options");
    check_paper_scaling(request.name, request.options, "options");
  }
  return request;
}

// What a face's texture is painted with, kept until every face's corners are known.
struct TexturePlan {
  int width = 0;
  int height = 0;
  bool constant = false;
  glm::vec3 color{1.0f};
  std::string image;  // a file whose pixels are level 0 (its size is the texture's)
};

// Everything that makes one face's chain, apart from the scene: the same recipe bakes a face at
// once or, deferred, when it is packed, so both give the same texels.
struct FaceRecipe {
  TexturePlan plan;
  std::array<glm::vec3, 4> corners{};
  std::function<TextureLevel()> read_image;  // image faces: the loader's reader
  std::string field;                         // faces[f].texture
  size_t decode_bytes = 0;                   // image faces: what read_image holds beside level 0
};

MipChain make_face_chain(const FaceRecipe& recipe) {
  const TexturePlan& plan = recipe.plan;
  if (recipe.read_image) return build_mip_chain(recipe.read_image());
  const glm::vec4 color(plan.color, 1.0f);
  TextureLevel level0 =
      plan.constant ? TextureLevel{plan.width, plan.height,
                                   std::vector<glm::vec4>(static_cast<size_t>(plan.width) * plan.height, color)}
                    : bake_face_texture(recipe.corners, plan.width, plan.height,
                                        [&color](glm::vec3 p) { return surface_pattern(p) * color; });
  return build_mip_chain(std::move(level0));
}

TexturePlan read_texture(const json& value, const std::string& path) {
  const ObjectFields fields(value, path, {"width", "height", "content", "color", "image"});
  TexturePlan plan;
  if (const json* image = fields.optional("image")) {
    const std::string image_path = fields.path_of("image");
    plan.image = read_string(*image, image_path);
    if (plan.image.empty()) throw InputError(image_path, "must not be empty");
    for (std::string_view other : {"width", "height", "content", "color"})
      if (fields.optional(other))
        throw InputError(fields.path_of(other), "must not be given with image (the image gives the texture)");
    return plan;
  }
  auto read_side = [&fields](std::string_view side) {
    const std::string side_path = fields.path_of(side);
    const int size = read_int(fields.required(side), side_path, 1, kMaxTextureSide);
    if ((size & (size - 1)) != 0)
      throw InputError(side_path, "must be a power of two, got " + std::to_string(size));
    return size;
  };
  plan.width = read_side("width");
  plan.height = read_side("height");
  if (const json* content = fields.optional("content")) {
    const std::string kind = read_string(*content, fields.path_of("content"));
    if (kind != "surface" && kind != "constant")
      throw InputError(fields.path_of("content"),
                       "must be \"surface\" or \"constant\", got \"" + kind + "\"");
    plan.constant = kind == "constant";
  }
  if (const json* color = fields.optional("color"))
    plan.color = read_color(*color, fields.path_of("color"));
  return plan;
}

Camera read_camera(const json& value) {
  const ObjectFields fields(value, "camera", {"eye", "target", "up", "fov_y_degrees"});
  Camera camera;
  camera.eye = read_vec3(fields.required("eye"), "camera.eye");
  camera.target = read_vec3(fields.required("target"), "camera.target");
  if (const json* up = fields.optional("up")) camera.up = read_vec3(*up, "camera.up");
  if (const json* fov = fields.optional("fov_y_degrees"))
    camera.fov_y_degrees = read_float(*fov, "camera.fov_y_degrees");
  return camera;
}

Orbit read_orbit(const json& value) {
  const ObjectFields fields(value, "orbit", {"center", "radius", "height", "start_degrees"});
  Orbit orbit;
  orbit.center = read_vec3(fields.required("center"), "orbit.center");
  orbit.radius = read_float(fields.required("radius"), "orbit.radius");
  orbit.height = 0.0f;  // documented default: the eye circles level with the centre
  if (const json* height = fields.optional("height"))
    orbit.height = read_float(*height, "orbit.height");
  if (const json* start = fields.optional("start_degrees"))
    orbit.start_degrees = read_float(*start, "orbit.start_degrees");
  return orbit;
}

Light read_light(const json& value) {
  const ObjectFields fields(value, "light", {"to_light", "color", "ambient"});
  Light light;
  if (const json* to_light = fields.optional("to_light")) {
    const glm::vec3 direction = read_vec3(*to_light, "light.to_light");
    const float length = glm::length(direction);
    if (!(length > 0.0f) || !std::isfinite(length))
      throw InputError("light.to_light", "must be a non-zero vector");
    light.to_light = direction / length;
  }
  if (const json* color = fields.optional("color")) light.color = read_color(*color, "light.color");
  if (const json* ambient = fields.optional("ambient"))
    light.ambient = read_float(*ambient, "light.ambient");
  return light;
}

// defer: every face's texture is left to scene.texture_source (deferred_mip_chain), image faces
// sized from their headers.
Scene read_explicit_scene(const json& doc, const std::string& default_name, const FaceImageLoader& load_image,
                          bool defer) {
  const ObjectFields fields(
      doc, "", {"name", "positions", "faces", "camera", "orbit", "light", "background", "environment", "normals"});
  Scene scene;
  scene.name = default_name;
  if (const json* name = fields.optional("name")) scene.name = read_string(*name, "name");

  const json& positions = read_array(fields.required("positions"), "positions");
  for (size_t i = 0; i < positions.size(); ++i)
    scene.positions.push_back(read_vec3(positions[i], element_path("positions", i)));

  const json& faces = read_array(fields.required("faces"), "faces");
  if (faces.empty()) throw InputError("faces", "must have at least one face");
  std::vector<TexturePlan> plans;
  size_t total_texels = 0;
  for (size_t f = 0; f < faces.size(); ++f) {
    const std::string face_path = element_path("faces", f);
    const ObjectFields face_fields(faces[f], face_path, {"vertices", "texture", "roughness"});
    const std::string vertices_path = face_fields.path_of("vertices");
    const json& vertices = read_array(face_fields.required("vertices"), vertices_path);
    if (vertices.size() != 4)
      throw InputError(vertices_path,
                       "must have 4 vertex indices, got " + std::to_string(vertices.size()));
    Face face;
    for (size_t k = 0; k < 4; ++k) {
      const std::string index_path = element_path(vertices_path, k);
      const int index = read_int(vertices[k], index_path, 0, std::numeric_limits<int>::max());
      if (static_cast<size_t>(index) >= scene.positions.size())
        throw InputError(index_path, "index " + std::to_string(index) + " out of range (" +
                                         std::to_string(scene.positions.size()) + " positions)");
      face.vertices[k] = static_cast<uint32_t>(index);
    }
    if (const json* roughness = face_fields.optional("roughness")) {
      face.roughness = read_float(*roughness, face_fields.path_of("roughness"));
      if (!(face.roughness >= 0.0f && face.roughness <= 4.0f))
        throw InputError(face_fields.path_of("roughness"), "must be in 0..4");
    }
    const std::string texture_path = face_fields.path_of("texture");
    // A reflective face never reads its texture: it may leave it out (then 1 x 1).
    const json* texture = face.roughness >= 0.0f ? face_fields.optional("texture") : &face_fields.required("texture");
    plans.push_back(texture ? read_texture(*texture, texture_path) : TexturePlan{1, 1, true, glm::vec3(0.5f), {}});
    if (!plans.back().image.empty() && !load_image)
      throw InputError(texture_path + ".image", "image files cannot be read here (an inline scene names no files)");
    total_texels += static_cast<size_t>(plans.back().width) * plans.back().height;
    if (total_texels > kMaxSceneTexels)
      throw InputError(texture_path, "the scene's textures exceed " +
                                         std::to_string(kMaxSceneTexels) + " texels in all");
    scene.faces.push_back(std::move(face));
  }

  scene.camera = read_camera(fields.required("camera"));
  if (const json* orbit = fields.optional("orbit")) scene.orbit = read_orbit(*orbit);
  if (const json* light = fields.optional("light")) scene.light = read_light(*light);
  if (const json* background = fields.optional("background"))
    scene.background = read_color(*background, "background");
  if (const json* environment = fields.optional("environment"))
    scene.environment = read_environment(*environment, "environment");
  if (const json* normals = fields.optional("normals")) {
    const json& list = read_array(*normals, "normals");
    for (size_t i = 0; i < list.size(); ++i) {
      const glm::vec3 n = read_vec3(list[i], element_path("normals", i));
      if (!(glm::length(n) > 0.0f)) throw InputError(element_path("normals", i), "must not be zero");
      scene.normals.push_back(glm::normalize(n));
    }
  }

  // Textures last: baking is the expensive part, so a document is checked in full first. Image
  // faces are sized from their files' headers here; their pixels are read when baked.
  std::vector<FaceRecipe> recipes;
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    FaceRecipe recipe{plans[f], scene.corners(scene.faces[f]), {}, element_path("faces", f) + ".texture"};
    if (!recipe.plan.image.empty()) {
      const std::string image_path = recipe.field + ".image";
      FaceImage image = load_image(recipe.plan.image, image_path);
      recipe.plan.width = image.width;
      recipe.plan.height = image.height;
      recipe.read_image = std::move(image.read);
      recipe.decode_bytes = image.decode_bytes;
      total_texels += static_cast<size_t>(image.width) * static_cast<size_t>(image.height);
      if (total_texels > kMaxSceneTexels)
        throw InputError(image_path, "the scene's textures exceed " + std::to_string(kMaxSceneTexels) + " texels in all");
    }
    recipes.push_back(std::move(recipe));
  }
  if (defer) {
    for (size_t f = 0; f < scene.faces.size(); ++f)
      scene.faces[f].texture = deferred_mip_chain(recipes[f].plan.width, recipes[f].plan.height);
    if (std::any_of(recipes.begin(), recipes.end(), [](const FaceRecipe& r) { return r.decode_bytes > 0; }))
      for (const FaceRecipe& recipe : recipes) scene.texture_source_decode_bytes.push_back(recipe.decode_bytes);
    scene.texture_source = [recipes = std::make_shared<const std::vector<FaceRecipe>>(recipes)](size_t f) {
      const FaceRecipe& recipe = recipes->at(f);
      MipChain chain = make_face_chain(recipe);
      check_texel_magnitudes(chain, recipe.field);
      return chain;
    };
  } else {
    for (size_t f = 0; f < scene.faces.size(); ++f) scene.faces[f].texture = make_face_chain(recipes[f]);
  }
  // The same content as a function, for the analytic reference; none when an image paints a face
  // (its texels are the only statement of its content).
  const bool any_image = std::any_of(plans.begin(), plans.end(), [](const TexturePlan& p) { return !p.image.empty(); });
  std::vector<std::pair<bool, glm::vec4>> contents;
  for (const TexturePlan& plan : plans) contents.emplace_back(plan.constant, glm::vec4(plan.color, 1.0f));
  if (!any_image) {
    scene.albedo = [contents](size_t face, glm::vec3 p) {
      const auto& [constant, color] = contents[face];
      return constant ? color : surface_pattern(p) * color;
    };
  }
  validate_scene(scene);
  return scene;
}

using SceneSource = std::variant<GeneratorRequest, Scene>;

SceneSource read_document(const json& doc, const std::string& default_name, const FaceImageLoader& load_image,
                          bool defer) {
  // "options" without "generator" is the generator form missing its name, not an explicit scene.
  if (doc.is_object() && (doc.contains("generator") || doc.contains("options"))) return read_generator_request(doc);
  return read_explicit_scene(doc, default_name, load_image, defer);
}

Scene realize(SceneSource source, const GeneratorOptions& extra) {
  if (auto* request = std::get_if<GeneratorRequest>(&source)) {
    GeneratorOptions options = request->options;
    options.tint = options.tint || extra.tint;
    if (extra.constant_color) options.constant_color = extra.constant_color;
    if (extra.content) options.content = extra.content;
    options.defer_textures = options.defer_textures || extra.defer_textures;
    return generate_scene(request->name, options);
  }
  Scene scene = std::move(std::get<Scene>(source));
  apply_generator_options(scene, extra);
  return scene;
}

SceneSource read_scene_file(const std::string& path, const FaceImageLoader& load_image, bool defer) {
  RegularFile file(path);
  if (file.refusal() != RegularFile::Refusal::None)
    throw InputError("scene", "cannot read scene file '" + path + "': " + file.refusal_text());
  // Read whole and no further than the bound (the parsed document takes some 40 times the text),
  // so that neither a huge file nor one that fails mid-read reaches the parser.
  const auto too_large = [&] {
    return InputError("scene", "scene file '" + path + "' is larger than " + std::to_string(kMaxSceneFileBytes >> 20) + " MiB");
  };
  if (file.size() > kMaxSceneFileBytes) throw too_large();  // before any of it is read
  std::string text;
  if (!file.read_all(text, kMaxSceneFileBytes))
    throw InputError("scene", "cannot read scene file '" + path + "': a read failed: " + file.refusal_text());
  if (text.size() > kMaxSceneFileBytes) throw too_large();  // grown since it was opened
  json doc;
  try {
    doc = parse_json_document(text);
  } catch (const json::exception& error) {
    throw InputError("scene", "scene file '" + path + "' is not valid JSON: " + error.what());
  } catch (const std::invalid_argument& error) {
    throw InputError("scene", "scene file '" + path + "' is not valid JSON: " + error.what());
  }
  try {
    return read_document(doc, std::filesystem::path(path).stem().string(), load_image, defer);
  } catch (const InputError& error) {
    throw error_in_scene_file(error, path);
  }
}

// A scene file's scene: what its faces find wrong when they are made (packed, for a deferred one)
// names the file as what the parse found wrong does.
Scene realize_file(SceneSource source, const GeneratorOptions& extra, const std::string& path) {
  Scene scene = realize(std::move(source), extra);
  if (scene.texture_source) {
    scene.texture_source = [source = std::move(scene.texture_source), path](size_t f) {
      try {
        return source(f);
      } catch (const InputError& error) {
        throw error_in_scene_file(error, path);
      }
    };
  }
  return scene;
}

}  // namespace

Scene parse_scene_json(const nlohmann::json& doc, const FaceImageLoader& load_image, const GeneratorOptions& options) {
  Scene scene = realize(read_document(doc, "scene", load_image, options.defer_textures), options);
  // A document without a file behind it: nothing would read an environment's image files.
  if (scene.environment && scene.environment->files) {
    const EnvironmentFiles& files = *scene.environment->files;
    throw InputError(files.field + (files.layout == EnvironmentLayout::Faces ? ".faces" : ".file"),
                     "an inline scene can name no image file (use a scene file)");
  }
  return scene;
}

Scene load_scene_file(const std::string& path, const FaceImageLoader& load_image) {
  return realize_file(read_scene_file(path, load_image, false), {}, path);
}

Scene load_scene(const std::string& name_or_path, const GeneratorOptions& options, const FaceImageLoader& load_image) {
  if (is_generator_name(name_or_path)) return generate_scene(name_or_path, options);
  std::error_code ignored;
  if (name_or_path.ends_with(".json") || std::filesystem::exists(name_or_path, ignored))
    return realize_file(read_scene_file(name_or_path, load_image, options.defer_textures), options, name_or_path);
  throw InputError("scene", "unknown scene '" + name_or_path + "' (known: " +
                                known_generator_names() + "; or the path of a .json scene file)");
}

InputError error_in_scene_file(const InputError& error, const std::string& path) {
  const std::string message = std::string(error.what()).substr(error.field().size() + 2);  // without "field: "
  return InputError(error.field(), message + " (in '" + path + "')");
}

bool is_builtin_scene(const std::string& name) { return is_generator_name(name); }

SceneViewFields parse_scene_view_fields(const nlohmann::json& doc) {
  SceneViewFields view;
  if (!doc.is_object()) return view;
  if (const auto camera = doc.find("camera"); camera != doc.end()) view.camera = read_camera(*camera);
  if (const auto orbit = doc.find("orbit"); orbit != doc.end()) view.orbit = read_orbit(*orbit);
  if (const auto light = doc.find("light"); light != doc.end()) view.light = read_light(*light);
  if (const auto background = doc.find("background"); background != doc.end())
    view.background = read_color(*background, "background");
  return view;
}

}  // namespace seamcl
