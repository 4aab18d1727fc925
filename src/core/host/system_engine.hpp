#pragma once
// The engine of continuous-system bounds (guarantee: system; docs/semantics.md): image enclosures
// of the system map over every cell, per-dimension transition bounds, and the robust Bellman steps
// of the lower and the upper bound through the backward driver, on the host's cores.
#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"
#include "host/backward_driver.hpp"
#include "host/robust_reference.hpp"

namespace amytiss::detail {

/// Lower and upper bounds over the joint interval MDP (the oracle) or the product set. The
/// abstraction's configuration gives the system map (ImageEnclosure) and the sets.
Policy run_system_bounds(const Abstraction& abstraction, AmbiguitySet set, StepReporter& reporter);

}  // namespace amytiss::detail
