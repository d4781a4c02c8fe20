// Device colours of a lookup batch against the twin's, lookup by lookup.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#include <seamcl/pipeline/packed_scene.h>
#include <seamcl/pipeline/texture_lookups.h>
#include "pipeline/stages/texture_sample_twin.h"

namespace seamcl_tests {

// The number of lookups whose device colour `close(device, twin)` refuses for some channel, against
// sample_texture_reference with the same sampler; the first three are reported as failures.
template <typename Close>
size_t twin_colour_mismatches(const std::vector<glm::vec4>& gpu, const seamcl::PackedScene& packed,
                              const SamplerParams& sampler, const std::vector<seamcl::Lookup>& lookups,
                              Close close) {
  size_t bad = 0;
  for (size_t i = 0; i < lookups.size(); ++i) {
    const seamcl::Lookup& l = lookups[i];
    const glm::vec4 twin = seamcl::sample_texture_reference(packed.textures(), l.face, sampler, l.u, l.v, l.dudx,
                                                            l.dvdx, l.dudy, l.dvdy);
    bool ok = true;
    for (int c = 0; c < 4; ++c) ok &= close(gpu[i][c], twin[c]);
    if (!ok && bad++ < 3) ADD_FAILURE() << "lookup " << i << ": gpu " << gpu[i].r << " twin " << twin.r;
  }
  return bad;
}

}  // namespace seamcl_tests
