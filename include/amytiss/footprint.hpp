#pragma once
// The car's footprint against `spec.obstacles` (docs/semantics.md, "Obstacles and the footprint"):
// a conservative test of whether the body, at some pose of a state cell, may touch an obstacle.
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/grid.hpp"
#include "amytiss/interval.hpp"

namespace amytiss {

/// An axis-aligned box of the world plane: x and y in m.
struct PlaneBox {
  Interval x, y;
};

/// A box that holds every point of the body for every pose with the reference point in x × y (m)
/// and the heading in `yaw` (rad). The body's four corners relative to the reference point are
/// rotated with interval cos and sin of `yaw` (outward rounded); their hull, shifted by x × y,
/// encloses the rectangle (the convex hull of its corners) at every such pose.
PlaneBox footprint_box(const Footprint& footprint, const Interval& x, const Interval& y, const Interval& yaw);

/// Whether `box` and one of the obstacles share a point (contact counts: the test is conservative).
bool meets_obstacle(const PlaneBox& box, const Region& obstacles);

/// Per cell of `states` (its box: the point ± eta/2 in every dimension): whether the body at some
/// pose of the cell may touch an obstacle. All false without `spec.obstacles`.
std::vector<bool> obstacle_cells(const Grid& states, const SpecConfig& spec);

}  // namespace amytiss
