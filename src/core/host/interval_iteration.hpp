#pragma once
// Unbounded specifications (spec.horizon: infinite) by interval iteration (docs/semantics.md,
// "Unbounded horizon"): a lower and an upper value sequence through any engine's Bellman step,
// the attractor precomputations, end-component corrections on the host, and a stationary policy
// whose guaranteed value is certified on the host.
#include <functional>
#include <string>

#include "amytiss/engine.hpp"
#include "host/bellman_step.hpp"

namespace amytiss::detail {

struct UnboundedRun {
  std::string device_label;
  /// Called after each iteration with the iterations done and the largest upper - lower gap;
  /// may throw Cancelled.
  std::function<void(unsigned iterations, double gap)> on_iteration;
};

/// Iterates `step` (any engine's) on both sequences until upper - lower <= a.tolerance on every
/// cell, or until neither moves any more, or kMaxIterations (reachability: with optimistic upper
/// bounds verified on `host`); then certifies the stationary policy with `host` (T_sigma from
/// below). The returned policy holds the certified lower bound, the upper bound, the iterations,
/// the final gap and whether it reached the tolerance (`converged`); report gets the phases and,
/// when the gap is above the tolerance, a Warning note that says so.
Policy solve_unbounded(const Abstraction& a, BellmanStep& step, ReferenceStep& host, const UnboundedRun& run,
                       SynthesisReport& report);

}  // namespace amytiss::detail
