#include "bounds/robust_iteration.hpp"

#include "amytiss/errors.hpp"
#include "amytiss/format.hpp"
#include "amytiss/stopwatch.hpp"

namespace amytiss::detail {
namespace {

// At most this many iterations of each sequence, and of the certification.
constexpr unsigned kMaxRobustIterations = 10000;

// Free cells start at `free_value`, fixed cells hold their role's value.
std::vector<double> start_values(const Abstraction& a, const std::vector<CellRole>& roles, double free_value) {
  std::vector<double> values(roles.size());
  for (std::size_t x = 0; x < values.size(); ++x)
    values[x] = roles[x] == CellRole::Free ? free_value : a.terminal_value(roles[x]);
  return values;
}

}  // namespace

IterationOptions robust_iteration_options(const Abstraction& a, double resolution) {
  IterationOptions options;
  options.max_iterations = kMaxRobustIterations;
  options.target_gap = a.tolerance;
  options.move_threshold = resolution;
  options.input_rule = InputRule::LastStep;
  options.certification_steps_base = kMaxRobustIterations;
  options.certification_steps_per_iteration = 0;
  return options;
}

Policy solve_unbounded_bounds(const Abstraction& a, BellmanStep& lower, const std::vector<CellRole>& lower_roles,
                              BellmanStep& upper, const std::vector<CellRole>& upper_roles, const UnboundedRun& run,
                              SynthesisReport& report) {
  const IterationOptions options = robust_iteration_options(a, lower.resolution());
  IterationState state;
  state.lower = start_values(a, lower_roles, 0.0);
  state.upper = start_values(a, upper_roles, 1.0);
  state.controller.assign(state.lower.size(), 0);
  const auto start = SteadyClock::now();
  iterate(lower, upper, state, options, nullptr, run.on_iteration);
  if (state.status == IterationStatus::Cancelled) throw Cancelled();
  report.phases.push_back({"interval iteration (" + std::to_string(state.iterations) + " iterations)",
                           seconds_since(start), 0, (lower.multiply_adds() + upper.multiply_adds()) * state.iterations});
  const auto certification_start = SteadyClock::now();
  const Certificate certificate =
      certify(lower, state.controller, start_values(a, lower_roles, 0.0), state.upper, state.iterations, options);
  report.phases.push_back({"policy certification (" + std::to_string(certificate.steps) + " steps)",
                           seconds_since(certification_start), 0, 0});
  report.notes.push_back(convergence_note("unbounded, continuous-system bounds: " + std::to_string(state.iterations) +
                                              " iterations; the stationary controller ",
                                          certificate.gap, a.tolerance));
  Policy policy = stationary_policy(a, lower_roles, certificate, state.upper, state.controller, state.iterations,
                                    run.device_label);
  policy.guarantee = Guarantee::System;
  return policy;
}

}  // namespace amytiss::detail
