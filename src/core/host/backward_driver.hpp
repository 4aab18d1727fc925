#pragma once
// The backward recursion that every engine runs (docs/engine.md, "One backward driver"): an
// engine sets itself up and hands over its Bellman step; run_backward() applies it T_d times
// from V_{T_d} down to V_0 (or runs interval iteration on it for unbounded specifications), and
// StepReporter writes the phase reports and the progress of every engine the same way.
#include <string>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/stopwatch.hpp"
#include "amytiss/synthesis_types.hpp"
#include "host/bellman_step.hpp"
#include "host/interval_step.hpp"

namespace amytiss::detail {

/// Phase reports and progress of one synthesis run. Every progress call may throw Cancelled.
class StepReporter {
 public:
  /// The clock of elapsed_s starts here.
  StepReporter(const Abstraction& abstraction, const ProgressCallback& progress, SynthesisReport& report);
  /// The label that progress and the policy's computed_by carry ("reference", "<platform> / <device>").
  void set_device(const std::string& label) { report_.device = label; }
  const std::string& device() const { return report_.device; }
  SynthesisReport& report() { return report_; }

  /// Appends a phase report (seconds; pairs per second where it applies).
  void phase(PhaseKind kind, const std::string& name, double seconds, double pairs_per_second = 0,
             double multiply_adds = 0, double bytes = 0, double memory_bytes = 0);
  /// Progress at the end of set-up (Phase::Setup) or construction (Phase::Construction).
  void reached(Phase phase);
  /// Starts the clock of the time steps' estimate of the time left.
  void start_steps() { steps_start_ = SteadyClock::now(); }
  /// After time step `step` (counting down from the horizon) that took `seconds` and did
  /// `multiply_adds` over operand `bytes`: its phase report and the progress, Phase::Done after
  /// the last one.
  void step_done(unsigned step, double seconds, double multiply_adds, double bytes, double memory_bytes = 0);
  /// Unbounded specifications: progress after each interval iteration (no total: 0 %), and
  /// Phase::Done at the end.
  void iteration_done(unsigned iterations);
  void unbounded_done(unsigned iterations);

 private:
  void progress(Phase phase, unsigned done, unsigned total, double remaining);
  const Abstraction& abstraction_;
  const ProgressCallback& progress_;
  SynthesisReport& report_;
  SteadyClock::time_point start_, steps_start_;
};

/// The policy arrays of `abstraction` with V_{T_d} (every cell's terminal value) in place and
/// everything else zero.
Policy terminal_policy(const Abstraction& abstraction, const std::string& computed_by);

/// Applies `step` from V_{T_d} down to V_0 (the step's first input is V_{T_d}, each later one the
/// step's previous output: apply_resident), or for unbounded specifications runs interval
/// iteration on it (host/interval_iteration.hpp). Reports every step and the process's peak
/// resident set; the policy's computed_by is the reporter's device.
Policy run_backward(const Abstraction& abstraction, BellmanStep& step, StepReporter& reporter);

/// Continuous-system bounds (guarantee: system): applies `lower` and `upper`, the interval MDP's
/// pessimistic and optimistic steps, together from V_{T_d} (each from its own cell roles) down to
/// V_0, one step report per time step; or for unbounded specifications runs robust interval
/// iteration on them (host/robust_iteration.hpp). The policy's values are the lower bounds, its
/// inputs the lower bound's maximisers, its roles the lower bound's, its upper_values the upper
/// bounds.
Policy run_backward_bounds(const Abstraction& abstraction, IntervalStep& lower, IntervalStep& upper,
                           StepReporter& reporter);

}  // namespace amytiss::detail
