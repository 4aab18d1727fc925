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

/// A rectangle of the car's frame (m): `rear..front` along the heading (forward > 0) from the
/// reference point, `right..left` across it (left > 0).
struct BodyPiece {
  double rear, front, right, left;
};

/// The body, `length` x `width` from `rear_overhang` behind the reference point, cut into pieces
/// of side at most width/2 (2 across, ceil(2 length / width) along): their union is the body.
std::vector<BodyPiece> body_pieces(const Footprint& footprint);

/// A box that holds every point of `piece` for every pose with the reference point in x × y (m)
/// and the heading in `yaw` (rad). The piece's four corners are rotated with interval cos and sin
/// of `yaw` (outward rounded); their hull, shifted by x × y, encloses the rectangle (the convex
/// hull of its corners) at every such pose.
PlaneBox piece_box(const BodyPiece& piece, const Interval& x, const Interval& y, const Interval& yaw);

/// piece_box() of the whole body: one box around the footprint swept over the poses.
PlaneBox footprint_box(const Footprint& footprint, const Interval& x, const Interval& y, const Interval& yaw);

/// Whether `box` and one of the obstacles share a point (contact counts: the test is conservative).
bool meets_obstacle(const PlaneBox& box, const Region& obstacles);

/// Whether the body (its body_pieces()) may touch an obstacle at some pose of x × y × yaw: whether
/// the box of one of the pieces meets one (tighter than footprint_box() when the heading is oblique).
bool body_may_touch(const std::vector<BodyPiece>& pieces, const Interval& x, const Interval& y, const Interval& yaw,
                    const Region& obstacles);

/// Per cell of `states` (its box: the point ± eta/2 in every dimension): whether the body at some
/// pose of the cell may touch an obstacle. All false without `spec.obstacles`.
std::vector<bool> obstacle_cells(const Grid& states, const SpecConfig& spec);

}  // namespace amytiss
