// The domain of a render option: the part of a scene it acts on. "cube" options act on scenes with
// an environment (their reflections and skybox), "displacement" options on displaced patches; the
// others (empty) on every scene. Declared with each option in its row of render_option_table
// (render_options.cpp), so front ends that group controls (the viewer, through the methods
// document's "domains") never list the keys themselves. A header of its own: the option table's
// header is included nearly everywhere, this one only where controls are grouped.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace seamcl {

// The domains' names, as the table's rows and scene_option_domains (jobs/scene_domains.h) give them.
inline constexpr const char* kCubeDomain = "cube";
inline constexpr const char* kDisplacementDomain = "displacement";

// Domain name -> the render options of that domain, in the table's order; options of no domain
// are left out.
const std::map<std::string, std::vector<std::string>>& render_option_domains();

}  // namespace seamcl
