#pragma once
// Unbounded specifications under guarantee: system (docs/semantics.md, "Unbounded horizon"):
// the one interval-iteration loop (solve/interval_iteration.hpp) on the robust steps of the
// interval MDP. The lower sequence starts at 0 on Free cells and the upper at 1; both are sound at
// every iteration (the steps are monotone and the continuous system's value is a fixed point
// between them). The stationary controller is then certified from below.
#include <vector>

#include "amytiss/policy.hpp"
#include "amytiss/synthesis_types.hpp"
#include "solve/bellman_step.hpp"
#include "solve/interval_iteration.hpp"

namespace amytiss::detail {

/// The robust iteration's limits: at most kMaxRobustIterations iterations of the sequences and
/// as many certification steps, stopping at a.tolerance, a value moving when it changes by more
/// than the steps' `resolution`.
IterationOptions robust_iteration_options(const Abstraction& a, double resolution);

/// Iterates `lower` and `upper` (each with its bound's cell roles) until upper - lower <=
/// a.tolerance on every cell, until neither moves, or the iteration limit; certifies the
/// stationary controller (the last lower step's maximiser) by iterating its pessimistic step from
/// 0. The policy holds the certified lower bound, the upper bound, the iterations, the gap and
/// whether it reached the tolerance; report gets the phases and a Convergence note (Warning when
/// the gap stays above the tolerance). Throws Cancelled when run.on_iteration says so.
Policy solve_unbounded_bounds(const Abstraction& a, BellmanStep& lower, const std::vector<CellRole>& lower_roles,
                              BellmanStep& upper, const std::vector<CellRole>& upper_roles, const UnboundedRun& run,
                              SynthesisReport& report);

}  // namespace amytiss::detail
