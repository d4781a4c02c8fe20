// A scene's displacement flattened into what kernels/tessellate.cl (and its twin) reads: one
// DisplacementPatch per face, every map's samples in one buffer, a normal per mesh vertex, and
// the per-method data the seam rules need (neighbours, corner values, owners' texcoords).
#pragma once
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/scene/scene.h>
#include <seamcl/options/displacement_method.h>
#include "scene/displacement_map.h"

static_assert(sizeof(DisplacementTexcoord) == 12, "DisplacementTexcoord layout");
static_assert(sizeof(DisplacementPatch) == 304, "DisplacementPatch layout");
static_assert(offsetof(DisplacementPatch, edge_factor) == 288);
static_assert(offsetof(DisplacementPatch, corner_value) == 64);
static_assert(offsetof(DisplacementPatch, texcoord) == 80);
static_assert(offsetof(DisplacementPatch, map_offset) == 272);
static_assert(sizeof(TessellationParams) == 16, "TessellationParams layout");
static_assert(sizeof(TessVertex) == 32, "TessVertex layout");

namespace seamcl {

struct DisplacementSettings {
  DisplacementMethod method = DisplacementMethod::Naive;
  int tessellation = 8;  // T, 1..SEAMCL_MAX_TESSELLATION; with edge_factors, the largest allowed
  int level = 0;         // the maps' level every patch samples (explicit, no lod selection)
  // Empty: uniform, every edge and inside at T. Else one factor per face edge (edge k from corner
  // k), 1..T, equal on both faces of a shared edge (host/pipeline/tessellation_factors.h makes
  // them from an edge's screen length); the packing then makes every patch's (N+1)^2 slot grid
  // with N the largest factor given and the inside at the largest of the patch's edges (at least
  // 2 when N >= 2).
  std::vector<std::array<int, 4>> edge_factors;

  bool operator==(const DisplacementSettings& o) const {
    return method == o.method && tessellation == o.tessellation && level == o.level && edge_factors == o.edge_factors;
  }
  bool operator!=(const DisplacementSettings& o) const { return !(*this == o); }
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
  // The patch corners at each mesh vertex, for the displaced surface's normals (displaced_normals):
  // vertex v's are corner_copies[corner_offsets[v] .. corner_offsets[v + 1]), each patch * 4 +
  // corner, in (patch, j, i) order of the corners' slots (the order displaced_normal sums in).
  std::vector<cl_uint> corner_offsets;     // positions + 1
  std::vector<cl_uint> corner_copies;      // 4 per patch
  TessellationParams params{};
  size_t matched_samples = 0;  // fixed: samples the edge matching changed
  size_t unmatched_edges = 0;  // fixed: shared edges whose resolutions do not nest (left as they are)

  size_t vertex_count() const;    // patches * (T+1)^2
  size_t triangle_count() const;  // patches * 2 * T^2
  bool adaptive() const { return !patches.empty() && patches.front().inner_factor > 0; }
  // Micro-triangles whose three slots are three different domain points: triangle_count() when
  // uniform, fewer when adaptive (the rest are degenerate, culled by setup).
  size_t surface_triangle_count() const;
  // Bytes the method adds to a patch's plain data (corners, map offset and size): zipper's
  // neighbours and corner values, ownership's 16 texcoords, none for naive and fixed.
  size_t method_bytes() const;
};

// Throws InputError naming the field: "tessellation" outside 1..64 or over
// kMaxTessellatedTriangles, "tessellation_factors" for edge factors that are not one per face
// edge in 1..T or differ between the two faces of an edge, "displacement_level" outside 0..16, "displacement" when the scene has
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
