// Displacement maps from a Ptex file: one channel per face (the 1-channel uint16 rand_lo.ptx and
// wave_lo.ptx of the Ptex sample assets), face i of the file displacing face i of the mesh.
#pragma once
#include <string>

#include <seamcl/assets/ptex_file.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// Reads `path` and sets scene.displacement: face i's W x H texels (texel-centred, Ptex's
// convention) become a (W+1) x (H+1) corner-to-corner sample grid by bilinear interpolation of
// the texel centres, clamped at the face's edges, rounded to 16 bits. The scale is 5% of the
// mesh's bounding-box diagonal. Throws InputError("displacement_map", ...) naming the file for an
// unreadable or malformed file, a file with other than one channel, or a face count that is not
// the mesh's.
void attach_ptex_displacement(Scene& scene, const std::string& path, const PtexLimits& limits = {});

}  // namespace seamcl
