#include "amytiss/roofline.hpp"

#include <cassert>

namespace amytiss {

std::string to_string(RoofKind kind) {
  switch (kind) {
    case RoofKind::Memory: return "memory";
    case RoofKind::Cache: return "cache";
    case RoofKind::Compute: return "compute";
  }
  return "compute";
}

RooflinePoint roofline_point(const RooflineDevice& device, const RooflineWork& work) {
  assert(device.peak > 0 && device.bandwidth > 0 && work.multiply_adds > 0 && work.operand_bytes > 0 &&
         work.seconds > 0);
  RooflinePoint point;
  point.operand_intensity = work.multiply_adds / work.operand_bytes;
  point.memory_intensity = work.memory_bytes > 0 ? work.multiply_adds / work.memory_bytes : point.operand_intensity;
  point.roof = device.peak;
  point.bound = RoofKind::Compute;
  const double memory_roof = point.memory_intensity * device.bandwidth;
  if (memory_roof < point.roof) {
    point.roof = memory_roof;
    point.bound = RoofKind::Memory;
  }
  if (device.cache_bandwidth > 0 && work.memory_bytes > 0) {
    const double cache_roof = point.operand_intensity * device.cache_bandwidth;
    if (cache_roof < point.roof) {
      point.roof = cache_roof;
      point.bound = RoofKind::Cache;
    }
  }
  point.achieved = work.multiply_adds / work.seconds;
  point.fraction_of_roof = point.achieved / point.roof;
  return point;
}

}  // namespace amytiss
