#pragma once
// Whether a box lies in a union of boxes, by a sweep over the boxes' faces one dimension at a
// time (docs/semantics.md, "Robust reference"): the cell roles of the continuous-system bounds
// ask it of every cell.
#include <cstddef>
#include <optional>
#include <vector>

#include "amytiss/config.hpp"

namespace amytiss::detail {

/// The sweep's subproblems one box_covered() call may solve before it gives up.
constexpr std::size_t kMaxCoverSteps = 1000000;

/// Whether the box [lo, hi] lies in the union of `boxes` up to `slack` (per dimension): a box that
/// shares with [lo, hi] no more than a layer of that thickness is left out, the others count
/// enlarged by it. Along the first dimension the faces of the boxes cut [lo, hi] into slabs; each
/// slab must be covered by the boxes that span it, in the remaining dimensions; subproblems with
/// the same boxes are solved once. Exact; the work is bounded by the number of distinct sets of
/// boxes that span some slab (at most 2^boxes, far fewer for most unions): nullopt when more than
/// kMaxCoverSteps subproblems would be needed.
std::optional<bool> box_covered(const std::vector<double>& lo, const std::vector<double>& hi,
                                const std::vector<Box>& boxes, const std::vector<double>& slack);

}  // namespace amytiss::detail
