#pragma once
// The OpenCL engine on one device (internal): the device set up, then the dense sweep
// (opencl/run.hpp) or the factored sweep (opencl/factored/sweep.hpp) run by the backward driver.
// Which device and which sweep is the synthesis plan's decision (plan.hpp).
#include <optional>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"
#include "solve/backward_driver.hpp"
#include "opencl/device.hpp"
#include "opencl/engine_options.hpp"
#include "factored/factored_plan.hpp"

namespace amytiss::detail {

/// Runs the synthesis on `device` with the factored sweep when `factored` holds a plan, else the
/// dense sweep; reports the device set-up, kernel build, construction and every step.
Policy run_on_device(const Abstraction& abstraction, const DeviceInfo& device,
                     const std::optional<FactoredPlan>& factored, const SynthesisOptions& options,
                     const OpenClEngineOptions& engine_options, StepReporter& reporter);

}  // namespace amytiss::detail
