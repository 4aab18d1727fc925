#include "host/robust_iteration.hpp"

#include <algorithm>
#include <cmath>

#include "amytiss/format.hpp"
#include "amytiss/stopwatch.hpp"

namespace amytiss::detail {
namespace {

// Free cells start at `free_value`, fixed cells hold their role's value.
std::vector<double> start_values(const Abstraction& a, const IntervalStep& step, double free_value) {
  std::vector<double> values(step.roles().size());
  for (std::size_t x = 0; x < values.size(); ++x)
    values[x] = step.roles()[x] == CellRole::Free ? free_value : a.terminal_value(step.roles()[x]);
  return values;
}

double largest_difference(const std::vector<double>& above, const std::vector<double>& below) {
  double largest = 0.0;
  for (std::size_t x = 0; x < above.size(); ++x) largest = std::max(largest, std::fabs(above[x] - below[x]));
  return largest;
}

// Iterates the stationary controller's pessimistic step from 0 while it moves: every iterate is a
// lower bound of what the controller guarantees.
unsigned certify(const Abstraction& a, IntervalStep& lower, const std::vector<std::uint32_t>& controller,
                 std::vector<double>& values) {
  values = start_values(a, lower, 0.0);
  std::vector<double> next(values.size());
  unsigned steps = 0;
  while (steps < kMaxRobustIterations) {
    lower.evaluate(values.data(), next.data(), controller.data());
    ++steps;
    const bool moved = largest_difference(next, values) > lower.resolution();
    for (std::size_t x = 0; x < values.size(); ++x) values[x] = std::max(values[x], next[x]);
    if (!moved) break;
  }
  return steps;
}

}  // namespace

Policy solve_unbounded_bounds(const Abstraction& a, IntervalStep& lower, IntervalStep& upper, const UnboundedRun& run,
                              SynthesisReport& report) {
  const std::size_t n = a.states.size();
  std::vector<double> low = start_values(a, lower, 0.0), high = start_values(a, upper, 1.0);
  std::vector<double> next_low(n), next_high(n);
  std::vector<std::uint32_t> controller(n, 0), unused(n);
  unsigned iterations = 0;
  double gap = largest_difference(high, low);
  const auto start = SteadyClock::now();
  while (gap > a.tolerance && iterations < kMaxRobustIterations) {
    lower.apply(low.data(), next_low.data(), controller.data());
    upper.apply(high.data(), next_high.data(), unused.data());
    ++iterations;
    const bool moved = std::max(largest_difference(next_low, low), largest_difference(next_high, high)) >
                       lower.resolution();
    // The sequences are monotone in exact arithmetic; keeping the better of two sound bounds keeps
    // them so under rounding.
    for (std::size_t x = 0; x < n; ++x) {
      low[x] = std::max(low[x], next_low[x]);
      high[x] = std::min(high[x], next_high[x]);
    }
    gap = largest_difference(high, low);
    if (run.on_iteration) run.on_iteration(iterations, gap);
    if (!moved) break;
  }
  report.phases.push_back({"interval iteration (" + std::to_string(iterations) + " iterations)",
                           seconds_since(start), 0, 0});
  const auto certification_start = SteadyClock::now();
  Policy policy;
  std::vector<double> certified;
  const unsigned steps = certify(a, lower, controller, certified);
  report.phases.push_back({"policy certification (" + std::to_string(steps) + " steps)",
                           seconds_since(certification_start), 0, 0});
  policy.values = certified;
  policy.values.insert(policy.values.end(), certified.begin(), certified.end());
  policy.input_index = controller;
  policy.upper_values = high;
  policy.iterations = iterations;
  policy.gap = largest_difference(high, certified);
  policy.converged = policy.gap <= a.tolerance;
  const std::string summary = "unbounded, continuous-system bounds: " + std::to_string(iterations) +
                              " iterations; the stationary controller guarantees a value within " +
                              format_significant(policy.gap) + " of the upper bound (tolerance " +
                              format_significant(a.tolerance) + ")";
  report.notes.push_back({policy.converged ? NoteSeverity::Info : NoteSeverity::Warning, NoteKind::Convergence,
                          policy.converged ? summary : summary + ": the tolerance was not reached"});
  return policy;
}

}  // namespace amytiss::detail
