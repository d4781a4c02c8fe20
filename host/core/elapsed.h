// Milliseconds since a steady-clock point: the one way timings in reports and headers are taken.
#pragma once
#include <chrono>

namespace seamcl {

inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace seamcl
