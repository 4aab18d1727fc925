#pragma once
// The roofline of a phase (for --profile): how fast its multiply-adds could run on a device with
// a given double multiply-add peak, memory bandwidth and cache bandwidth, and how close the phase
// came.
#include <string>

namespace amytiss {

/// Which roof bounds a phase: the lowest of compute (the peak), memory (the bytes the phase must
/// move at the memory bandwidth) and cache (the operands it loads at the cache bandwidth).
enum class RoofKind { Memory, Cache, Compute };
std::string to_string(RoofKind kind);  ///< "memory", "cache", "compute"

/// What the roofline knows of a device (per second; a bandwidth of 0: unknown).
struct RooflineDevice {
  double peak = 0;             ///< multiply-adds
  double bandwidth = 0;        ///< memory: bytes read plus bytes written
  double cache_bandwidth = 0;  ///< cache: bytes read (0: no cache roof)
};

/// What a phase did: multiply-adds in seconds over operand bytes (what its kernels load and
/// store) and memory bytes (what it must move at least: its tensors once; 0 when not counted,
/// then the memory roof takes the operand bytes, an upper bound of the traffic).
struct RooflineWork {
  double multiply_adds = 0;
  double operand_bytes = 0;
  double memory_bytes = 0;
  double seconds = 0;
};

struct RooflinePoint {
  double memory_intensity = 0;   ///< multiply-adds per memory byte (operand byte when not counted)
  double operand_intensity = 0;  ///< multiply-adds per operand byte
  double roof = 0;               ///< multiply-adds per second: the lowest roof
  RoofKind bound = RoofKind::Compute;
  double achieved = 0;           ///< multiply-adds per second measured
  double fraction_of_roof = 0;   ///< achieved / roof
};

/// The roofline point of `work` on `device`. Peak, bandwidth, multiply-adds, operand bytes and
/// seconds must be positive. The cache roof applies where both the cache bandwidth and the memory
/// bytes are known; ties go to compute, then memory.
RooflinePoint roofline_point(const RooflineDevice& device, const RooflineWork& work);

}  // namespace amytiss
