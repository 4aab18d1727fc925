#include "amytiss/roofline.hpp"

#include <algorithm>
#include <cassert>

namespace amytiss {

std::string to_string(RoofKind kind) { return kind == RoofKind::Memory ? "memory" : "compute"; }

RooflinePoint roofline_point(double peak, double bandwidth, double multiply_adds, double bytes, double seconds) {
  assert(peak > 0 && bandwidth > 0 && multiply_adds > 0 && bytes > 0 && seconds > 0);
  RooflinePoint point;
  point.intensity = multiply_adds / bytes;
  const double memory_roof = point.intensity * bandwidth;
  point.bound = memory_roof < peak ? RoofKind::Memory : RoofKind::Compute;
  point.roof = std::min(peak, memory_roof);
  point.achieved = multiply_adds / seconds;
  point.fraction_of_roof = point.achieved / point.roof;
  return point;
}

}  // namespace amytiss
