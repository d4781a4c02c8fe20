// How tessellated vertices on patch edges take their displacement (Castano, "Watertight Texture
// Sampling"): one enum, one parse/to-string pair, used by the CLI, HTTP and server/openapi.json.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace seamcl {

//   naive     - float domain points, each patch samples its own map (cracks where maps or
//               float rounding differ between the two sides of an edge);
//   zipper    - edge vertices take the mean of both sides' samples, corner vertices one value
//               every patch at the corner uses (the corner sample of the corner's owner);
//   ownership - every edge and corner has an owning patch; four texcoords per corner and the
//               post's index formulas pick the owner's, one sample;
//   fixed     - domain points in fixed point, an edge's computed from one end and mirrored, the
//               patch's own map filtered in exact integer arithmetic, on maps whose edge samples
//               are made to match (the post: fixed point alone is not enough);
//   ptex-filter - each patch filters its own map with a 3x3 tent one of its own sample spacings
//               wide, taps past an edge read the neighbour's map (the traverse idea), taps past
//               a corner or a boundary are dropped and the rest renormalised: both sides agree
//               only where they would use the same filter width.
enum class DisplacementMethod { Naive, Zipper, Ownership, Fixed, PtexFilter };

std::optional<DisplacementMethod> parse_displacement_method(std::string_view name);
std::string to_string(DisplacementMethod method);
std::vector<std::string> displacement_method_names();
// SEAMCL_DISPLACEMENT_* of kernels/seamcl_types.h
int displacement_method_code(DisplacementMethod method);

}  // namespace seamcl
