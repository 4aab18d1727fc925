// Runs on the host with the serial step: target cells are few against the Free cells the engines
// sweep, and the choice needs only one row per cell and input.
#include "serial/target_cell_inputs.hpp"

#include <algorithm>
#include <cassert>
#include <cstdint>
#include <thread>
#include <vector>

#include "amytiss/stopwatch.hpp"
#include "serial/reference_step.hpp"

namespace amytiss::detail {

TargetCellInputs choose_target_cell_inputs(const Abstraction& a, Policy& policy) {
  assert(policy.guarantee == Guarantee::Abstraction && policy.roles.size() == a.states.size());
  const auto start = SteadyClock::now();
  std::vector<std::size_t> targets;
  for (std::size_t x = 0; x < policy.roles.size(); ++x)
    if (policy.roles[x] == CellRole::FixedOne) targets.push_back(x);
  if (targets.empty() || a.inputs.size() <= 1) return {targets.size(), 0.0};
  const std::size_t cells = a.states.size();
  const unsigned rows = policy.stationary ? 1 : policy.horizon;
  // One serial step per thread (its scratch is its own); the threads split the target cells.
  const unsigned threads = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), unsigned(targets.size())));
  std::vector<std::thread> team;
  for (unsigned t = 0; t < threads; ++t)
    team.emplace_back([&, t] {
      ReferenceStep step(a);
      for (unsigned k = 0; k < rows; ++k) {
        // Stationary: rows 0 and 1 of values hold the same certified lower bound.
        const double* next = &policy.values[std::size_t(policy.stationary ? 0 : k + 1) * cells];
        double value = 0.0;
        for (std::size_t i = t; i < targets.size(); i += threads)
          policy.input_index[std::size_t(k) * cells + targets[i]] = step.best_input(targets[i], next, &value);
      }
    });
  for (std::thread& member : team) member.join();
  return {targets.size(), seconds_since(start)};
}

}  // namespace amytiss::detail
