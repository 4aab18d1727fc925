#pragma once
// The inputs the abstraction's controller applies in its target cells.
#include <cstddef>

#include "amytiss/abstraction.hpp"
#include "amytiss/policy.hpp"

namespace amytiss::detail {

/// Gives every target cell (FixedOne) of an abstraction policy the input a Free cell would get
/// there: argmax over inputs of min over disturbances of the expected next values (ties: the
/// lowest index), at every step (stationary: from the stationary values). The values stay 1.
/// A target cell's point lies in the target, not all its states: input 0 would steer a real
/// state that has not arrived anywhere. Avoid cells keep input 0 (they are many where a
/// footprint meets obstacles, and the abstraction counts them as failed whatever the input).
struct TargetCellInputs {
  std::size_t cells = 0;  ///< target cells
  double seconds = 0;     ///< 0 when nothing was chosen (no target cell, or one input)
};
TargetCellInputs choose_target_cell_inputs(const Abstraction& abstraction, Policy& policy);

}  // namespace amytiss::detail
