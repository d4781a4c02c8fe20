#include "displacement_test_scenes.h"

#include <array>
#include <cmath>
#include <memory>

#include <seamcl/assets/ptex_displacement.h>
#include <seamcl/assets/scene_source.h>
#include <seamcl/scene/scene_generators.h>
#include "pipeline/stages/tessellate_launcher.h"
#include "scene/displaced_scene.h"
#include "scene/displacement_map.h"
#include "test_support.h"

namespace seamcl_tests {

using namespace seamcl;

// A torus of rings x sides quads (major radius 1, minor 0.35, axis y), counter-clockwise from
// outside, with maps of different resolutions (1 to 16 intervals a side, non-square) baked face by face from displacement_pattern: the
// hole makes it non-star-shaped (no point inside sees all of it), and neighbours' maps disagree
// between shared corners, so naive cracks. Seen from an orbit above its plane, through the hole.
Scene make_torus(int rings, int sides) {
  Scene scene;
  scene.name = "torus";
  constexpr float kMajor = 1.0f, kMinor = 0.35f;
  constexpr float kTwoPi = 6.28318530718f;
  auto index = [&](int i, int j) { return static_cast<uint32_t>((i % rings) * sides + (j % sides)); };
  for (int i = 0; i < rings; ++i) {
    const float theta = kTwoPi * static_cast<float>(i) / static_cast<float>(rings);
    for (int j = 0; j < sides; ++j) {
      const float phi = kTwoPi * static_cast<float>(j) / static_cast<float>(sides);
      const float ring = kMajor + kMinor * std::cos(phi);
      scene.positions.emplace_back(ring * std::cos(theta), kMinor * std::sin(phi), ring * std::sin(theta));
    }
  }
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < sides; ++j) {
      std::array<uint32_t, 4> quad{index(i, j), index(i, j + 1), index(i + 1, j + 1), index(i + 1, j)};
      // Outward: away from the tube's centre line at this face.
      const float theta = kTwoPi * (static_cast<float>(i) + 0.5f) / static_cast<float>(rings);
      const glm::vec3 tube_centre(kMajor * std::cos(theta), 0.0f, kMajor * std::sin(theta));
      const glm::vec3 p0 = scene.positions[quad[0]], p1 = scene.positions[quad[1]], p2 = scene.positions[quad[2]];
      if (glm::dot(glm::cross(p1 - p0, p2 - p0), p0 - tube_centre) < 0.0f) std::swap(quad[1], quad[3]);
      scene.faces.push_back({quad, {}});
    }
  }
  TextureLevel grey;
  grey.width = grey.height = 1;
  grey.texels = {glm::vec4(0.7f, 0.7f, 0.7f, 1.0f)};
  const MipChain texture = build_mip_chain(grey);
  for (Face& f : scene.faces) f.texture = texture;
  auto displacement = std::make_shared<Displacement>();
  displacement->scale = 0.08f;
  displacement->source = "test torus";
  // Resolutions that nest (powers of two), so that fixed's edge matching applies everywhere.
  constexpr std::array<int, 5> kIntervals{1, 4, 8, 2, 16};
  for (size_t f = 0; f < scene.faces.size(); ++f) {
    const int nu = kIntervals[f % kIntervals.size()], nv = kIntervals[(f * 2 + 1) % kIntervals.size()];
    displacement->maps.push_back(
        bake_displacement_map(scene.corners(scene.faces[f]), nu + 1, nv + 1, [](glm::vec3 p) {
          return displacement_pattern(p * 1.7f);
        }));
  }
  scene.displacement = displacement;
  scene.orbit = Orbit{glm::vec3(0.0f), 2.6f, 2.2f, 15.0f};
  scene.camera.fov_y_degrees = 40.0f;
  scene.camera = orbit_camera(scene, 0, 1);
  return scene;
}

Scene cube_obj() {
  Scene scene = load_scene_source(kPtexAssets + "cube.obj");
  attach_ptex_displacement(scene, kPtexAssets + "cube_text.ptx");
  return scene;
}

DisplacedShadingReference DeviceSurface::shading(DisplacementNormals normals) const {
  DisplacedShadingReference out;
  out.params.tessellation = normals == DisplacementNormals::Displaced ? packed.params.tessellation : 0;
  out.params.adaptive = packed.adaptive() ? 1 : 0;
  out.vertices = &vertices;
  out.normals = &this->normals;
  return out;
}

DeviceSurface device_surface(PackedDisplacement packed) {
  TessellateLauncher stage(shared_runtime());
  stage.load(std::move(packed));
  DeviceSurface out;
  out.normals = stage.tessellate_normals();
  out.vertices = stage.read_vertices();
  out.packed = stage.packed();
  return out;
}

}  // namespace seamcl_tests
