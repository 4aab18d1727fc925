#include "amytiss/footprint.hpp"

#include <stdexcept>

namespace amytiss {

PlaneBox footprint_box(const Footprint& footprint, const Interval& x, const Interval& y, const Interval& yaw) {
  const Interval cos_yaw = cos(yaw), sin_yaw = sin(yaw);
  const double rear = -footprint.rear_overhang, front = footprint.length - footprint.rear_overhang;
  const double half_width = 0.5 * footprint.width;
  Interval body_x = Interval::empty(true), body_y = Interval::empty(true);
  for (double along : {rear, front}) {
    for (double across : {-half_width, half_width}) {
      const Interval a = Interval::point(along), c = Interval::point(across);
      body_x = hull(body_x, a * cos_yaw - c * sin_yaw);
      body_y = hull(body_y, a * sin_yaw + c * cos_yaw);
    }
  }
  return {x + body_x, y + body_y};
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
  std::vector<std::size_t> multi(states.dims());
  auto cell_range = [&](unsigned dim) {
    const double centre = states.lb()[dim] + double(multi[dim]) * states.eta()[dim];
    const double half = 0.5 * states.eta()[dim];
    return rounded_outward(centre - half, centre + half, kExactRoundingSteps);
  };
  for (std::size_t cell = 0; cell < states.size(); ++cell) {
    states.multi_index(cell, multi.data());
    const PlaneBox box = footprint_box(footprint, cell_range(footprint.pose[0]), cell_range(footprint.pose[1]),
                                       cell_range(footprint.pose[2]));
    touched[cell] = meets_obstacle(box, *spec.obstacles);
  }
  return touched;
}

}  // namespace amytiss
