// The option domains (options/option_domains.h) that act on a scene: "cube" where it has an
// environment, "displacement" where it has displacement maps. Front ends show a domain's controls
// for the scenes it acts on only, and leave its options out of requests for the others.
#pragma once
#include <string>
#include <vector>

#include <seamcl/options/option_domains.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

inline std::vector<std::string> scene_option_domains(const Scene& scene) {
  std::vector<std::string> out;
  if (scene.environment) out.push_back(kCubeDomain);
  if (scene.displacement) out.push_back(kDisplacementDomain);
  return out;
}

}  // namespace seamcl
