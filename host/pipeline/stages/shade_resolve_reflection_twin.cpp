#include "pipeline/stages/shade_resolve_reflection_twin.h"

#include <cmath>

#include "pipeline/stages/cube_sample_twin.h"

namespace seamcl {
namespace {

float dot3(glm::vec3 a, glm::vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
glm::vec3 load3(const float* p) { return {p[0], p[1], p[2]}; }

}  // namespace

ReflectedRay reflected_ray(const FrameParams& frame, const ReflectiveFace& face, const SurfaceUv& s) {
  const float u = s.u, v = s.v;
  const glm::vec3 p0 = load3(face.position[0]), p1 = load3(face.position[1]);
  const glm::vec3 p2 = load3(face.position[2]), p3 = load3(face.position[3]);
  const glm::vec3 n0 = load3(face.normal[0]), n1 = load3(face.normal[1]);
  const glm::vec3 n2 = load3(face.normal[2]), n3 = load3(face.normal[3]);
  // The point, piecewise linear over the two triangles as rasterised.
  const bool first_triangle = u >= v;
  const glm::vec3 pu = first_triangle ? p1 - p0 : p2 - p3;
  const glm::vec3 pv = first_triangle ? p2 - p1 : p3 - p0;
  const glm::vec3 view = p0 + pu * u + pv * v - load3(frame.environment.eye);
  // The normal, bilinear over the corners, normalised; d(n/|n|) = (dn - N (N.dn)) / |n|.
  const glm::vec3 n = n0 * ((1.0f - u) * (1.0f - v)) + n1 * (u * (1.0f - v)) + n2 * (u * v) + n3 * ((1.0f - u) * v);
  const glm::vec3 nu = (n1 - n0) * (1.0f - v) + (n2 - n3) * v;
  const glm::vec3 nv = (n3 - n0) * (1.0f - u) + (n2 - n1) * u;
  const float inv_length = 1.0f / std::sqrt(dot3(n, n));
  const glm::vec3 normal = n * inv_length;
  const glm::vec3 dn_x = nu * s.dudx + nv * s.dvdx;
  const glm::vec3 dn_y = nu * s.dudy + nv * s.dvdy;
  const glm::vec3 dnormal_x = (dn_x - normal * dot3(normal, dn_x)) * inv_length;
  const glm::vec3 dnormal_y = (dn_y - normal * dot3(normal, dn_y)) * inv_length;
  const glm::vec3 dview_x = pu * s.dudx + pv * s.dvdx;
  const glm::vec3 dview_y = pu * s.dudy + pv * s.dvdy;
  // R = I - 2 (N.I) N and its derivative by the product rule.
  const float n_dot_i = dot3(normal, view);
  ReflectedRay r;
  r.direction = view - normal * (2.0f * n_dot_i);
  r.ddx = dview_x - (normal * (dot3(dnormal_x, view) + dot3(normal, dview_x)) + dnormal_x * n_dot_i) * 2.0f;
  r.ddy = dview_y - (normal * (dot3(dnormal_y, view) + dot3(normal, dview_y)) + dnormal_y * n_dot_i) * 2.0f;
  return r;
}

glm::vec3 environment_lookup_reference(const FrameParams& frame, const std::vector<float>& cube_texels, glm::vec3 d,
                                       glm::vec3 ddx, glm::vec3 ddy, float roughness) {
  if (frame.environment.sampler.method == SEAMCL_CUBE_DIRECTION) {
    return d * ((1.0f + roughness) / std::sqrt(dot3(d, d)));
  }
  return glm::vec3(sample_cube_reference(cube_texels, frame.environment.sampler, d, ddx, ddy, roughness, -1.0f));
}

glm::vec3 shade_reflection_reference(const FrameParams& frame, const ReflectiveFace& face,
                                     const std::vector<float>& cube_texels, const SurfaceUv& s) {
  const ReflectedRay r = reflected_ray(frame, face, s);
  return environment_lookup_reference(frame, cube_texels, r.direction, r.ddx, r.ddy, face.roughness);
}

glm::vec3 shade_sky_reference(const FrameParams& frame, const std::vector<float>& cube_texels, float x, float y) {
  const EnvironmentParams& e = frame.environment;
  const glm::vec3 dx = load3(e.ray_dx), dy = load3(e.ray_dy);
  const glm::vec3 d = load3(e.ray_corner) + dx * x + dy * y;
  return environment_lookup_reference(frame, cube_texels, d, dx, dy, 0.0f);
}

}  // namespace seamcl
