#include "opencl/device_peak.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace amytiss::detail {
namespace {

std::string lowercase(std::string text) {
  for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// Double-precision FMA units per streaming multiprocessor (NVIDIA's data sheets: H100 34 TFLOP/s
// = 132 SMs x 1.98 GHz x 64 x 2; A100 9.7 = 108 x 1.41 x 32 x 2; V100 7.8 = 80 x 1.53 x 32 x 2).
// Other NVIDIA GPUs run double at 1/32 or 1/64 of float: 2 per SM.
unsigned nvidia_fp64_units_per_sm(const std::string& name) {
  for (const char* full_rate : {"h100", "h200", "gh200", "h800"})
    if (name.find(full_rate) != std::string::npos) return 64;
  for (const char* half_rate : {"a100", "a800", "a30", "v100", "p100"})
    if (name.find(half_rate) != std::string::npos) return 32;
  return 2;
}

}  // namespace

DevicePeak double_fma_peak(bool gpu, bool cpu, const std::string& name, unsigned compute_units, unsigned clock_mhz,
                           unsigned native_double_width) {
  DevicePeak peak;
  char basis[256];
  if (clock_mhz == 0 || compute_units == 0) {
    peak.basis = "unknown (the device reports no clock or no compute units)";
    return peak;
  }
  const std::string lower = lowercase(name);
  if (gpu && lower.find("nvidia") != std::string::npos) {
    const unsigned units = nvidia_fp64_units_per_sm(lower);
    peak.multiply_adds_per_second = double(compute_units) * units * clock_mhz * 1e6;
    std::snprintf(basis, sizeof basis, "%u SMs x %u FP64 FMA/clock x %u MHz (NVIDIA data-sheet rate)",
                  compute_units, units, clock_mhz);
  } else if (cpu) {
    // Two FMA pipes per core (Haswell and later, Zen and later), each native_double_width lanes;
    // pocl's "pthread-haswell" device is compiled for AVX2 (4 double lanes) whatever it reports.
    unsigned lanes = std::max(1u, native_double_width);
    if (lower.find("haswell") != std::string::npos) lanes = std::min(lanes, 4u);
    peak.multiply_adds_per_second = double(compute_units) * 2.0 * lanes * clock_mhz * 1e6;
    std::snprintf(basis, sizeof basis, "%u cores x 2 FMA pipes x %u double lanes x %u MHz (assumed 2 pipes)",
                  compute_units, lanes, clock_mhz);
  } else {
    peak.basis = "unknown (no rate table for this device)";
    return peak;
  }
  peak.basis = basis;
  return peak;
}

}  // namespace amytiss::detail
