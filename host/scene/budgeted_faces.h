// Per-face work in parallel within a memory budget: packing a deferred scene makes each face's
// float chain while the packed copy already exists, so how many chains are in flight at once
// decides the peak (host/pipeline/packed_scene.cpp).
#pragma once
#include <cstddef>
#include <functional>

#include <seamcl/scene/scene.h>

namespace seamcl {

// The threads for_each_face_in_parallel runs on (this one included) on this machine: up to 8.
unsigned face_threads();

// As for_each_face_in_parallel, but a face starts only while the `weight`s of the faces running,
// its own included, sum to at most `budget`, or when none is running (a face heavier than the
// budget runs alone): what the running faces hold together stays within the budget, or within
// the one heaviest face. The first exception is rethrown once all have stopped, as there.
void for_each_face_in_budget(size_t count, const std::function<void(size_t face)>& work,
                             const std::function<size_t(size_t face)>& weight, size_t budget);

// The most face f holds while it is made, for a deferred face: its float RGBA chain (every level's
// texels), or its level 0 with what its source decodes it from beside it
// (Scene::texture_source_decode_bytes: an image's decode buffers, dropped before the chain is
// built), whichever is more. 0 for a stored face (read where it is).
size_t texture_making_bytes(const Scene& scene, size_t face);

}  // namespace seamcl
