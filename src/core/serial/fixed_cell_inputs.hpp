#pragma once
// The inputs the abstraction's controller applies in its fixed cells (target, avoid).
#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"

namespace amytiss::detail {

/// Gives every fixed cell of an abstraction policy the input a Free cell would get there:
/// argmax over inputs of min over disturbances of the expected next values (ties: the lowest
/// index), at every step (stationary: from the stationary values). The values keep the role's
/// value. On the real system a state in a target cell's box need not lie in the target set, and
/// one in an avoid cell's box need not lie in the avoid set: input 0 would steer it anywhere.
void choose_fixed_cell_inputs(const Abstraction& abstraction, Policy& policy);

}  // namespace amytiss::detail
