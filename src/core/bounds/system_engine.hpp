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
#include "bounds/row_bounds.hpp"

namespace amytiss::detail {

/// Lower and upper bounds by `method` (Auto: choose_bounds_method()'s choice) on the host's
/// threads, or on one thread when `serial` (device reference). The abstraction's configuration
/// gives the system map (ImageEnclosure) and the sets.
Policy run_system_bounds(const Abstraction& abstraction, BoundsMethod method, bool serial, StepReporter& reporter);

/// The threads the bounds run on: one when `serial` (device reference), else the host's.
unsigned bounds_threads(bool serial);

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

/// Which noise-free state dimensions of `rows` are lattice dimensions (RowBounds::lattice()) and
/// which are not, as a note; empty without noise-free dimensions.
std::string lattice_text(const NoiseModel& noise, const RowBounds& rows);

}  // namespace amytiss::detail
