// An allocator whose vectors leave new elements of a trivial type unwritten on resize(), for
// arrays that are filled right after, in parallel: a value-initialising resize() zeroes them on one
// thread first, and its page faults and memset sat on a compare's critical path (docs/performance.md).
#pragma once
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace seamcl {

template <typename T>
class UninitializedAllocator : public std::allocator<T> {
 public:
  template <typename U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  UninitializedAllocator() noexcept = default;
  template <typename U>
  UninitializedAllocator(const UninitializedAllocator<U>&) noexcept {}

  // resize() and the size constructor construct with no arguments: left as the memory was.
  template <typename U>
  void construct(U* at) noexcept(std::is_nothrow_default_constructible_v<U>) {
    static_assert(std::is_trivially_default_constructible_v<U>, "only trivial elements may be left unwritten");
    ::new (static_cast<void*>(at)) U;
  }
  template <typename U, typename... Args>
  void construct(U* at, Args&&... args) {
    ::new (static_cast<void*>(at)) U(std::forward<Args>(args)...);
  }
};

template <typename T, typename U>
bool operator==(const UninitializedAllocator<T>&, const UninitializedAllocator<U>&) noexcept {
  return true;
}

// A vector whose resize() leaves trivial elements unwritten: every element must be written before
// it is read.
template <typename T>
using UninitializedVector = std::vector<T, UninitializedAllocator<T>>;

}  // namespace seamcl
