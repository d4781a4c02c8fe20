// Tessellation factors per patch edge (docs/displacement.md, "Factors per edge"): uniform (every
// edge at T) or screen-space adaptive, each edge's factor from its projected length in pixels.
// A factor is a function of the edge alone (its two mesh vertices, in index order), so the two
// patches that share an edge always get the same one, the condition for watertight transitions.
#pragma once
#include <array>
#include <vector>

#include <glm/glm.hpp>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>
#include "pipeline/displacement_packing.h"

namespace seamcl {

// Each face edge's factor: ceil(projected length in pixels / pixels_per_segment) clamped to
// 1..max_factor, the undisplaced edge projected with view_proj onto a width x height image; an
// edge with an end at or behind the near plane gets max_factor.
std::vector<std::array<int, 4>> screen_space_edge_factors(const Scene& scene, const glm::mat4& view_proj, int width,
                                                          int height, float pixels_per_segment, int max_factor);

// What the tessellation stage is loaded with for a frame of `options` seen from `camera`:
// options.displacement (required), tessellation and level, and with options.tessellation_pixels
// the screen-space factors of that camera at the options' size.
DisplacementSettings displacement_settings(const Scene& scene, const RenderOptions& options, const Camera& camera);

}  // namespace seamcl
