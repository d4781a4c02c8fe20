// The scalar twin of kernels/texture_sample.cl: the sampler every seam
// method is a setting of (filter, address mode, renormalisation).
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <seamcl/pipeline/texture_view.h>

namespace seamcl {


// log2 within 5e-6 for x > 0, the polynomial the kernels use.
float approx_log2(float x);
// log2 of an aniso probe count 1..SEAMCL_MAX_PROBES as the kernels read it
// (SEAMCL_LOG2_PROBE_COUNTS: approx_log2's bits for each count).
float log2_probe_count(int probes);
// An aniso lookup's probe count for a footprint's major / minor ratio, as the kernels'
// probe_count: ceil(ratio), at most SEAMCL_MAX_PROBES and max_aniso, at least 1.
int probe_count(float ratio, int max_aniso);

// One lookup with sampler.filter and `address`, before renormalisation: at the mip level its
// footprint gives plus sampler.lod_bias (bilinear: the level nearest the bias), as the kernel's
// filter_texture.
FilterSum filter_texture_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler,
                                   int address, float u, float v, float dudx, float dvdx, float dudy, float dvdy);
// Whether any tap of face `other` can weigh anything in a lookup with `filter` (SEAMCL_FILTER_*;
// SamplerParams.lod_bias `lod_bias`; derivatives in this face's uv; `guard_band` texels per level
// stored around each level)
// whose point must travel at least distance_u along u and distance_v along v (this face's uv; a
// negative distance never decides) to reach the other face's square: a conservative bound, so a
// neighbour it rules out would have added exactly nothing. Traverse skips those. `swapped`: the
// other face's u and v run along this face's v and u (map_swaps_axes of the map to it).
bool neighbor_may_contribute(const FaceGpu& other, bool swapped, int filter, int max_aniso, float lod_bias,
                             int guard_band, float distance_u, float distance_v, float dudx, float dvdx, float dudy,
                             float dvdy);
// Whether a uv map's coefficients (map_coefficients of FaceNeighbors' edge_map or corner_map)
// swap u and v (a signed permutation with t0 = 0).
bool map_swaps_axes(const float transform[6]);
// EWA's bound, for any face whose shorter side is no less than min_side and whose aspect is no
// more than max_side / min_side; min_side 0 (not known) never rules out.
bool ewa_sides_may_contribute(float min_side, float max_side, int guard_band, float lod_bias, float distance_u,
                              float distance_v, float dudx, float dvdx, float dudy, float dvdy);
// Bilinear, trilinear and aniso's bound along one axis of this face's uv: true when a lookup
// `distance` (uv) inside the edge across that axis cannot reach a face whose side along it is
// `side` texels and along the other axis `cross_side`, nor any face whose side along it is no
// shorter and whose cross_side / side is no larger. x_a, y_a: the screen axes' components
// (absolute, finite) along this axis; x_b, y_b: along the other. side 0 never rules out.
bool axis_rules_out(float side, float cross_side, int filter, int max_aniso, float lod_bias, int guard_band,
                    float distance, float x_a, float x_b, float y_a, float y_b);
// Traverse's first test, from the lookup's own face record alone: bit k set when the lookup may
// reach a face across edge k or past its two ends (axis_rules_out with the edge's
// reach_min_side / reach_max_side); a clear bit skips those three faces unread. EWA: all set.
int edges_may_reach(const FaceNeighbors& n, int filter, int max_aniso, float lod_bias, int guard_band, float u, float v,
                    float dudx, float dvdx, float dudy, float dvdy);
// Whether a border-addressed lookup with `filter` on `face` (its own uv and derivatives) can put
// weight inside it (or in its guard band of `guard_band` texels per level): bilinear, trilinear
// and aniso test the very probes the filter takes (their line, and a texel of the coarser level
// read); EWA always may. Conservative, like the above.
bool lookup_may_reach_face(const FaceGpu& face, int guard_band, int filter, int max_aniso, float lod_bias, float u,
                           float v, float dudx, float dvdx, float dudy, float dvdy);
// What a method sums before renormalising: filter_texture_reference on the face with the
// sampler's address mode and, for traverse, on each edge neighbour (border) through its uv
// transform, and with corners, on the diagonal face past each valence-4 corner. `early_out`
// false reads every neighbour, for the tests that check the early-outs change nothing.
FilterSum method_sum_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler, float u, float v,
                               float dudx, float dvdx, float dudy, float dvdy, bool early_out = true);
// The lookup as a seam method asks for it (renormalisation and zero-coverage rule included).
glm::vec4 sample_texture_reference(const TextureView& textures, uint32_t face, const SamplerParams& sampler, float u,
                                   float v, float dudx, float dvdx, float dudy, float dvdy);

}  // namespace seamcl
