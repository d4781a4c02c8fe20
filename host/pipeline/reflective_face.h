// What the shade stage needs of a face that reflects the environment (ReflectiveFace).
#pragma once
#include <seamcl/pipeline/gpu_types.h>
#include <seamcl/scene/scene.h>

namespace seamcl {

// The face's corner positions and shading normals (Scene::normals) and its roughness.
ReflectiveFace reflective_face(const Scene& scene, const Face& face);

}  // namespace seamcl
