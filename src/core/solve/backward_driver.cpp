// One loop for every engine's time steps; the engines differ only in their BellmanStep.
#include "solve/backward_driver.hpp"

#include <algorithm>

#include "amytiss/errors.hpp"
#include "amytiss/resources.hpp"

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

namespace {

// The finite horizon's policy arrays with V_{T_d} (every cell's terminal value) in place.
Policy terminal_policy(const Abstraction& a, const ValueSequence& lower, const ValueSequence* upper,
                       const std::string& computed_by) {
  Policy policy;
  policy.states = a.states;
  policy.inputs = a.inputs;
  policy.horizon = a.horizon;
  policy.roles = lower.roles;
  policy.computed_by = computed_by;
  policy.config_hash = config_hash(a.config);
  const std::size_t cells = a.states.size(), last = std::size_t(a.horizon) * cells;
  policy.values.assign(last + cells, 0.0);
  policy.input_index.assign(last, 0);
  for (std::size_t x = 0; x < cells; ++x) policy.values[last + x] = a.terminal_value(lower.roles[x]);
  if (upper) {
    policy.guarantee = Guarantee::System;
    policy.upper_values.assign(policy.values.size(), 0.0);
    for (std::size_t x = 0; x < cells; ++x) policy.upper_values[last + x] = a.terminal_value(upper->roles[x]);
  }
  return policy;
}

Policy run_unbounded(const UnboundedSolver& unbounded, StepReporter& reporter) {
  unsigned last_iteration = 0;
  const UnboundedRun run{reporter.device(), [&](unsigned iterations, double) {
                           last_iteration = iterations;
                           try {
                             reporter.iteration_done(iterations);
                           } catch (const Cancelled&) {
                             return false;
                           }
                           return true;
                         }};
  Policy policy = unbounded(run, reporter.report());
  reporter.unbounded_done(last_iteration);
  return policy;
}

}  // namespace

Policy run_backward(const Abstraction& a, ValueSequence lower, const ValueSequence* upper,
                    const UnboundedSolver& unbounded, StepReporter& reporter) {
  if (a.unbounded) {
    Policy policy = run_unbounded(unbounded, reporter);
    reporter.report().host_peak_bytes = peak_resident_bytes();
    return policy;
  }
  Policy policy = terminal_policy(a, lower, upper, reporter.device());
  const std::size_t cells = a.states.size();
  std::vector<std::uint32_t> upper_inputs(upper ? cells : 0);
  reporter.start_steps();
  for (unsigned k = a.horizon; k-- > 0;) {
    const auto step_start = SteadyClock::now();
    const std::size_t now = std::size_t(k) * cells, next = now + cells;
    lower.step.apply_resident(&policy.values[next], &policy.values[now], &policy.input_index[now]);
    double multiply_adds = lower.step.multiply_adds(), bytes = lower.step.bytes();
    double memory_bytes = lower.step.memory_bytes();
    if (upper) {
      upper->step.apply_resident(&policy.upper_values[next], &policy.upper_values[now], upper_inputs.data());
      multiply_adds += upper->step.multiply_adds();
      bytes += upper->step.bytes();
      memory_bytes += upper->step.memory_bytes();
    }
    reporter.step_done(k, seconds_since(step_start), multiply_adds, bytes, memory_bytes);
  }
  reporter.report().host_peak_bytes = peak_resident_bytes();
  return policy;
}

}  // namespace amytiss::detail
