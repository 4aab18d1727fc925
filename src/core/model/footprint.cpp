#include "amytiss/footprint.hpp"

#include "amytiss/grid_rules.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace amytiss {

namespace {

// Pieces much shorter than the cells add work without tightening the boxes: the cells' own extent
// in x and y dominates them.
constexpr double kPiecesPerCellSide = 2;
// The reach is computed in round-to-nearest; this relative margin makes it an upper bound.
constexpr double kReachMargin = 1e-9;
// Box tests between two looks at the clock: small enough that a poll is never late by much.
constexpr double kTestsPerClockCheck = 65536;

// The largest distance from a reference point in [x_lo, x_hi] x [y_lo, y_hi] to a point of an
// obstacle, enlarged to an upper bound.
double obstacle_reach(const Region& obstacles, double x_lo, double x_hi, double y_lo, double y_hi) {
  double reach = 0;
  for (const Box& obstacle : obstacles.boxes) {
    const double dx = std::max(std::abs(obstacle.ub[0] - x_lo), std::abs(x_hi - obstacle.lb[0]));
    const double dy = std::max(std::abs(obstacle.ub[1] - y_lo), std::abs(y_hi - obstacle.lb[1]));
    reach = std::max(reach, std::hypot(dx, dy));
  }
  return reach * (1 + kReachMargin);
}

}  // namespace

BodyCut body_cut(const Footprint& footprint, double min_side, double reach) {
  const double rear = -footprint.rear_overhang, front = footprint.length - footprint.rear_overhang;
  BodyCut cut;
  cut.min_side = min_side;
  // A body within reach keeps its own length, so that the pieces' bounds do not change by rounding.
  const bool whole = -rear <= reach && front <= reach;
  cut.rear = whole ? rear : std::max(rear, -reach);
  cut.front = whole ? front : std::min(front, reach);
  const double span = whole ? footprint.length : cut.front - cut.rear;
  cut.along = std::max(1.0, std::ceil(span / std::max(0.5 * footprint.width, min_side)));
  return cut;
}

std::vector<BodyPiece> body_pieces(const Footprint& footprint, double min_side, double reach) {
  return body_pieces(footprint, body_cut(footprint, min_side, reach));
}

std::vector<BodyPiece> body_pieces(const Footprint& footprint, const BodyCut& cut) {
  if (!(cut.along <= kMaxBodyPieces))
    throw std::logic_error("body_pieces: expected a validated footprint of at most 1e8 pieces");
  const auto along = std::size_t(cut.along);
  const double step = (cut.front - cut.rear) / double(along);
  const double half_width = 0.5 * footprint.width;
  std::vector<BodyPiece> pieces;
  pieces.reserve(2 * along);
  for (std::size_t i = 0; i < along; ++i) {
    // The last piece ends exactly at the front of the cut, whatever the rounding of the steps.
    const double front = i + 1 == along ? cut.front : cut.rear + double(i + 1) * step;
    const double back = cut.rear + double(i) * step;
    pieces.push_back({back, front, -half_width, 0.0});
    pieces.push_back({back, front, 0.0, half_width});
  }
  return pieces;
}

BodyCut grid_body_cut(const Grid& states, const SpecConfig& spec) {
  const Footprint& footprint = *spec.footprint;
  const std::size_t x = footprint.pose[0], y = footprint.pose[1];
  // eta() of a dimension given by its faces is its smallest cell width.
  const double min_side = std::min(states.eta()[x], states.eta()[y]) / kPiecesPerCellSide;
  return body_cut(footprint, min_side,
                  obstacle_reach(*spec.obstacles, states.covered_low(x), states.covered_high(x), states.covered_low(y),
                                 states.covered_high(y)));
}

BodyCut grid_body_cut(const GridSpec& states, const SpecConfig& spec) { return grid_body_cut(Grid(states), spec); }

namespace {

double cell_count(const GridSpec& states) {
  double cells = 1;
  for (std::size_t d = 0; d < states.lb.size(); ++d)
    cells *= states.has_faces(d) ? double(states.faces[d].size() - 1)
                                 : grid_points(states.lb[d], states.ub[d], states.eta[d]);
  return cells;
}

}  // namespace

