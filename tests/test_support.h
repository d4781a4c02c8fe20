// What several test files share: one OpenCL runtime per test process, and uniform random floats
// that do not depend on the standard library's distribution implementation.
#pragma once
#include <random>

#include <seamcl/cl/cl_runtime.h>

namespace seamcl_tests {

inline seamcl::ClRuntime& shared_runtime() {
  static seamcl::ClRuntime runtime;
  return runtime;
}

// Uniform in [lo, hi] on a grid of 1e6 steps.
inline float uniform(std::mt19937& rng, float lo, float hi) {
  return lo + (hi - lo) * static_cast<float>(rng() % 1000001u) / 1000000.0f;
}

}  // namespace seamcl_tests
