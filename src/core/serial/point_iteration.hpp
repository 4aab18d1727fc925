#pragma once
// Unbounded specifications (spec.horizon: infinite) by interval iteration (docs/semantics.md,
// "Unbounded horizon"): a lower and an upper value sequence through any engine's Bellman step,
// the attractor precomputations, end-component corrections on the host, and a stationary policy
// whose guaranteed value is certified on the host.
#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"
#include "solve/bellman_step.hpp"
#include "serial/reference_step.hpp"
#include "solve/backward_driver.hpp"
#include "solve/interval_iteration.hpp"

namespace amytiss::detail {

/// Iterates `step` (any engine's) on both sequences until upper - lower <= a.tolerance on every
/// cell, or until neither moves any more, or kMaxIterations (reachability: with optimistic upper
/// bounds verified on `host`); then certifies the stationary policy with `host` (T_sigma from
/// below). The returned policy holds the certified lower bound, the upper bound, the iterations,
/// the final gap and whether it reached the tolerance (`converged`); report gets the phases and,
/// when the gap is above the tolerance, a Warning note that says so.
Policy solve_unbounded(const Abstraction& a, BellmanStep& step, ReferenceStep& host, const UnboundedRun& run,
                       SynthesisReport& report);

/// The abstraction's backward recursion on any engine's `step` through the backward driver: the
/// finite horizon from the abstraction's roles, unbounded specifications by solve_unbounded().
Policy run_abstraction_backward(const Abstraction& a, BellmanStep& step, StepReporter& reporter);

}  // namespace amytiss::detail
