#pragma once
// The dense sweep over a team of devices and ranks (internal, docs/scale_out.md).
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "solve/backward_driver.hpp"
#include "opencl/engine_options.hpp"
#include "scale_out/team.hpp"

namespace amytiss::detail {

/// Device i of rank r constructs and sweeps its contiguous slice of the states; after every step
/// the new values (and inputs) of every slice go to every device. Bit-identical to one device.
Policy run_dense_team(const Abstraction& abstraction, Team& team, const ComputeConfig& compute,
                      const OpenClEngineOptions& engine_options, StepReporter& reporter);
/// The dense sweep's split, memory per device and exchange per step, without computing.
std::vector<std::string> describe_dense_team(const Abstraction& abstraction, Team& team, const ComputeConfig& compute);

}  // namespace amytiss::detail
