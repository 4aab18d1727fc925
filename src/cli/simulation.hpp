#pragma once
// amytiss_synth's --simulate: Monte Carlo episodes of the continuous closed loop (closed_loop.hpp)
// from the cell of --at's state, their success rate printed beside the policy's values there
// (docs/cli.md).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "amytiss/closed_loop.hpp"
#include "amytiss/config.hpp"
#include "amytiss/policy.hpp"

namespace amytiss::cli {

/// How many standard errors a rate may lie beyond a bound and still be called consistent.
constexpr double kConsistencyStandardErrors = 4.0;

/// Runs `episodes` episodes (seed `seed`) from uniform points of the cell of `state` under the
/// policy and prints the rate, its standard error, the policy's values of that cell at step 0 with
/// the gaps, and how the episodes ended. The state must lie in the grid.
void print_simulation(const Config& config, const Policy& policy, const std::vector<double>& state,
                      std::size_t episodes, std::uint64_t seed);

}  // namespace amytiss::cli
