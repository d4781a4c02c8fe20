// The service's process-wide memory bound (ServerOptions::memory_bound_bytes, by default half the
// machine's physical memory). Two figures count against it: the bytes the admitted requests plan
// to use (their JobPlan, reserved while they run) and the bytes the kept caches hold (the render
// slots' Renderers: each keeps a built-in scene packed, on the device and on the host). A request
// that does not fit is answered 503 (Retry-After) after its slot has given back what it keeps,
// least recently used first; the kept caches never hold more than half the bound, so a request
// of up to half of it is always admitted when nothing else runs. /health shows the figures and
// the resident size of the process (which also counts what no one plans: code, kernels, the
// allocator's free lists).
#pragma once
#include <atomic>
#include <cstddef>
#include <mutex>

#include <nlohmann/json.hpp>

namespace seamcl::server {

class MemoryBound {
 public:
  explicit MemoryBound(size_t bound_bytes);

  // Half the physical memory (sysconf), at least 256 MiB.
  static size_t default_bound();
  // This process's resident bytes now (/proc/self/statm); 0 where it cannot be read.
  static size_t resident_bytes();

  size_t bound() const { return bound_; }
  size_t kept_limit() const { return bound_ / 2; }
  // Reserves `bytes` for an admitted request: false (nothing reserved) when what is in flight, what
  // is kept and `bytes` would pass the bound.
  bool try_reserve(size_t bytes);
  void release(size_t bytes);
  // What the kept caches hold changed by `delta` bytes.
  void add_kept(long long delta);
  size_t kept() const;
  size_t in_flight() const;
  // Whether the kept caches should give back: over their half, or over what the bound leaves
  // beside the requests in flight.
  bool kept_over() const;

  // {"bound_bytes", "kept_bytes", "kept_limit_bytes", "in_flight_bytes", "resident_bytes"}
  nlohmann::json to_json() const;

 private:
  const size_t bound_;
  mutable std::mutex mutex_;
  size_t in_flight_ = 0;
  size_t kept_ = 0;
};

// Bytes reserved for one request, given back when it ends.
class MemoryReservation {
 public:
  MemoryReservation() = default;
  MemoryReservation(MemoryBound& bound, size_t bytes) : bound_(&bound), bytes_(bytes) {}
  ~MemoryReservation() {
    if (bound_) bound_->release(bytes_);
  }
  MemoryReservation(const MemoryReservation&) = delete;
  MemoryReservation& operator=(const MemoryReservation&) = delete;

 private:
  MemoryBound* bound_ = nullptr;
  size_t bytes_ = 0;
};

}  // namespace seamcl::server
