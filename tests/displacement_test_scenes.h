// Closed displaced meshes that are not star-shaped, shared by the crack and adaptive
// tessellation tests: a torus made here and the Ptex cube with tunnels; and a displaced surface
// as the device tessellates it, for the shading twins.
#pragma once
#include <string>
#include <vector>

#include <seamcl/options/displacement_method.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>
#include "pipeline/displacement_packing.h"
#include "pipeline/stages/shade_resolve_twin.h"

namespace seamcl_tests {

inline const std::string kPtexAssets = std::string(SEAMCL_TEST_ASSETS_DIR) + "/ptex/";

// Every displacement method, and the ones that claim a watertight surface.
inline const std::vector<seamcl::DisplacementMethod> kAllDisplacementMethods{
    seamcl::DisplacementMethod::Naive, seamcl::DisplacementMethod::Zipper, seamcl::DisplacementMethod::Ownership,
    seamcl::DisplacementMethod::Fixed, seamcl::DisplacementMethod::PtexFilter};
inline const std::vector<seamcl::DisplacementMethod> kWatertightMethods{
    seamcl::DisplacementMethod::Zipper, seamcl::DisplacementMethod::Ownership, seamcl::DisplacementMethod::Fixed};

// A torus of rings x sides quads (major radius 1, minor 0.35, axis y), counter-clockwise from
// outside, with maps of different resolutions baked face by face: the hole makes it
// non-star-shaped, and neighbours' maps disagree between shared corners, so naive cracks.
seamcl::Scene make_torus(int rings, int sides);

// tests/assets/ptex/cube.obj (72 quads with tunnels) displaced by cube_text.ptx.
seamcl::Scene cube_obj();

// The tessellation stage's vertices and normals of `packed`, read back from the device.
struct DeviceSurface {
  seamcl::PackedDisplacement packed;
  std::vector<TessVertex> vertices;  // kernels/seamcl_types.h: a C struct outside the namespace
  std::vector<cl_float4> normals;
  // What the shading twins take for a render lit by `normals` (the face normal: none).
  seamcl::DisplacedShadingReference shading(seamcl::DisplacementNormals normals) const;
};
DeviceSurface device_surface(seamcl::PackedDisplacement packed);

}  // namespace seamcl_tests
