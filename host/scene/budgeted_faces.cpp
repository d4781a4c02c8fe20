#include "scene/budgeted_faces.h"

#include <algorithm>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace seamcl {

unsigned face_threads() {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());  // 0 if unknown
  return 1 + std::min(7u, cores - 1);
}

void for_each_face_in_budget(size_t count, const std::function<void(size_t face)>& work,
                             const std::function<size_t(size_t face)>& weight, size_t budget) {
  std::mutex mutex;
  std::condition_variable room;
  size_t running_weight = 0, running = 0;  // of the faces between their wait and their end
  // Gives a face's weight back when its work ends, also by an exception.
  struct Leave {
    std::mutex& mutex;
    std::condition_variable& room;
    size_t& running_weight;
    size_t& running;
    size_t weight;
    ~Leave() {
      {
        const std::lock_guard lock(mutex);
        running_weight -= weight;
        --running;
      }
      room.notify_all();
    }
  };
  for_each_face_in_parallel(count, [&](size_t f) {
    const size_t w = weight(f);
    {
      std::unique_lock lock(mutex);
      room.wait(lock, [&] { return running == 0 || (w <= budget && running_weight <= budget - w); });
      running_weight += w;
      ++running;
    }
    const Leave leave{mutex, room, running_weight, running, w};
    work(f);
  });
}

size_t texture_making_bytes(const Scene& scene, size_t face) {
  const MipChain& chain = scene.faces.at(face).texture;
  if (!is_deferred(chain)) return 0;
  size_t texels = 0;
  for (const TextureLevel& level : chain.levels) texels += static_cast<size_t>(level.width) * static_cast<size_t>(level.height);
  const size_t chain_bytes = texels * sizeof(glm::vec4);
  if (face >= scene.texture_source_decode_bytes.size()) return chain_bytes;
  const size_t level0_bytes = static_cast<size_t>(chain.width()) * static_cast<size_t>(chain.height()) * sizeof(glm::vec4);
  return std::max(chain_bytes, level0_bytes + scene.texture_source_decode_bytes[face]);
}

}  // namespace seamcl
