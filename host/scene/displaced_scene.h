// The built-in `displaced` scene and the baking of displacement maps from one continuous 3D
// function, so that any crack a render shows is a seam method's, not the data's.
#pragma once
#include <array>
#include <functional>

#include <glm/glm.hpp>

#include <seamcl/scene/scene.h>
#include <seamcl/scene/scene_generators.h>
#include "scene/displacement_map.h"

namespace seamcl {

// A smooth height in [0, 1] of a 3D point: a few waves with features 0.1 to 0.3 units wide.
float displacement_pattern(glm::vec3 p);

// The point of a quad at (u, v), bilinear in its corners (the surface the tessellator displaces;
// at u, v in {0, 1} it is the corner itself, exactly).
glm::vec3 bilinear_point(const std::array<glm::vec3, 4>& corners, float u, float v);

// A columns x rows map for a face, each sample the height at its own surface point
// (bilinear_point at (i / (columns-1), j / (rows-1))), rounded to 16 bits. Each face bakes its
// own samples: neighbours of different resolution agree at shared corners (the same point) but
// not between them, as maps baked face by face do not.
DisplacementMap bake_displacement_map(const std::array<glm::vec3, 4>& corners, int columns, int rows,
                                      const std::function<float(glm::vec3)>& height);

// `displaced`: a closed cube-sphere of 24 quads (each cube face split 2 x 2, projected onto the
// unit sphere), displacement maps from 2x2 to 33x33 samples, non-square among them, baked from
// displacement_pattern; every face starts its vertex list at a different corner, so neighbours
// meet rotated by every multiple of 90 degrees.
Scene make_displaced_scene(const GeneratorOptions& options);

}  // namespace seamcl
