#include <seamcl/assets/ptex_displacement.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include <seamcl/core/input_error.h>
#include "scene/displacement_map.h"

namespace seamcl {

void attach_ptex_displacement(Scene& scene, const std::string& path, const PtexLimits& limits) {
  PtexFile file;
  try {
    file = read_ptex_file(path, limits);
  } catch (const InputError& e) {
    // The reader names its own field ("texture: ..."); the message without it, under this one.
    const std::string message = e.what();
    const std::string own = e.field() + ": ";
    throw InputError("displacement_map", message.starts_with(own) ? message.substr(own.size()) : message);
  }
  if (file.channels != 1) {
    throw InputError("displacement_map", path + ": a displacement map has 1 channel, this file has " + std::to_string(file.channels));
  }
  if (file.textures.size() != scene.faces.size()) {
    throw InputError("displacement_map", path + ": " + std::to_string(file.textures.size()) + " faces for a mesh of " +
                                             std::to_string(scene.faces.size()));
  }
  auto displacement = std::make_shared<Displacement>();
  displacement->source = path;
  for (const MipChain& chain : file.textures) {
    const TextureLevel& level = chain.levels.front();
    const int w = level.width, h = level.height;
    DisplacementMap map;
    map.columns = w + 1;
    map.rows = h + 1;
    map.samples.resize(static_cast<size_t>(map.columns) * map.rows);
    for (int b = 0; b <= h; ++b) {
      // Grid point b lies at v = b / h, texel coordinate b - 0.5 between centres, clamped.
      const float y = std::clamp(static_cast<float>(b) - 0.5f, 0.0f, static_cast<float>(h - 1));
      const int j0 = std::min(static_cast<int>(y), h - 1), j1 = std::min(j0 + 1, h - 1);
      const float fy = y - static_cast<float>(j0);
      for (int a = 0; a <= w; ++a) {
        const float x = std::clamp(static_cast<float>(a) - 0.5f, 0.0f, static_cast<float>(w - 1));
        const int i0 = std::min(static_cast<int>(x), w - 1), i1 = std::min(i0 + 1, w - 1);
        const float fx = x - static_cast<float>(i0);
        const float value = (1.0f - fy) * ((1.0f - fx) * level.at(i0, j0).r + fx * level.at(i1, j0).r) +
                            fy * ((1.0f - fx) * level.at(i0, j1).r + fx * level.at(i1, j1).r);
        map.at(a, b) = static_cast<uint16_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * 65535.0f));
      }
    }
    displacement->maps.push_back(std::move(map));
  }
  glm::vec3 low(0.0f), high(0.0f);
  if (!scene.positions.empty()) low = high = scene.positions.front();
  for (const glm::vec3& p : scene.positions) low = glm::min(low, p), high = glm::max(high, p);
  displacement->scale = 0.05f * glm::length(high - low);
  validate_displacement(*displacement, scene.faces.size());
  scene.displacement = displacement;
}

}  // namespace seamcl
