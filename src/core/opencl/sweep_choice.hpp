#pragma once
// What the OpenCL engines can run, and which sweep (dense or factored) a problem gets on a
// device: decisions of the synthesis plan (plan.hpp), made before any device work.
#include <optional>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/synthesis_types.hpp"
#include "opencl/device.hpp"
#include "factored/factored_plan.hpp"
#include "opencl/layout.hpp"

namespace amytiss::detail {

/// ConfigError when no OpenCL engine can run the problem (full covariance, 2^32 state cells).
void check_opencl_supported(const Abstraction& abstraction);
/// The dense sweep's limit on the padded value array (ConfigError).
void check_dense_supported(const Layout& layout);
/// The factored plan when compute.sweep asks for it or it saves enough work (nullopt: dense),
/// for a device of `device`'s memory and allocation limit; a Sweep note says which and why. A
/// request that cannot be honoured is a ConfigError naming compute.sweep (or the noise law).
std::optional<FactoredPlan> choose_sweep(const Abstraction& abstraction, const DeviceInfo& device,
                                         const ComputeConfig& compute, std::vector<EngineNote>& notes);

}  // namespace amytiss::detail
