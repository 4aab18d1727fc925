#pragma once
// The specification's sets as the continuous system meets them (docs/cli.md, "Simulating
// the closed loop"): where one concrete state stands, judged on the configuration's own sets, not
// on the cells' roles. These are the sets whose probabilities the continuous-system bounds
// (guarantee: system) enclose:
//   - outside the grid: the state lies outside the covered box (Grid::cell_of has no cell), or is
//     not finite;
//   - obstacle: with `spec.obstacles` and a footprint, the car's body at the state's pose (one
//     rectangle, not the cell-wide over-approximation) meets an obstacle box, contact counting;
//   - safety: unsafe when `spec.safe` is given and the state lies in none of its boxes;
//   - reachability, reach_avoid: avoid when the state lies in a box of `spec.avoid` (avoid wins
//     over the target), target when it lies in a box of `spec.target`.
// Boxes are closed: a state on a face belongs to the box (a set of probability 0 under noise
// with a density).
#include <cstddef>
#include <string>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/grid.hpp"

namespace amytiss {

/// Where a state stands. Undecided: none of the others (the episode goes on).
enum class SetVerdict { Undecided, Target, Avoid, Obstacle, Unsafe, OutsideGrid };

/// "reached the target", "entered the avoid set", "touched an obstacle", "left the safe set",
/// "left the grid", "undecided".
std::string to_string(SetVerdict verdict);

/// Whether the body of `footprint` at the pose of `state` (state[pose[0]], state[pose[1]] in m,
/// state[pose[2]] the heading in rad) shares a point with one of the 2-d boxes of `obstacles`
/// (world frame, m): an exact rectangle-against-box test (separating axes), contact counting.
bool body_touches(const Footprint& footprint, const double* state, const Region& obstacles);

/// Whether `state` lies in one of the region's closed boxes.
bool in_region(const Region& region, const double* state);

class SpecSets {
 public:
  /// `config` passed Config::validate().
  explicit SpecSets(const Config& config);
  /// The verdict of state[0..dims): outside the grid first, then an obstacle, then (safety) the
  /// safe set or (reach specifications) the avoid set and the target.
  SetVerdict judge(const double* state) const;
  const Grid& states() const { return states_; }

 private:
  Grid states_;
  SpecConfig spec_;
};

}  // namespace amytiss
