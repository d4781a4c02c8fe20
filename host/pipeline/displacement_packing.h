// A scene's displacement flattened into what kernels/tessellate.cl (and its twin) reads: one
// DisplacementPatch per face, every map's samples in one buffer, a normal per mesh vertex, and
// the per-method data the seam rules need (neighbours, corner values, owners' texcoords).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/scene/scene.h>
#include <seamcl/options/displacement_method.h>
#include "scene/displacement_map.h"

static_assert(sizeof(DisplacementTexcoord) == 12, "DisplacementTexcoord layout");
static_assert(sizeof(DisplacementPatch) == 288, "DisplacementPatch layout");
static_assert(offsetof(DisplacementPatch, corner_value) == 64);
static_assert(offsetof(DisplacementPatch, texcoord) == 80);
static_assert(offsetof(DisplacementPatch, map_offset) == 272);
static_assert(sizeof(TessellationParams) == 16, "TessellationParams layout");
static_assert(sizeof(TessVertex) == 32, "TessVertex layout");

namespace seamcl {

struct DisplacementSettings {
  DisplacementMethod method = DisplacementMethod::Naive;
  int tessellation = 8;  // T, 1..SEAMCL_MAX_TESSELLATION
  int level = 0;         // the maps' level every patch samples (explicit, no lod selection)
};

// Micro-triangles one render may make (patches * 2 * T^2): with SEAMCL_CLIP_SLOTS setups of 112
// bytes each, 2^21 of them need 1.4 GB; larger requests are refused.
inline constexpr size_t kMaxTessellatedTriangles = size_t{1} << 21;

// InputError("tessellation") for T outside 1..SEAMCL_MAX_TESSELLATION or patches * 2 * T^2 over
// kMaxTessellatedTriangles.
void check_tessellation(size_t patches, int tessellation);

struct PackedDisplacement {
  std::vector<DisplacementPatch> patches;  // one per scene face
  std::vector<uint16_t> samples;           // every map at the chosen level
  std::vector<cl_float4> positions;        // the scene's, xyz, w = 1
  std::vector<cl_float4> normals;          // per mesh vertex: the mean of its faces' normals
  TessellationParams params{};
  size_t matched_samples = 0;  // fixed: samples the edge matching changed
  size_t unmatched_edges = 0;  // fixed: shared edges whose resolutions do not nest (left as they are)

  size_t vertex_count() const;    // patches * (T+1)^2
  size_t triangle_count() const;  // patches * 2 * T^2
  // Bytes the method adds to a patch's plain data (corners, map offset and size): zipper's
  // neighbours and corner values, ownership's 16 texcoords, none for naive and fixed.
  size_t method_bytes() const;
};

// Throws InputError naming the field: "tessellation" outside 1..64 or over
// kMaxTessellatedTriangles, "displacement_level" outside 0..16, "displacement" when the scene has
// no maps or they do not fit it (validate_displacement).
PackedDisplacement pack_displacement(const Scene& scene, const DisplacementSettings& settings);

// The fixed method's map preparation, on maps at the level sampled: every face's corner sample
// at a vertex becomes one value (the lowest-numbered face's, rounded to a multiple of 64), and
// across each shared edge whose resolutions nest (one a multiple r <= 64 of the other), the
// coarser side's edge samples are rounded to multiples of r and the finer side's become their
// exact linear interpolation, so both sides' piecewise-linear edge functions are the same
// integers. Returns the number of samples changed; counts edges that could not be matched.
size_t match_edge_samples(const Scene& scene, std::vector<DisplacementMap>& maps, size_t* unmatched_edges);

}  // namespace seamcl
