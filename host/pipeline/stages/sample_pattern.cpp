#include "pipeline/stages/sample_pattern.h"

#include <stdexcept>
#include <string>

namespace seamcl {

const std::vector<SampleOffset>& sample_pattern(int sample_count) {
  // D3D11_STANDARD_MULTISAMPLE_PATTERN (D3D11 functional spec, 3.5.6.1).
  static const std::vector<SampleOffset> one = {{0, 0}};
  static const std::vector<SampleOffset> two = {{4, 4}, {-4, -4}};
  static const std::vector<SampleOffset> four = {{-2, -6}, {6, -2}, {-6, 2}, {2, 6}};
  static const std::vector<SampleOffset> eight = {{1, -3}, {-1, 3}, {5, 1}, {-3, -5}, {-5, 5}, {-7, -1}, {3, 7}, {7, -7}};
  static const std::vector<SampleOffset> sixteen = {{1, 1},   {-1, -3}, {-3, 2}, {4, -1}, {-5, -2}, {2, 5},
                                                    {5, 3},   {3, -5},  {-2, 6}, {0, -7}, {-4, -6}, {-6, 4},
                                                    {-8, 0},  {7, -4},  {6, 7},  {-7, -8}};
  switch (sample_count) {
    case 1: return one;
    case 2: return two;
    case 4: return four;
    case 8: return eight;
    case 16: return sixteen;
    default: throw std::invalid_argument("no standard pattern for " + std::to_string(sample_count) + " samples");
  }
}

}  // namespace seamcl
