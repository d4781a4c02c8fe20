// A .ptx file as Ptex's own filters read it (PtexFilterData, what kernels/ptex_filter.cl and its
// twin take): every resolution 2^i x 2^j of every face that a filter may ask for, each the stored
// level where the file holds it and otherwise made as the Ptex library makes it on demand (halving
// u or v from the next finer resolution, alternating for square ones, in the file's own type: integer
// halves round down, float16 ones round to float16), so the values read are the library's.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <seamcl/assets/ptex_file.h>
#include "pipeline/stages/ptex_filter_twin.h"

namespace seamcl {

struct PtexFilterLimits {
  uint64_t max_bytes = uint64_t(1) << 30;  // every resolution of every face, in the file's type
};

// Bytes build_ptex_filter_data will hold for `stored` (texels and tables), without building.
uint64_t ptex_filter_data_bytes(const PtexStored& stored);

// Throws InputError("texture", ...) for what the filters cannot take: subfaces (quads of split
// non-quad faces), or more bytes than limits allow.
PtexFilterData build_ptex_filter_data(const PtexStored& stored, const PtexFilterLimits& limits = {});

}  // namespace seamcl

namespace seamcl {

// Resolution 2^ulog2 x 2^vlog2 of face `face` as the Ptex library reads it (the stored level, or
// its on-demand reduction), in the file's units, rows of texels with channels interleaved.
std::vector<float> ptex_face_resolution(const PtexStored& stored, size_t face, int ulog2, int vlog2);

}  // namespace seamcl
