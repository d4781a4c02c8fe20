#include "memory_bound.h"

#include <algorithm>
#include <cstdio>

#include <unistd.h>

namespace seamcl::server {

MemoryBound::MemoryBound(size_t bound_bytes) : bound_(bound_bytes) {}

size_t MemoryBound::default_bound() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGESIZE);
  const size_t physical = pages > 0 && page > 0 ? static_cast<size_t>(pages) * static_cast<size_t>(page) : size_t{4} << 30;
  return std::max(physical / 2, size_t{256} << 20);
}

size_t MemoryBound::resident_bytes() {
  FILE* file = std::fopen("/proc/self/statm", "r");
  if (!file) return 0;
  unsigned long size = 0, resident = 0;
  const int read = std::fscanf(file, "%lu %lu", &size, &resident);
  std::fclose(file);
  return read == 2 ? static_cast<size_t>(resident) * static_cast<size_t>(::sysconf(_SC_PAGESIZE)) : 0;
}

bool MemoryBound::try_reserve(size_t bytes) {
  std::lock_guard lock(mutex_);
  if (bytes > bound_ || in_flight_ + kept_ > bound_ - bytes) return false;
  in_flight_ += bytes;
  return true;
}

void MemoryBound::release(size_t bytes) {
  std::lock_guard lock(mutex_);
  in_flight_ -= std::min(bytes, in_flight_);
}

void MemoryBound::add_kept(long long delta) {
  std::lock_guard lock(mutex_);
  if (delta < 0) {
    kept_ -= std::min(static_cast<size_t>(-delta), kept_);
  } else {
    kept_ += static_cast<size_t>(delta);
  }
}

size_t MemoryBound::kept() const {
  std::lock_guard lock(mutex_);
  return kept_;
}

size_t MemoryBound::in_flight() const {
  std::lock_guard lock(mutex_);
  return in_flight_;
}

bool MemoryBound::kept_over() const {
  std::lock_guard lock(mutex_);
  return kept_ > bound_ / 2 || kept_ + in_flight_ > bound_;
}

nlohmann::json MemoryBound::to_json() const {
  std::lock_guard lock(mutex_);
  return {{"bound_bytes", bound_},
          {"kept_bytes", kept_},
          {"kept_limit_bytes", bound_ / 2},
          {"in_flight_bytes", in_flight_},
          {"resident_bytes", resident_bytes()}};
}

}  // namespace seamcl::server
