// How the packed textures store texels: 8-bit sRGB (linearised through a table as they are read)
// or 32-bit float. An option of a render (texels) that the packing and the sampler read too.
#pragma once

namespace seamcl {

enum class TexelFormat { Rgba8, Rgba32f };

}  // namespace seamcl
