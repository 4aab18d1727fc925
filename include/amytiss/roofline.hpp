#pragma once
// The roofline of a phase (for --profile): how fast its multiply-adds could run on a device with
// a given double multiply-add peak and memory bandwidth, and how close the phase came.
#include <string>

namespace amytiss {

/// Which roof bounds a phase: memory when its intensity times the bandwidth is below the peak.
enum class RoofKind { Memory, Compute };
std::string to_string(RoofKind kind);  ///< "memory", "compute"

struct RooflinePoint {
  /// Multiply-adds per operand byte. The operand bytes are an upper bound of the traffic (caches
  /// serve part of it), so this is a lower bound of the true intensity.
  double intensity = 0;
  double roof = 0;              ///< multiply-adds per second: min(peak, intensity x bandwidth)
  RoofKind bound = RoofKind::Compute;
  double achieved = 0;          ///< multiply-adds per second measured
  double fraction_of_roof = 0;  ///< achieved / roof
};

/// The roofline point of a phase of `multiply_adds` over `bytes` operand bytes in `seconds`, on
/// a device of `peak` multiply-adds per second and `bandwidth` bytes per second. Every argument
/// must be positive.
RooflinePoint roofline_point(double peak, double bandwidth, double multiply_adds, double bytes, double seconds);

}  // namespace amytiss
