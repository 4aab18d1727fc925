#pragma once
// Unbounded specifications under guarantee: system (docs/semantics.md, "Unbounded horizon"):
// interval iteration on the robust operators of the interval MDP. The lower sequence starts at 0
// on Free cells and the upper at 1; both are sound at every iteration (the operators are monotone
// and the continuous system's value is a fixed point between them). The stationary controller is
// then certified from below.
#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"
#include "host/interval_iteration.hpp"
#include "host/interval_step.hpp"

namespace amytiss::detail {

/// At most this many iterations of each sequence, and of the certification.
constexpr unsigned kMaxRobustIterations = 10000;

/// Iterates `lower` and `upper` until upper - lower <= a.tolerance on every cell, until neither
/// moves by more than their resolution, or kMaxRobustIterations; certifies the stationary
/// controller (the last lower step's maximiser) by iterating its pessimistic step from 0. The
/// policy holds the certified lower bound, the upper bound, the iterations, the gap and whether it
/// reached the tolerance; report gets the phases and a Convergence note (Warning when the gap
/// stays above the tolerance).
Policy solve_unbounded_bounds(const Abstraction& a, IntervalStep& lower, IntervalStep& upper,
                              const UnboundedRun& run, SynthesisReport& report);

}  // namespace amytiss::detail
