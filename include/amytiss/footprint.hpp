#pragma once
// The car's footprint against `spec.obstacles` (docs/semantics.md, "Obstacles and the footprint"):
// a conservative test of whether the body, at some pose of a state cell, may touch an obstacle.
#include <functional>
#include <limits>
#include <string>
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

/// The part of the body that is cut into pieces: `rear..front` along the heading (m), in `along`
/// pieces (a double, so that a count too large for any index type can still be refused), none
/// shorter than `min_side` unless the cut is.
struct BodyCut {
  double rear = 0, front = 0, along = 0, min_side = 0;
};

/// The cut of the body: pieces of length at most max(width/2, min_side) along the heading, over
/// the body's points closer than `reach` (m) to the reference point along the heading; the points
/// further along cannot touch an obstacle when `reach` is at least the largest distance from a
/// pose of a cell to a point of an obstacle.
BodyCut body_cut(const Footprint& footprint, double min_side = 0,
                 double reach = std::numeric_limits<double>::infinity());

/// body_cut() cut into pieces of side at most width/2 across (2 across) and as cut along: their
/// union is every point of the body that may reach an obstacle (with the defaults: the body).
/// Throws std::logic_error for a cut of more pieces than kMaxBodyPieces (validate() refuses them).
std::vector<BodyPiece> body_pieces(const Footprint& footprint, double min_side = 0,
                                   double reach = std::numeric_limits<double>::infinity());
std::vector<BodyPiece> body_pieces(const Footprint& footprint, const BodyCut& cut);
constexpr double kMaxBodyPieces = 1e8;

/// The cut of the body for a grid of states and the obstacles of `spec` (with a footprint):
/// pieces no shorter than half the finer cell side in x and y, over the reach from the
/// cells' poses to the obstacles.
BodyCut grid_body_cut(const GridSpec& states, const SpecConfig& spec);
BodyCut grid_body_cut(const Grid& states, const SpecConfig& spec);

/// The work of obstacle_cells(): cells x pieces x obstacles box tests (0 without obstacles), as a
/// double so that any grid can be counted.
double footprint_box_tests(const GridSpec& states, const SpecConfig& spec);
/// footprint_box_tests() for people: "2.9e+08 box tests (74 pieces of the body x 6.67e+05 cells x
/// 6 obstacles)".
std::string footprint_work_text(const GridSpec& states, const SpecConfig& spec);
/// The most box tests validate() accepts.
constexpr double kMaxFootprintBoxTests = 5e8;

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

/// Called at bounded intervals of obstacle_cells()' work; may throw (Cancelled) to end it.
using SetupPoll = std::function<void()>;

/// Per cell of `states` (its box: the point ± eta/2 in every dimension): whether the body at some
/// pose of the cell may touch an obstacle. All false without `spec.obstacles`. Calls `poll` (when
/// given) every kPollSeconds of work at most.
std::vector<bool> obstacle_cells(const Grid& states, const SpecConfig& spec, const SetupPoll& poll = {});
constexpr double kPollSeconds = 0.1;

}  // namespace amytiss
