// Scalar twin of kernels/shade_resolve.cl: shading once per pixel and triangle (or per sample)
// and the box resolve.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/pipeline/packed_scene.h>

namespace seamcl {

struct PtexRenderTexture;  // pipeline/stages/ptex_filter_twin.h

// uv and its screen derivatives at a pixel-space point, perspective-correct from the planes.
struct SurfaceUv {
  float u, v, dudx, dvdx, dudy, dvdy;
};
SurfaceUv interpolate_uv(const TriangleSetup& t, float x, float y);

// A displaced render's shading normals (kernels/shade_resolve.cl's DisplacedSource): the
// tessellated vertices and displaced_normals' normals, params.tessellation 0 for none.
struct DisplacedShadingReference {
  DisplacedShading params{};
  const std::vector<TessVertex>* vertices = nullptr;
  const std::vector<cl_float4>* normals = nullptr;
};

// The lighting normal at domain point (u, v) of micro-triangle `tri` (input order): its
// vertices' normals weighted by (u, v)'s barycentrics in their uv, each clamped to >= 0,
// renormalised; (0, 0, 0) where that has no finite length.
glm::vec3 displaced_shading_normal_reference(const DisplacedShadingReference& d, int tri, float u, float v);

// Colour of one fragment: texture lookup times the face's Lambert lighting; on a reflective face
// the environment along the reflected ray (pipeline/stages/shade_resolve_reflection_twin.h), from
// `cube_texels` (the renderer's Renderer::cube_texels(); needed by scenes with an environment only).
// With `ptex` (the Ptex variant), the lookup is Ptex's own filter on its file (ptex_albedo_twin).
// With `displaced` (tessellation > 0), lit by displaced_shading_normal_reference of the record's
// micro-triangle, input order `slot` / SEAMCL_CLIP_SLOTS, where that has a length.
glm::vec3 shade_fragment_reference(const PackedScene& scene, const FrameParams& frame, const TriangleSetup& t, float x,
                                   float y, const std::vector<float>* cube_texels = nullptr,
                                   const PtexRenderTexture* ptex = nullptr,
                                   const DisplacedShadingReference* displaced = nullptr, uint32_t slot = 0);

// A triangle's fragment in one pixel (pixel or centroid shading): the samples it covers and
// where it is shaded. `ids` are the pixel's sample winners; `slot` must be among them.
struct PixelFragment {
  int covered = 0;
  float x = 0, y = 0;  // pixel-space shading point
};
PixelFragment pixel_fragment(const FrameParams& frame, const TriangleSetup& t, const uint32_t* ids, uint32_t slot,
                             int x, int y);

// Whether some fragment of pixel (x, y) (pixel or centroid shading) has no filter tap inside its
// face (nor, for traverse, its neighbours): the fragments zero_coverage=nan turns into NaN.
// Reflective faces (cube-map lookups) have no patch taps and never count.
bool pixel_has_uncovered_fragment(const PackedScene& scene, const FrameParams& frame,
                                  const std::vector<TriangleSetup>& setups, const uint32_t* ids, int x, int y);

// The seam mask class of the fragment of `t` shaded at (x, y) (see kernels/shade_resolve.cl):
// SEAMCL_MASK_SEAM when its footprint crosses an edge shared with a neighbour (its own filter, or
// the same filter carried onto the neighbour as traverse reads it), else SEAMCL_MASK_BOUNDARY when
// it crosses a mesh boundary edge, else SEAMCL_MASK_NONE: there every seam method agrees.
uint8_t footprint_class(const PackedScene& scene, const FrameParams& frame, const TriangleSetup& t, float x, float y);
// A pixel's class over its fragments: seam over boundary over none.
uint8_t merge_mask(uint8_t a, uint8_t b);

struct ResolveReference {
  std::vector<glm::vec4> pixels;  // linear RGBA
  uint32_t fragments = 0;
  std::vector<uint8_t> seam_mask;  // per pixel, SEAMCL_MASK_* over its fragments; empty when the
                                   // packing has no adjacency (the mask reads it)
};
ResolveReference shade_resolve_reference(const PackedScene& scene, const FrameParams& frame,
                                         const std::vector<TriangleSetup>& setups,
                                         const std::vector<uint32_t>& sample_triangle,
                                         const std::vector<float>* cube_texels = nullptr,
                                         const PtexRenderTexture* ptex = nullptr,
                                         const DisplacedShadingReference* displaced = nullptr);

}  // namespace seamcl
