#pragma once
// The backward recursion that every engine runs (docs/engine.md, "One backward driver"): an
// engine sets itself up and hands over its Bellman step (two for continuous-system bounds: the
// lower and the upper bound's); run_backward() applies them T_d times from V_{T_d} down to V_0,
// or hands an unbounded specification to the engine's interval iteration, and StepReporter
// writes the phase reports and the progress of every engine the same way.
#include <functional>
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "amytiss/stopwatch.hpp"
#include "amytiss/synthesis_types.hpp"
#include "solve/bellman_step.hpp"
#include "solve/interval_iteration.hpp"

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

/// One value sequence of the backward recursion: its Bellman step and the cell roles that give
/// its terminal values V_{T_d}.
struct ValueSequence {
  BellmanStep& step;
  const std::vector<CellRole>& roles;
};

/// How the engine solves an unbounded specification (the point MDP's or the interval MDP's
/// interval iteration, solve/interval_iteration.hpp); it may throw Cancelled.
using UnboundedSolver = std::function<Policy(const UnboundedRun& run, SynthesisReport& report)>;

/// Applies `lower`, and `upper` where not null, from V_{T_d} down to V_0 (each step's first input
/// is V_{T_d}, each later one its previous output: apply_resident), one step report per time step;
/// or, for unbounded specifications, runs `unbounded` with the reporter's progress. The policy's
/// values are `lower`'s, its inputs `lower`'s maximisers, its roles `lower`'s; with `upper`, its
/// upper_values are `upper`'s and its guarantee is System. Records the process's peak resident set;
/// the policy's computed_by is the reporter's device.
Policy run_backward(const Abstraction& abstraction, ValueSequence lower, const ValueSequence* upper,
                    const UnboundedSolver& unbounded, StepReporter& reporter);

}  // namespace amytiss::detail
