// Admission of renders: at most `threads` render at once, each on a slot of its own (a slot's
// Renderers hold kernel objects, whose arguments cannot be set from two threads at once), and at
// most `queue` wait for one. A render beyond that is refused at once (503 with Retry-After), as is
// one still waiting at its deadline or whose client has gone. Slots become free as the warm-up
// readies them, so early renders wait rather than build kernels themselves.
#pragma once
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace seamcl {
class Renderer;
}  // namespace seamcl

namespace seamcl::server {

// The Renderers one worker uses: one per built-in scene (and tint), by builtin_scene_key, and a
// scratch one for inline scenes and assets, which reloads its scene on every request.
struct RenderSlot {
  RenderSlot();
  ~RenderSlot();
  std::map<std::string, std::unique_ptr<Renderer>> renderers;
  std::unique_ptr<Renderer> scratch;
  // For the memory bound (server/memory_bound.h): when each Renderer was last used (a count of
  // the slot's requests) and the bytes it was counted with ("" for the scratch one).
  std::map<std::string, long long> last_used;
  std::map<std::string, size_t> counted_bytes;
  long long uses = 0;
};

class RenderSlots;

// A slot held by one request, given back when the lease ends.
class SlotLease {
 public:
  SlotLease(RenderSlots& slots, RenderSlot& slot) : slots_(slots), slot_(slot) {}
  ~SlotLease();
  SlotLease(const SlotLease&) = delete;
  SlotLease& operator=(const SlotLease&) = delete;
  RenderSlot& slot() const { return slot_; }

 private:
  RenderSlots& slots_;
  RenderSlot& slot_;
};

class RenderSlots {
 public:
  using Clock = std::chrono::steady_clock;

  // `deadline_ms`: how long after it arrived a request may wait for a slot; 0: no deadline.
  RenderSlots(int threads, int queue, int deadline_ms);
  ~RenderSlots();
  RenderSlots(const RenderSlots&) = delete;
  RenderSlots& operator=(const RenderSlots&) = delete;

  // A free slot for a request that arrived at `arrived`, waiting for one if the queue has room.
  // Throws HttpError 503: "queue" when full, "deadline" past the deadline, "client" when the
  // client has gone while waiting, "server" when no slot could be warmed.
  std::unique_ptr<SlotLease> acquire(Clock::time_point arrived);

  // For the warm-up: slot `index` with a warm Renderer under `key` becomes free.
  void add_warm(size_t index, const std::string& key, std::unique_ptr<Renderer> renderer);
  // For the warm-up: the slots not yet warm never will be. With none warm, renders are refused
  // rather than left waiting.
  void record_warm_up_failure(const std::string& message);

  size_t size() const { return slots_.size(); }
  // Every slot is warm, or failed to warm while at least one did.
  bool ready() const;
  // No slot could be warmed.
  bool failed() const;
  // Blocks until ready() or the warm-up failed; false on failure or after timeout.
  bool wait_ready(std::chrono::milliseconds timeout);
  int ready_slots() const { return ready_slots_.load(); }
  int admitted() const { return admitted_.load(); }  // rendering + waiting
  // Wakes every waiting request, to see whether it should give up (the server is stopping).
  void wake_all();

 private:
  friend class SlotLease;
  void release(RenderSlot& slot);

  const int threads_;
  const int queue_;
  const int deadline_ms_;
  std::vector<std::unique_ptr<RenderSlot>> slots_;
  std::vector<RenderSlot*> free_slots_;
  mutable std::mutex mutex_;
  std::condition_variable slot_freed_;
  std::atomic<int> admitted_{0};
  std::atomic<int> ready_slots_{0};
  std::atomic<int> failed_slots_{0};  // slots whose warm-up failed (the rest serve)
  std::string warm_error_;            // under mutex_; not empty: no slot could be warmed
};

}  // namespace seamcl::server
