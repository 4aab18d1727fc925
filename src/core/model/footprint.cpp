#include "amytiss/footprint.hpp"

#include <cmath>
#include <stdexcept>

namespace amytiss {

std::vector<BodyPiece> body_pieces(const Footprint& footprint) {
  const std::size_t along = std::size_t(std::ceil(2.0 * footprint.length / footprint.width));
  const double rear = -footprint.rear_overhang, step = footprint.length / double(along);
  const double half_width = 0.5 * footprint.width;
  std::vector<BodyPiece> pieces;
  for (std::size_t i = 0; i < along; ++i) {
    // The last piece ends exactly at the front bumper, whatever the rounding of the steps.
    const double front = i + 1 == along ? footprint.length - footprint.rear_overhang : rear + double(i + 1) * step;
    const double back = rear + double(i) * step;
    pieces.push_back({back, front, -half_width, 0.0});
    pieces.push_back({back, front, 0.0, half_width});
  }
  return pieces;
}

PlaneBox piece_box(const BodyPiece& piece, const Interval& x, const Interval& y, const Interval& yaw) {
  const Interval cos_yaw = cos(yaw), sin_yaw = sin(yaw);
  Interval body_x = Interval::empty(true), body_y = Interval::empty(true);
  for (double along : {piece.rear, piece.front}) {
    for (double across : {piece.right, piece.left}) {
      const Interval a = Interval::point(along), c = Interval::point(across);
      body_x = hull(body_x, a * cos_yaw - c * sin_yaw);
      body_y = hull(body_y, a * sin_yaw + c * cos_yaw);
    }
  }
  return {x + body_x, y + body_y};
}

PlaneBox footprint_box(const Footprint& footprint, const Interval& x, const Interval& y, const Interval& yaw) {
  const double half_width = 0.5 * footprint.width;
  return piece_box({-footprint.rear_overhang, footprint.length - footprint.rear_overhang, -half_width, half_width},
                   x, y, yaw);
}

bool body_may_touch(const std::vector<BodyPiece>& pieces, const Interval& x, const Interval& y, const Interval& yaw,
                    const Region& obstacles) {
  for (const BodyPiece& piece : pieces)
    if (meets_obstacle(piece_box(piece, x, y, yaw), obstacles)) return true;
  return false;
}

bool meets_obstacle(const PlaneBox& box, const Region& obstacles) {
  for (const Box& obstacle : obstacles.boxes)
    if (box.x.lo <= obstacle.ub[0] && box.x.hi >= obstacle.lb[0] && box.y.lo <= obstacle.ub[1] &&
        box.y.hi >= obstacle.lb[1])
      return true;
  return false;
}

std::vector<bool> obstacle_cells(const Grid& states, const SpecConfig& spec) {
  std::vector<bool> touched(states.size(), false);
  if (!spec.obstacles) return touched;
  // Inputs here passed Config::validate(); a violation is a bug of the caller.
  if (!spec.footprint || spec.footprint->pose.size() != 3)
    throw std::logic_error("obstacle_cells: expected a validated configuration with a footprint");
  const Footprint& footprint = *spec.footprint;
  const std::vector<BodyPiece> pieces = body_pieces(footprint);
  std::vector<std::size_t> multi(states.dims());
  auto cell_range = [&](unsigned dim) {
    const double centre = states.lb()[dim] + double(multi[dim]) * states.eta()[dim];
    const double half = 0.5 * states.eta()[dim];
    return rounded_outward(centre - half, centre + half, kExactRoundingSteps);
  };
  for (std::size_t cell = 0; cell < states.size(); ++cell) {
    states.multi_index(cell, multi.data());
    touched[cell] = body_may_touch(pieces, cell_range(footprint.pose[0]), cell_range(footprint.pose[1]),
                                   cell_range(footprint.pose[2]), *spec.obstacles);
  }
  return touched;
}

}  // namespace amytiss
