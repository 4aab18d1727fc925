#pragma once
// The robust Bellman step of an interval MDP (docs/semantics.md, "Interval transition bounds"):
// the pessimistic (lower bound) or optimistic (upper bound) expectation of values in [0, 1] over
// every distribution within per-outcome probability intervals, and the two ambiguity sets built
// from per-dimension bounds (model/mass_bounds.hpp):
//   - joint: the row's outcomes are the window's cells, each in [prod_i lo_i, prod_i hi_i], and the
//     residual (mass outside the window) in [1 - sum hi, 1 - sum lo], narrowed to
//     [max_i residual_i.lo, sum_i residual_i.hi] (outside the window is outside some dimension's);
//   - product: the distributions whose dimension i picks its 1-d distribution within dimension i's
//     intervals (the O-maximisation one dimension at a time, the last dimension first); sound and at
//     least as tight as the joint set (equal in one dimension).
// Residual mass is worth 0 to the lower bound; to the upper bound 1 when it may be cut by the
// truncation (land on grid cells outside the window), else 0 (it leaves the grid, which fails the
// specification).
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
/// The error bound robust_expectation() allows for, for `count` outcomes: (2 count + 4) u.
double robust_expectation_rounding(std::size_t count);

/// Residual value of a row: 0 for the lower bound; for the upper bound 1 when it may be cut.
inline double residual_value(Bound bound, bool cut) { return bound == Bound::Upper && cut ? 1.0 : 0.0; }

/// One row of the joint interval MDP: outcomes targets[j] (flat state indices of the window, row-
/// major) with [lo[j], hi[j]], then the residual as the last entry of lo and hi.
struct IntervalRow {
  std::vector<std::size_t> targets;
  std::vector<double> lo, hi;
  bool cut = false;  ///< the residual may be cut (some dimension's is)
};
/// Products of the per-dimension bounds (one per state dimension), lo rounded down and hi up at
/// every multiplication, hi clipped to 1; the residual as above.
IntervalRow joint_row(const Grid& states, const std::vector<DimensionBounds>& dimensions);
/// robust_expectation() of a joint row over `values` (one per state cell, flat).
double joint_expectation(const IntervalRow& row, const double* values, Bound bound);

/// The product (orthogonally decoupled) bound over `values` (one per state cell, flat): the last
/// dimension's intervals applied first to the values of each line of the window, then the
/// previous dimension's to those results, down to dimension 0; each stage's residual outcome is
/// worth residual_value(bound, that dimension's cut).
double product_expectation(const Grid& states, const std::vector<DimensionBounds>& dimensions, const double* values,
                           Bound bound);

}  // namespace amytiss::detail
