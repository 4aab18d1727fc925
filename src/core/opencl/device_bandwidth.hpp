#pragma once
// The memory bandwidth of an OpenCL device, measured with a copy kernel, for --profile's
// roofline (internal). Measured once per device and driver, then read from a small text file in
// the program binary cache's folder.
#include <string>

#include "opencl/device.hpp"

namespace amytiss::detail {

struct DeviceBandwidth {
  double bytes_per_second = 0;  ///< memory: bytes read plus bytes written per second; 0 when unknown
  std::string basis;            ///< how the figure was measured (and whether it came from the cache)
  /// Cache: bytes read per second from a buffer that fits a CPU core's L2 (a GPU's L1 or L2).
  double cache_bytes_per_second = 0;
  std::string cache_basis;
};

/// Bytes of each of the copy's two buffers on `device`: 128 MiB, less when the device's largest
/// allocation or an eighth of its global memory is smaller (never below 1 MiB).
std::size_t copy_buffer_bytes(const DeviceInfo& device);

/// The device's copy bandwidth: best of a few copies of one double buffer into another, and its
/// cache read bandwidth: best of a few launches that read a small buffer many times; or the
/// figures cached for this device and driver in `cache_dir` (as build_program's: "" default, "-"
/// no cache). Throws DeviceError when the device fails the copy.
DeviceBandwidth measured_copy_bandwidth(const DeviceInfo& device, const DeviceSession& session,
                                        const std::string& cache_dir);

}  // namespace amytiss::detail
