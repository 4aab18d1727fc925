#pragma once
// The engine of continuous-system bounds (guarantee: system; docs/semantics.md): image enclosures
// of the system map over every cell, per-dimension transition bounds, and the robust Bellman steps
// of the lower and the upper bound through the backward driver, on the host's cores.
#include <string>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "solve/backward_driver.hpp"
#include "bounds/cell_roles.hpp"

namespace amytiss::detail {

/// Lower and upper bounds by `method` (Auto: choose_bounds_method()'s choice) on the host's
/// threads, or on one thread when `serial` (device reference). The abstraction's configuration
/// gives the system map (ImageEnclosure) and the sets.
Policy run_system_bounds(const Abstraction& abstraction, BoundsMethod method, bool serial, StepReporter& reporter);

/// Reach specifications: "891 of 60125 cells lie wholly inside the target (the lower bound's target
/// cells)"; with none, also that the lower bound is then 0 everywhere and how to draw the target.
/// Empty for safety. `lower_roles`: robust_cell_roles() of the lower bound.
std::string lower_targets_text(const std::vector<CellRole>& lower_roles, SpecType spec);

}  // namespace amytiss::detail
