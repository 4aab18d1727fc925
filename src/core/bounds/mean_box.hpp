#pragma once
// The bounds' mean boxes (MeanBox, bounds/cell_roles.hpp) from image enclosures of the
// system map (amytiss/enclosure.hpp, docs/semantics.md "Image enclosures").
#include "amytiss/enclosure.hpp"
#include "amytiss/grid.hpp"
#include "bounds/cell_roles.hpp"

namespace amytiss::detail {

/// The box of disturbances that disturbance index `disturbance` stands for: along each dimension its
/// cell [face(k), face(k + 1)] (the point +- eta/2, as for states), or the point itself where the
/// dimension has one point (lb == ub, or ub - lb below eta/2). Empty without disturbances.
IntervalBox disturbance_cell(const Grid& disturbances, std::size_t disturbance);

/// For state cell `cell` of `states` (the box c +- eta/2 around its point), the point of `inputs`
/// and the disturbance_cell() of `disturbances` (grids of no dimension: none), writes
/// ImageEnclosure::enclose(), rounded outward to multiples of a power of two at most 2^-40 of the
/// cell's width (per dimension), and its expansion (ImageBox::expansion). Where the map may be
/// undefined in the cell the box is the whole space (-inf, +inf): every mass is then unknown.
/// `enclosure` and the grids must outlive the returned function.
MeanBox enclosure_mean_box(const ImageEnclosure& enclosure, const Grid& states, const Grid& inputs,
                           const Grid& disturbances);

}  // namespace amytiss::detail
