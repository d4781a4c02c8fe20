#include "native_array.h"

#include <memory>
#include <stdexcept>
#include <string>

#include <nanobind/ndarray.h>

namespace nb = nanobind;

namespace seamcl::python {
namespace {

template <class Scalar, class Element>
nb::object view_of(std::vector<Element>&& values, std::initializer_list<size_t> shape) {
  size_t count = 1;
  for (size_t side : shape) count *= side;
  if (values.size() * sizeof(Element) != count * sizeof(Scalar))
    throw std::logic_error("an array of " + std::to_string(values.size()) + " elements does not fill its shape");
  auto holder = std::make_unique<std::vector<Element>>(std::move(values));
  Scalar* data = reinterpret_cast<Scalar*>(holder->data());
  nb::capsule owner(holder.get(), [](void* p) noexcept { delete static_cast<std::vector<Element>*>(p); });
  holder.release();  // the capsule owns it now
  return nb::ndarray<nb::numpy, Scalar>(data, shape, owner).cast();
}

}  // namespace

nb::object rgba_array(std::vector<glm::vec4>&& pixels, int width, int height) {
  static_assert(sizeof(glm::vec4) == 4 * sizeof(float), "glm::vec4 is four packed floats");
  return view_of<float>(std::move(pixels), {static_cast<size_t>(height), static_cast<size_t>(width), 4});
}

nb::object float_array(std::vector<float>&& values, int width, int height) {
  return view_of<float>(std::move(values), {static_cast<size_t>(height), static_cast<size_t>(width)});
}

nb::object byte_array(std::vector<uint8_t>&& values, int width, int height) {
  return view_of<uint8_t>(std::move(values), {static_cast<size_t>(height), static_cast<size_t>(width)});
}

}  // namespace seamcl::python
