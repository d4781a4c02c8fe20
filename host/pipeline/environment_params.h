// The per-frame part of the environment lookups (EnvironmentParams): the cube sampler of the
// request's cube method, the eye and the view rays of the skybox.
#pragma once
#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/options/render_options.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// All zero (sampler.size 0) for a scene without an environment.
EnvironmentParams environment_params(const Scene& scene, const Camera& camera, const RenderOptions& options);

}  // namespace seamcl
