// Scalar twin of kernels/tessellate.cl: the same domain points, base surface, seam rules and
// displacement, one vertex at a time; and the micro-triangle setup that feeds the raster stage.
#pragma once
#include <vector>

#include <seamcl/pipeline/gpu_types.h>
#include "pipeline/displacement_packing.h"

namespace seamcl {

// Vertex (i, j) of patch `patch`, i along u and j along v, both 0..T.
TessVertex tessellate_vertex_reference(const PackedDisplacement& packed, int patch, int i, int j);

// Every vertex in the kernel's order: patch by patch, row j by row, i along a row.
std::vector<TessVertex> tessellate_reference(const PackedDisplacement& packed);

}  // namespace seamcl