double footprint_box_tests(const GridSpec& states, const SpecConfig& spec) {
  if (!spec.obstacles || !spec.footprint) return 0;
  return cell_count(states) * 2 * grid_body_cut(states, spec).along * double(spec.obstacles->boxes.size());
}

std::string footprint_work_text(const GridSpec& states, const SpecConfig& spec) {
  char text[160];
  std::snprintf(text, sizeof text, "%.3g box tests (%.3g pieces of the body x %.3g cells x %zu obstacles)",
                footprint_box_tests(states, spec), 2 * grid_body_cut(states, spec).along, cell_count(states),
                spec.obstacles ? spec.obstacles->boxes.size() : std::size_t(0));
  return text;
}

namespace {

PlaneBox rotated_piece_box(const BodyPiece& piece, const Interval& x, const Interval& y, const Interval& cos_yaw,
                           const Interval& sin_yaw) {
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

}  // namespace

PlaneBox piece_box(const BodyPiece& piece, const Interval& x, const Interval& y, const Interval& yaw) {
  return rotated_piece_box(piece, x, y, cos(yaw), sin(yaw));
}

PlaneBox footprint_box(const Footprint& footprint, const Interval& x, const Interval& y, const Interval& yaw) {
  const double half_width = 0.5 * footprint.width;
  return piece_box({-footprint.rear_overhang, footprint.length - footprint.rear_overhang, -half_width, half_width},
                   x, y, yaw);
}

bool body_may_touch(const std::vector<BodyPiece>& pieces, const Interval& x, const Interval& y, const Interval& yaw,
                    const Region& obstacles) {
  const Interval cos_yaw = cos(yaw), sin_yaw = sin(yaw);
  for (const BodyPiece& piece : pieces)
    if (meets_obstacle(rotated_piece_box(piece, x, y, cos_yaw, sin_yaw), obstacles)) return true;
  return false;
}

bool meets_obstacle(const PlaneBox& box, const Region& obstacles) {
  for (const Box& obstacle : obstacles.boxes)
    if (box.x.lo <= obstacle.ub[0] && box.x.hi >= obstacle.lb[0] && box.y.lo <= obstacle.ub[1] &&
        box.y.hi >= obstacle.lb[1])
      return true;
  return false;
}

std::vector<bool> obstacle_cells(const Grid& states, const SpecConfig& spec, const SetupPoll& poll) {
  std::vector<bool> touched(states.size(), false);
  if (!spec.obstacles) return touched;
  // Inputs here passed Config::validate(); a violation is a bug of the caller.
  if (!spec.footprint || spec.footprint->pose.size() != 3)
    throw std::logic_error("obstacle_cells: expected a validated configuration with a footprint");
  const Footprint& footprint = *spec.footprint;
  const std::vector<BodyPiece> pieces = body_pieces(footprint, grid_body_cut(states, spec));
  std::vector<std::size_t> multi(states.dims());
  auto cell_range = [&](unsigned dim) {
    if (!states.uniform(dim))
      return rounded_outward(states.face(dim, std::int64_t(multi[dim])), states.face(dim, std::int64_t(multi[dim]) + 1),
                             kExactRoundingSteps);
    const double centre = states.lb()[dim] + double(multi[dim]) * states.eta()[dim];
    const double half = 0.5 * states.eta()[dim];
    return rounded_outward(centre - half, centre + half, kExactRoundingSteps);
  };
  const double tests_per_cell = double(pieces.size()) * double(spec.obstacles->boxes.size());
  const auto cells_per_check = std::size_t(std::max(1.0, kTestsPerClockCheck / std::max(tests_per_cell, 1.0)));
  auto last_poll = std::chrono::steady_clock::now();
  for (std::size_t cell = 0; cell < states.size(); ++cell) {
    if (poll && cell % cells_per_check == 0 && cell > 0) {
      const auto now = std::chrono::steady_clock::now();
      if (std::chrono::duration<double>(now - last_poll).count() >= kPollSeconds) {
        poll();
        last_poll = now;
      }
    }
    states.multi_index(cell, multi.data());
    touched[cell] = body_may_touch(pieces, cell_range(footprint.pose[0]), cell_range(footprint.pose[1]),
                                   cell_range(footprint.pose[2]), *spec.obstacles);
  }
  return touched;
}

}  // namespace amytiss
