#include "amytiss/spec_sets.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace amytiss {
namespace {

using Point = std::array<double, 2>;

// The extent of `corners` along the direction `axis` (not normalized: both shapes are projected on
// the same vector, so the comparison of their extents does not need unit length).
std::pair<double, double> projection(const std::array<Point, 4>& corners, const Point& axis) {
  double lo = corners[0][0] * axis[0] + corners[0][1] * axis[1], hi = lo;
  for (const Point& corner : corners) {
    const double along = corner[0] * axis[0] + corner[1] * axis[1];
    lo = std::min(lo, along);
    hi = std::max(hi, along);
  }
  return {lo, hi};
}

}  // namespace

std::string to_string(SetVerdict verdict) {
  switch (verdict) {
    case SetVerdict::Target: return "reached the target";
    case SetVerdict::Avoid: return "entered the avoid set";
    case SetVerdict::Obstacle: return "touched an obstacle";
    case SetVerdict::Unsafe: return "left the safe set";
    case SetVerdict::OutsideGrid: return "left the grid";
    case SetVerdict::Undecided:
    default: return "undecided";
  }
}

bool body_touches(const Footprint& footprint, const double* state, const Region& obstacles) {
  const double x = state[footprint.pose.at(0)], y = state[footprint.pose.at(1)], yaw = state[footprint.pose.at(2)];
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double rear = -footprint.rear_overhang, front = footprint.length - footprint.rear_overhang;
  const double half_width = 0.5 * footprint.width;
  std::array<Point, 4> body;
  int k = 0;
  for (double along : {rear, front})
    for (double across : {-half_width, half_width})
      body[k++] = {x + along * c - across * s, y + along * s + across * c};
  // Two convex polygons are disjoint exactly when their projections on one edge normal of either
  // are: the world axes (the box's) and the heading and its normal (the body's).
  const std::array<Point, 4> axes = {Point{1, 0}, Point{0, 1}, Point{c, s}, Point{-s, c}};
  for (const Box& obstacle : obstacles.boxes) {
    const std::array<Point, 4> box = {Point{obstacle.lb[0], obstacle.lb[1]}, Point{obstacle.ub[0], obstacle.lb[1]},
                                      Point{obstacle.lb[0], obstacle.ub[1]}, Point{obstacle.ub[0], obstacle.ub[1]}};
    const bool separated = std::any_of(axes.begin(), axes.end(), [&](const Point& axis) {
      const auto [body_lo, body_hi] = projection(body, axis);
      const auto [box_lo, box_hi] = projection(box, axis);
      return body_hi < box_lo || box_hi < body_lo;
    });
    if (!separated) return true;
  }
  return false;
}

bool in_region(const Region& region, const double* state) {
  return std::any_of(region.boxes.begin(), region.boxes.end(), [&](const Box& box) {
    for (std::size_t d = 0; d < box.lb.size(); ++d)
      if (!(box.lb[d] <= state[d] && state[d] <= box.ub[d])) return false;
    return true;
  });
}

SpecSets::SpecSets(const Config& config) : states_(config.states), spec_(config.spec) {
  if (spec_.obstacles && !spec_.footprint)
    throw std::logic_error("SpecSets: expected a validated configuration (obstacles come with a footprint)");
}

SetVerdict SpecSets::judge(const double* state) const {
  if (!states_.cell_of(state)) return SetVerdict::OutsideGrid;
  if (spec_.obstacles && body_touches(*spec_.footprint, state, *spec_.obstacles)) return SetVerdict::Obstacle;
  if (spec_.type == SpecType::Safety)
    return spec_.safe && !in_region(*spec_.safe, state) ? SetVerdict::Unsafe : SetVerdict::Undecided;
  if (spec_.avoid && in_region(*spec_.avoid, state)) return SetVerdict::Avoid;
  if (spec_.target && in_region(*spec_.target, state)) return SetVerdict::Target;
  return SetVerdict::Undecided;
}

}  // namespace amytiss
