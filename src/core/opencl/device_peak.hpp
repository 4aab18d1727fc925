#pragma once
// The double-precision multiply-add peak of an OpenCL device, for --profile's "fraction of peak"
// (internal). OpenCL does not report it: it is derived from what the device reports and a table
// of per-core rates, and the basis says how.
#include <string>

namespace amytiss::detail {

struct DevicePeak {
  double multiply_adds_per_second = 0;  ///< 0 when unknown
  std::string basis;                    ///< how the figure was derived, for the report
};

/// `name`: platform and device name (vendor table lookup); clock in MHz as CL_DEVICE_MAX_CLOCK_FREQUENCY
/// reports it; `native_double_width`: CL_DEVICE_NATIVE_VECTOR_WIDTH_DOUBLE.
DevicePeak double_fma_peak(bool gpu, bool cpu, const std::string& name, unsigned compute_units, unsigned clock_mhz,
                           unsigned native_double_width);

}  // namespace amytiss::detail
