#pragma once
// The vocabulary of the continuous-system bounds (docs/semantics.md, "Interval transition
// bounds"): the two ambiguity sets of a row, the mean boxes that enclose the system map over a
// cell, and the cells' roles for the lower and the upper bound.
#include <cstdint>
#include <cstddef>
#include <functional>
#include <vector>

#include "amytiss/abstraction.hpp"
#include "bounds/omax/robust_expectation.hpp"

namespace amytiss::detail {

/// Writes lo[i] <= f(x, u, w)_i <= hi[i] (state units) for every x in state cell `cell` (flat
/// index), input index `input` and disturbance index `disturbance`; and, where it knows one,
/// expansion[i]: a lower bound of |df_i/dx_i| over the cell (ImageBox::expansion). The caller fills
/// `expansion` with 0 (nothing known) before the call.
using MeanBox = std::function<void(std::size_t cell, std::size_t input, std::size_t disturbance, double* lo,
                                   double* hi, double* expansion)>;

/// Cell roles for one bound, from the cells' interiors (c - eta/2, c + eta/2): the bounds hold for
/// every x inside a cell; contact with a set along a face (within kFaceTolerance * eta) does not
/// count. Lower: target only when the cell lies inside the target, avoid (safety: unsafe) as soon
/// as it meets the avoid set (leaves the safe set). Upper: target as soon as it meets the target,
/// avoid only inside the avoid set (unsafe only when it misses the safe set). Avoid wins.
/// Sets that are unions of boxes: "meets" is meeting one of the boxes, "inside" is lying inside
/// their union (exactly, by box_covered(): a cell covered by several boxes together is inside);
/// ConfigError naming the set for a union too intricate to decide. `poll`: as obstacle_cells().
constexpr double kFaceTolerance = 1e-9;
std::vector<CellRole> robust_cell_roles(const Grid& states, const SpecConfig& spec, Bound bound,
                                        const SetupPoll& poll = {});

}  // namespace amytiss::detail
