#include "render_slots.h"

#include <algorithm>

#include <seamcl/pipeline/renderer.h>

#include "connection.h"
#include "request_hygiene.h"

namespace seamcl::server {

RenderSlot::RenderSlot() = default;
RenderSlot::~RenderSlot() = default;

SlotLease::~SlotLease() { slots_.release(slot_); }

RenderSlots::RenderSlots(int threads, int queue, int deadline_ms)
    : threads_(threads), queue_(queue), deadline_ms_(deadline_ms) {
  for (int i = 0; i < threads; ++i) slots_.push_back(std::make_unique<RenderSlot>());
}

RenderSlots::~RenderSlots() = default;

std::unique_ptr<SlotLease> RenderSlots::acquire(Clock::time_point arrived) {
  const int capacity = threads_ + queue_;
  if (admitted_.fetch_add(1) >= capacity) {
    admitted_.fetch_sub(1);
    throw HttpError{503, "queue",
                    "busy: " + std::to_string(threads_) + " renders running and " + std::to_string(queue_) +
                        " waiting; retry later",
                    1};
  }
  std::unique_lock lock(mutex_);
  // Wait for a slot, until the deadline, waking now and then to see whether the client has gone.
  const Clock::time_point deadline =
      deadline_ms_ > 0 ? arrived + std::chrono::milliseconds(deadline_ms_) : Clock::time_point::max();
  const auto usable = [&] { return !free_slots_.empty() || !warm_error_.empty(); };
  while (!usable()) {
    const Clock::time_point wake = std::min(deadline, Clock::now() + std::chrono::milliseconds(200));
    slot_freed_.wait_until(lock, wake, usable);
    if (usable()) break;
    if (Clock::now() >= deadline || GuardedHttpServer::client_gone()) {
      admitted_.fetch_sub(1);
      if (GuardedHttpServer::client_gone()) throw HttpError{503, "client", "the client has gone", 0};
      throw HttpError{503, "deadline",
                      "no render slot free within this server's deadline of " + std::to_string(deadline_ms_) + " ms", 1};
    }
  }
  if (free_slots_.empty()) {
    admitted_.fetch_sub(1);
    throw HttpError{503, "server", "the server could not warm its kernels: " + warm_error_, 0};
  }
  RenderSlot* slot = free_slots_.back();
  free_slots_.pop_back();
  return std::make_unique<SlotLease>(*this, *slot);
}

void RenderSlots::release(RenderSlot& slot) {
  {
    std::lock_guard lock(mutex_);
    free_slots_.push_back(&slot);
  }
  admitted_.fetch_sub(1);
  slot_freed_.notify_one();
}

void RenderSlots::add_warm(size_t index, const std::string& key, std::unique_ptr<Renderer> renderer) {
  {
    std::lock_guard lock(mutex_);
    slots_[index]->renderers[key] = std::move(renderer);
    free_slots_.push_back(slots_[index].get());
    ready_slots_.fetch_add(1);  // under the lock, before the notification: wait_ready() sees it
  }
  slot_freed_.notify_all();
}

void RenderSlots::record_warm_up_failure(const std::string& message) {
  {
    std::lock_guard lock(mutex_);
    if (ready_slots_.load() == 0) warm_error_ = message;
    failed_slots_.store(threads_ - ready_slots_.load());
  }
  slot_freed_.notify_all();
}

bool RenderSlots::ready() const {
  return ready_slots_.load() > 0 && ready_slots_.load() + failed_slots_.load() == threads_;
}

bool RenderSlots::failed() const {
  std::lock_guard lock(mutex_);
  return !warm_error_.empty();
}

bool RenderSlots::wait_ready(std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  slot_freed_.wait_for(lock, timeout, [&] { return ready() || !warm_error_.empty(); });
  return ready();
}

void RenderSlots::wake_all() { slot_freed_.notify_all(); }

}  // namespace seamcl::server
