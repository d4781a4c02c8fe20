#include <seamcl/options/displacement_method.h>

#include <array>
#include <utility>

#include <seamcl/kernels/seamcl_types.h>

namespace seamcl {
namespace {

constexpr std::array<std::pair<DisplacementMethod, const char*>, 5> kNames{{{DisplacementMethod::Naive, "naive"},
                                                                           {DisplacementMethod::Zipper, "zipper"},
                                                                           {DisplacementMethod::Ownership, "ownership"},
                                                                           {DisplacementMethod::Fixed, "fixed"},
                                                                           {DisplacementMethod::PtexFilter, "ptex-filter"}}};

}  // namespace

std::optional<DisplacementMethod> parse_displacement_method(std::string_view name) {
  for (const auto& [value, text] : kNames) {
    if (name == text) return value;
  }
  return std::nullopt;
}

std::string to_string(DisplacementMethod method) {
  for (const auto& [value, text] : kNames) {
    if (value == method) return text;
  }
  return "?";
}

std::vector<std::string> displacement_method_names() {
  std::vector<std::string> out;
  for (const auto& entry : kNames) out.emplace_back(entry.second);
  return out;
}

int displacement_method_code(DisplacementMethod method) {
  switch (method) {
    case DisplacementMethod::Naive: return SEAMCL_DISPLACEMENT_NAIVE;
    case DisplacementMethod::Zipper: return SEAMCL_DISPLACEMENT_ZIPPER;
    case DisplacementMethod::Ownership: return SEAMCL_DISPLACEMENT_OWNERSHIP;
    case DisplacementMethod::Fixed: return SEAMCL_DISPLACEMENT_FIXED;
    case DisplacementMethod::PtexFilter: return SEAMCL_DISPLACEMENT_PTEX_FILTER;
  }
  return SEAMCL_DISPLACEMENT_NAIVE;
}

}  // namespace seamcl
