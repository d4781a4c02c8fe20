#include <seamcl/scene/environment.h>

#include <cmath>
#include <string>

#include <seamcl/core/input_error.h>
#include <seamcl/scene/cube_map.h>

namespace seamcl {

glm::vec4 environment_radiance(const AnalyticEnvironment& e, glm::vec3 d) {
  glm::vec3 base;
  if (d.y >= 0.0f) {
    // The gradient: towards the zenith with height, warmer towards +x and cooler towards -x.
    const float height = std::sqrt(d.y);
    base = e.horizon + (e.zenith - e.horizon) * height + glm::vec3(0.12f, 0.0f, -0.12f) * (d.x * (1.0f - height));
  } else {
    base = e.ground * (0.75f + 0.25f * d.z);
  }
  // The spot: a Gaussian in the angle to the sun (1 - cos is half the squared angle).
  const float one_minus_cos = 1.0f - glm::dot(d, e.sun_direction);
  const float spot = std::exp(-2.0f * one_minus_cos / (e.sun_radius * e.sun_radius));
  const glm::vec3 color = glm::clamp(base * (1.0f - spot) + e.sun_color * spot, 0.0f, 1.0f);
  return {color, 1.0f};
}

DirectionFunction environment_function(const Environment& environment) {
  if (environment.constant) {
    const glm::vec4 c(*environment.constant, 1.0f);
    return [c](glm::vec3) { return c; };
  }
  const AnalyticEnvironment analytic = environment.analytic;
  return [analytic](glm::vec3 d) { return environment_radiance(analytic, d); };
}

void validate_environment(const Environment& e) {
  if (e.cube_size < 1 || e.cube_size > kMaxCubeSize || (e.cube_size & (e.cube_size - 1)) != 0) {
    throw InputError("environment.cube_size", "must be a power of two in 1.." + std::to_string(kMaxCubeSize) +
                                                  ", got " + std::to_string(e.cube_size));
  }
  if (e.bake_samples < 1 || e.bake_samples > 8) {
    throw InputError("environment.bake_samples", "must be in 1..8, got " + std::to_string(e.bake_samples));
  }
  auto finite = [](glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (e.constant && !finite(*e.constant)) throw InputError("environment.constant", "must be finite");
  const AnalyticEnvironment& a = e.analytic;
  if (!finite(a.sun_direction) || glm::length(a.sun_direction) < 1e-6f) {
    throw InputError("environment.sun_direction", "must be a finite, non-zero vector");
  }
  if (!(a.sun_radius > 0.0f && a.sun_radius <= 3.2f)) {
    throw InputError("environment.sun_radius", "must be in (0, 3.2] radians");
  }
  if (!finite(a.sun_color) || !finite(a.zenith) || !finite(a.horizon) || !finite(a.ground)) {
    throw InputError("environment", "colours must be finite");
  }
}

}  // namespace seamcl
