// Why the loop is sound: both sequences start on their side of the value, the Bellman steps are
// monotone with the value as a fixed point, and keeping the better of two sound values keeps a
// sequence sound under rounding; corrections only tighten by proven bounds.
#include "solve/interval_iteration.hpp"

#include <algorithm>
#include <limits>

#include "amytiss/format.hpp"

namespace amytiss::detail {
namespace {

double largest_gap(const std::vector<double>& lower, const std::vector<double>& upper) {
  double gap = 0;
  for (std::size_t x = 0; x < lower.size(); ++x) gap = std::max(gap, upper[x] - lower[x]);
  return gap;
}

}  // namespace

void iterate(BellmanStep& lower_step, BellmanStep& upper_step, IterationState& state, const IterationOptions& options,
             IterationCorrections* corrections, const IterationProgress& progress) {
  const std::size_t n = state.lower.size();
  const double input_margin = options.input_rule == InputRule::OnGrowth
                                  ? lower_step.resolution()
                                  : -std::numeric_limits<double>::infinity();
  std::vector<std::uint32_t> lower_input(n, 0), upper_input(n, 0);
  std::vector<double> next(n);
  state.gap = largest_gap(state.lower, state.upper);
  state.status = IterationStatus::Converged;
  while (state.gap > options.target_gap) {
    if (state.iterations >= options.max_iterations) {
      state.status = IterationStatus::IterationLimit;
      return;
    }
    bool moved = false;
    double lower_change = 0;
    lower_step.apply(state.lower.data(), next.data(), lower_input.data());
    for (std::size_t x = 0; x < n; ++x) {
      if (next[x] > state.lower[x] + input_margin) state.controller[x] = lower_input[x];
      if (next[x] > state.lower[x]) {
        lower_change = std::max(lower_change, next[x] - state.lower[x]);
        moved = moved || next[x] - state.lower[x] > options.move_threshold;
        state.lower[x] = next[x];
      }
    }
    upper_step.apply(state.upper.data(), next.data(), upper_input.data());
    for (std::size_t x = 0; x < n; ++x)
      if (next[x] < state.upper[x]) {
        moved = moved || state.upper[x] - next[x] > options.move_threshold;
        state.upper[x] = next[x];
      }
    const unsigned iterations = ++state.iterations;
    if (corrections) moved |= corrections->correct(iterations, lower_change, state.lower, state.upper);
    state.gap = largest_gap(state.lower, state.upper);
    if (progress && !progress(iterations, state.gap)) {
      state.status = IterationStatus::Cancelled;
      return;
    }
    if (!moved && (!corrections || corrections->stall_is_final(iterations))) {
      state.status = state.gap > options.target_gap ? IterationStatus::Stalled : IterationStatus::Converged;
      return;
    }
  }
}

Certificate certify(BellmanStep& step, const std::vector<std::uint32_t>& controller, std::vector<double> start,
                    const std::vector<double>& upper, unsigned iterations, const IterationOptions& options) {
  Certificate certificate{std::move(start), 0, 0};
  std::vector<double>& values = certificate.values;
  std::vector<double> next(values.size());
  const unsigned limit = options.certification_steps_base + options.certification_steps_per_iteration * iterations;
  certificate.gap = largest_gap(values, upper);
  while ((!options.certification_gap || certificate.gap > *options.certification_gap) && certificate.steps < limit) {
    step.evaluate(values.data(), next.data(), controller.data());
    bool moved = false;
    for (std::size_t x = 0; x < values.size(); ++x)
      if (next[x] > values[x]) {
        moved = moved || next[x] - values[x] > options.move_threshold;
        values[x] = next[x];
      }
    ++certificate.steps;
    certificate.gap = largest_gap(values, upper);
    if (!moved) break;
  }
  return certificate;
}

Policy stationary_policy(const Abstraction& a, const std::vector<CellRole>& roles, const Certificate& certificate,
                         std::vector<double> upper, std::vector<std::uint32_t> controller, unsigned iterations,
                         const std::string& computed_by) {
  Policy policy;
  policy.states = a.states;
  policy.inputs = a.inputs;
  policy.horizon = 1;
  policy.stationary = true;
  policy.roles = roles;
  policy.computed_by = computed_by;
  policy.config_hash = config_hash(a.config);
  policy.values = certificate.values;
  policy.values.insert(policy.values.end(), certificate.values.begin(), certificate.values.end());
  policy.input_index = std::move(controller);
  policy.upper_values = std::move(upper);
  policy.iterations = iterations;
  policy.gap = certificate.gap;
  policy.converged = certificate.gap <= a.tolerance;
  return policy;
}

EngineNote convergence_note(const std::string& head, double gap, double tolerance) {
  const std::string summary = head + "guarantees a value within " + format_significant(gap) +
                              " of the upper bound (tolerance " + format_significant(tolerance) + ")";
  const bool converged = gap <= tolerance;
  return {converged ? NoteSeverity::Info : NoteSeverity::Warning, NoteKind::Convergence,
          converged ? summary : summary + ": the tolerance was not reached"};
}

}  // namespace amytiss::detail
