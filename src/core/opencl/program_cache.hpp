#pragma once
// Building an OpenCL program, through a cache of program binaries. Building from source costs
// ~35-50 ms on pocl even when pocl's own cache holds the compiled kernels (its front end still
// runs); loading our own copy of the program binary costs ~5 ms.
#include <string>
#include <vector>

#include "opencl/device.hpp"

namespace amytiss::detail {

/// Folder of the program binary cache for a requested one: "" (the default,
/// $XDG_CACHE_HOME/amytiss/kernels or ~/.cache/amytiss/kernels), "-" (no cache: returns ""), or
/// the folder itself.
std::string resolved_cache_dir(const std::string& requested);

/// The program of `source` built for `device`: loaded from the cache in `cache_dir` (see
/// resolved_cache_dir) when an entry for this source, device and driver exists, else compiled
/// from source and stored there. A note (KernelBuild) says which. Any failure to read, write or
/// load an entry falls back to building from source; throws DeviceError with the compiler's log
/// when the source does not build.
Program build_program(cl_context context, const DeviceInfo& device, const std::string& source,
                      const std::string& cache_dir, std::vector<EngineNote>& notes);

}  // namespace amytiss::detail
