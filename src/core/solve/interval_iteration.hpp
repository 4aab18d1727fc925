#pragma once
// The one interval-iteration loop of unbounded specifications (docs/semantics.md, "Unbounded
// horizon"), for the abstraction's point MDP and for the interval MDP's bounds alike: a lower and
// an upper value sequence through Bellman steps until their gap closes, then the stationary
// controller's own value iterated from below (its certificate). What differs between the two
// problems is passed in: the options (limits and stopping rule), the start values and, for the
// point MDP, the end-component corrections.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"
#include "solve/bellman_step.hpp"

namespace amytiss::detail {

/// Which input the stationary controller keeps for a cell after a lower step.
enum class InputRule {
  LastStep,  ///< the last lower step's maximiser
  OnGrowth,  ///< the maximiser of the last lower step that raised the cell's value by more than
             ///< the step's resolution (an input merely as good makes no progress)
};

/// Limits and stopping rule of one interval iteration and its certification.
struct IterationOptions {
  unsigned max_iterations = 0;
  /// The iteration stops once upper - lower <= target_gap on every cell.
  double target_gap = 0;
  /// A value moves when it improves by more than this; nothing moved: the iteration stalled.
  double move_threshold = 0;
  InputRule input_rule = InputRule::LastStep;
  /// The certification takes at most certification_steps_base + certification_steps_per_iteration
  /// * iterations steps ...
  unsigned certification_steps_base = 0, certification_steps_per_iteration = 0;
  /// ... and stops once upper - certified <= this on every cell (none: only when it stops moving).
  std::optional<double> certification_gap;
};

enum class IterationStatus { Converged, IterationLimit, Stalled, Cancelled };

/// Tightenings of the two sequences between iterations (the point MDP's end components).
class IterationCorrections {
 public:
  virtual ~IterationCorrections() = default;
  /// After iteration `iterations`, in which the lower sequence grew by at most `lower_change`:
  /// raises `lower` and lowers `upper` where it can prove it; true where it changed any.
  virtual bool correct(unsigned iterations, double lower_change, std::vector<double>& lower,
                       std::vector<double>& upper) = 0;
  /// Whether a stall at iteration `iterations` is final (no correction is due later).
  virtual bool stall_is_final(unsigned iterations) const = 0;
};

/// The two sequences and the stationary controller between iterations.
struct IterationState {
  std::vector<double> lower, upper;
  std::vector<std::uint32_t> controller;
  unsigned iterations = 0;
  double gap = 0;  ///< largest upper - lower
  IterationStatus status = IterationStatus::Converged;
};

/// Called after each iteration with the iterations done and the gap; false cancels the run.
using IterationProgress = std::function<bool(unsigned iterations, double gap)>;

/// Where an unbounded run reports: the label of its device and its progress.
struct UnboundedRun {
  std::string device_label;
  IterationProgress on_iteration;
};

/// Iterates `lower_step` on state.lower and `upper_step` on state.upper (the same step twice for
/// the point MDP), keeping the better of the old and the new value of each (the sequences are
/// monotone in exact arithmetic, so both stay sound under rounding), until the status is decided.
/// `corrections` may be null.
void iterate(BellmanStep& lower_step, BellmanStep& upper_step, IterationState& state, const IterationOptions& options,
             IterationCorrections* corrections, const IterationProgress& progress);

struct Certificate {
  std::vector<double> values;  ///< the stationary controller's value, from below
  unsigned steps = 0;
  double gap = 0;  ///< largest upper - certified value
};

/// Iterates step.evaluate() for `controller` from `start` (values below the controller's) while
/// it moves, within the options' certification limits for `iterations` iterations.
Certificate certify(BellmanStep& step, const std::vector<std::uint32_t>& controller, std::vector<double> start,
                    const std::vector<double>& upper, unsigned iterations, const IterationOptions& options);

/// The stationary policy of an unbounded run: values (twice: V_0 and the terminal row) the
/// certificate, upper_values `upper`, converged when certificate.gap <= tolerance; grids, roles,
/// label and hash from `a` and `roles`.
Policy stationary_policy(const Abstraction& a, const std::vector<CellRole>& roles, const Certificate& certificate,
                         std::vector<double> upper, std::vector<std::uint32_t> controller, unsigned iterations,
                         const std::string& computed_by);

/// `head` + "guarantees a value within <gap> of the upper bound (tolerance <t>)",
/// and ": the tolerance was not reached" when the gap is above it: the closing Convergence note's
/// end, Info or Warning.
EngineNote convergence_note(const std::string& head, double gap, double tolerance);

}  // namespace amytiss::detail
