// One loop for every engine's time steps; the engines differ only in their BellmanStep.
#include "host/backward_driver.hpp"

#include <algorithm>

#include "amytiss/errors.hpp"
#include "amytiss/resources.hpp"
#include "host/interval_iteration.hpp"
#include "host/reference_step.hpp"
#include "host/robust_iteration.hpp"

namespace amytiss::detail {

StepReporter::StepReporter(const Abstraction& abstraction, const ProgressCallback& progress, SynthesisReport& report)
    : abstraction_(abstraction), progress_(progress), report_(report), start_(SteadyClock::now()),
      steps_start_(start_) {}

void StepReporter::phase(PhaseKind kind, const std::string& name, double seconds, double pairs_per_second,
                         double multiply_adds, double bytes, double memory_bytes) {
  PhaseReport phase;
  phase.kind = kind;
  phase.name = name;
  phase.seconds = seconds;
  phase.pairs_per_second = pairs_per_second;
  phase.multiply_adds = multiply_adds;
  phase.bytes = bytes;
  phase.memory_bytes = memory_bytes;
  report_.phases.push_back(phase);
}

void StepReporter::progress(Phase phase, unsigned done, unsigned total, double remaining) {
  if (progress_ && !progress_({phase, done, total, report_.device, seconds_since(start_), remaining}))
    throw Cancelled();
}

void StepReporter::reached(Phase phase) {
  progress(phase, 0, abstraction_.unbounded ? 0 : abstraction_.horizon, -1);
}

void StepReporter::step_done(unsigned step, double seconds, double multiply_adds, double bytes,
                             double memory_bytes) {
  // A step shorter than the clock's resolution still gets a finite rate.
  constexpr double kShortestStepSeconds = 1e-9;
  phase(PhaseKind::Step, "step " + std::to_string(step), seconds,
        double(abstraction_.pairs()) / std::max(seconds, kShortestStepSeconds), multiply_adds, bytes,
        memory_bytes);
  const unsigned total = abstraction_.horizon, done = total - step;
  progress(done == total ? Phase::Done : Phase::Synthesis, done, total,
           seconds_since(steps_start_) / done * double(total - done));
}

void StepReporter::iteration_done(unsigned iterations) { progress(Phase::Synthesis, iterations, 0, -1); }

void StepReporter::unbounded_done(unsigned iterations) { progress(Phase::Done, iterations, 0, 0); }

Policy terminal_policy(const Abstraction& a, const std::string& computed_by) {
  Policy policy;
  policy.states = a.states;
  policy.inputs = a.inputs;
  policy.horizon = a.horizon;
  policy.roles = a.roles;
  policy.computed_by = computed_by;
  policy.config_hash = config_hash(a.config);
  const std::size_t cells = a.states.size();
  policy.values.assign((std::size_t(a.horizon) + 1) * cells, 0.0);
  policy.input_index.assign(std::size_t(a.horizon) * cells, 0);
  for (std::size_t x = 0; x < cells; ++x)
    policy.values[std::size_t(a.horizon) * cells + x] = a.terminal_value(a.roles[x]);
  return policy;
}

namespace {

Policy run_unbounded(const Abstraction& a, BellmanStep& step, StepReporter& reporter) {
  ReferenceStep host(a);
  unsigned last_iteration = 0;
  const UnboundedRun run{reporter.device(), [&](unsigned iterations, double) {
                           last_iteration = iterations;
                           reporter.iteration_done(iterations);
                         }};
  Policy policy = solve_unbounded(a, step, host, run, reporter.report());
  reporter.unbounded_done(last_iteration);
  return policy;
}

}  // namespace

Policy run_backward(const Abstraction& a, BellmanStep& step, StepReporter& reporter) {
  Policy policy = a.unbounded ? run_unbounded(a, step, reporter) : terminal_policy(a, reporter.device());
  if (!a.unbounded) {
    const std::size_t cells = a.states.size();
    reporter.start_steps();
    for (unsigned k = a.horizon; k-- > 0;) {
      const auto step_start = SteadyClock::now();
      step.apply_resident(&policy.values[std::size_t(k + 1) * cells], &policy.values[std::size_t(k) * cells],
                          &policy.input_index[std::size_t(k) * cells]);
      reporter.step_done(k, seconds_since(step_start), step.multiply_adds(), step.bytes(), step.memory_bytes());
    }
  }
  reporter.report().host_peak_bytes = peak_resident_bytes();
  return policy;
}

Policy run_backward_bounds(const Abstraction& a, IntervalStep& lower, IntervalStep& upper, StepReporter& reporter) {
  const std::size_t cells = a.states.size();
  Policy policy;
  if (a.unbounded) {
    unsigned last_iteration = 0;
    const UnboundedRun run{reporter.device(), [&](unsigned iterations, double) {
                             last_iteration = iterations;
                             reporter.iteration_done(iterations);
                           }};
    policy = solve_unbounded_bounds(a, lower, upper, run, reporter.report());
    policy.horizon = 1;
    policy.stationary = true;
    reporter.unbounded_done(last_iteration);
  } else {
    policy.horizon = a.horizon;
    policy.values.assign((std::size_t(a.horizon) + 1) * cells, 0.0);
    policy.upper_values.assign(policy.values.size(), 0.0);
    policy.input_index.assign(std::size_t(a.horizon) * cells, 0);
    for (std::size_t x = 0; x < cells; ++x) {
      policy.values[std::size_t(a.horizon) * cells + x] = a.terminal_value(lower.roles()[x]);
      policy.upper_values[std::size_t(a.horizon) * cells + x] = a.terminal_value(upper.roles()[x]);
    }
    std::vector<std::uint32_t> upper_inputs(cells);
    reporter.start_steps();
    for (unsigned k = a.horizon; k-- > 0;) {
      const auto step_start = SteadyClock::now();
      lower.apply(&policy.values[std::size_t(k + 1) * cells], &policy.values[std::size_t(k) * cells],
                  &policy.input_index[std::size_t(k) * cells]);
      upper.apply(&policy.upper_values[std::size_t(k + 1) * cells], &policy.upper_values[std::size_t(k) * cells],
                  upper_inputs.data());
      reporter.step_done(k, seconds_since(step_start), 0, 0);
    }
  }
  policy.states = a.states;
  policy.inputs = a.inputs;
  policy.roles = lower.roles();
  policy.guarantee = Guarantee::System;
  policy.computed_by = reporter.device();
  policy.config_hash = config_hash(a.config);
  reporter.report().host_peak_bytes = peak_resident_bytes();
  return policy;
}

}  // namespace amytiss::detail
