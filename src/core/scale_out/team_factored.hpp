#pragma once
// The factored sweep over a team of devices and ranks (internal, docs/scale_out.md).
#include <cstdint>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "solve/backward_driver.hpp"
#include "opencl/engine_options.hpp"
#include "factored/factored_plan.hpp"
#include "scale_out/team.hpp"

namespace amytiss::detail {

/// How a stage's output entries are split: in `parts` contiguous parts of `entries` each. By the
/// major output digit when it has at least as many values as there are devices (then a stage
/// split by the same variable digit next reads only the part its device computed, and no
/// exchange is needed between them); else by every digit before the vector digit (a part is then
/// still a contiguous range of work-items whatever the device's stage shape); parts 1: not split,
/// every device computes the whole stage (its vector digit is the major one).
struct StageParts {
  std::uint64_t parts = 1, entries = 0;
  bool by_major_digit = false;
};
StageParts stage_parts(const FactoredStage& stage, std::size_t devices);
/// Whether the output of stage `k` must be exchanged before stage k + 1 runs.
bool exchange_after(const FactoredPlan& plan, const std::vector<StageParts>& parts, std::size_t k);

/// Every stage's output entries (and the input choice's states) split in contiguous ranges, each
/// device's part exchanged where the next stage needs it. Bit-identical to one device.
Policy run_factored_team(const Abstraction& abstraction, const FactoredPlan& plan, Team& team,
                         const OpenClEngineOptions& engine_options, StepReporter& reporter);
/// The factored sweep's split and exchange per step, without computing.
std::vector<std::string> describe_factored_team(const Abstraction& abstraction, const FactoredPlan& plan, Team& team);

}  // namespace amytiss::detail
