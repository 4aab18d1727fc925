#pragma once
// The engine of continuous-system bounds (guarantee: system; docs/semantics.md): image enclosures
// of the system map over every cell, per-dimension transition bounds, and the robust Bellman steps
// of the lower and the upper bound through the backward driver, on the host's cores.
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "host/backward_driver.hpp"
#include "host/robust_reference.hpp"

namespace amytiss::detail {

/// Lower and upper bounds over the joint interval MDP (the oracle) or the product set. The
/// abstraction's configuration gives the system map (ImageEnclosure) and the sets.
Policy run_system_bounds(const Abstraction& abstraction, AmbiguitySet set, StepReporter& reporter);

/// What the lower bound's roles (`lower_roles`: robust_cell_roles()) leave it. Reach
/// specifications: "891 of 60125 cells lie wholly inside the target (the lower bound's target
/// cells)". Safety: empty while some cell is kept. With no cell (the lower bound 0 everywhere, a
/// warning), why: no cell lies wholly inside the set (how to draw it), or every cell inside it is
/// avoided (it meets spec.avoid, or the footprint may touch an obstacle).
struct RolesText {
  std::string text;
  bool warning = false;
};
RolesText lower_roles_text(const Grid& states, const SpecConfig& spec, const std::vector<CellRole>& lower_roles);

}  // namespace amytiss::detail
