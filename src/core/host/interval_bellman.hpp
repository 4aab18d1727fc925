#pragma once
// The robust Bellman step of an interval MDP (docs/semantics.md, "Interval transition bounds"):
// the pessimistic (lower bound) or optimistic (upper bound) expectation of values in [0, 1] over
// every distribution within per-outcome probability intervals, and the two ambiguity sets built
// from per-dimension bounds (model/mass_bounds.hpp):
//   - joint: the row's outcomes are the window's cells, each in [prod_i lo_i, prod_i hi_i], the
//     mass leaving the grid (off the grid along some dimension: in [max_i leave_i.lo,
//     sum_i leave_i.hi]) and the cut mass (in [0, sum_i cut_i.hi]; in 1-d the dimension's own);
//   - product: the distributions whose dimension i picks its 1-d distribution within dimension i's
//     intervals (the O-maximisation one dimension at a time, the last dimension first); sound, its
//     lower bound at least the joint one (equal in one dimension).
// Mass leaving the grid is worth 0 to both bounds (it fails the specification, as in the
// abstraction). Cut mass lands on grid cells outside the window, whose values the row does not
// read: worth 0 to the lower bound and 1 to the upper.
#include <cstddef>
#include <vector>

#include "amytiss/grid.hpp"
#include "model/mass_bounds.hpp"

namespace amytiss::detail {

enum class Bound { Lower, Upper };

/// The O-maximisation: min (Lower) or max (Upper) of sum_j p_j values_j over lo <= p <= hi,
/// sum_j p_j = 1, j < count. Starts from lo and gives the budget 1 - sum lo to the outcomes in
/// increasing (Lower) or decreasing (Upper) order of value, each at most hi - lo. Values lie in
/// [0, 1]; the row must be feasible (sum lo <= 1 <= sum hi up to rounding; std::logic_error
/// otherwise). The result is moved outward by the arithmetic's error bound and clipped to [0, 1].
/// `order` is scratch space.
double robust_expectation(const double* lo, const double* hi, const double* values, std::size_t count, Bound bound,
                          std::vector<std::size_t>& order);
/// The error bound robust_expectation() allows for, for `count` outcomes: (4 count + 4) u.
double robust_expectation_rounding(std::size_t count);

/// Value of the cut mass: 0 for the lower bound, 1 for the upper.
inline double cut_value(Bound bound) { return bound == Bound::Upper ? 1.0 : 0.0; }

/// One row of the joint interval MDP: outcomes targets[j] (flat state indices of the window, row-
/// major) with [lo[j], hi[j]], then the mass leaving the grid and the cut mass as the last two
/// entries of lo and hi.
struct IntervalRow {
  std::vector<std::size_t> targets;
  std::vector<double> lo, hi;
};
/// Products of the per-dimension bounds (one per state dimension), lo rounded down and hi up at
/// every multiplication, hi clipped to 1; leave and cut as above, at most remainder() of the cells.
IntervalRow joint_row(const Grid& states, const std::vector<DimensionBounds>& dimensions);
/// robust_expectation() of a joint row over `values` (one per state cell, flat).
double joint_expectation(const IntervalRow& row, const double* values, Bound bound);

/// The product (orthogonally decoupled) bound over `values` (one per state cell, flat): the last
/// dimension's intervals applied first to the values of each line of the window, then the
/// previous dimension's to those results, down to dimension 0; each stage's leave outcome is worth
/// 0, its cut outcome cut_value(bound).
double product_expectation(const Grid& states, const std::vector<DimensionBounds>& dimensions, const double* values,
                           Bound bound);

}  // namespace amytiss::detail
