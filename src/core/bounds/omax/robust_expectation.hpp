#pragma once
// The robust Bellman step of an interval MDP (docs/semantics.md, "Interval transition bounds"):
// the pessimistic (lower bound) or optimistic (upper bound) expectation of values in [0, 1] over
// every distribution within per-outcome probability intervals, and the two ambiguity sets built
// from per-dimension bounds (bounds/mass_bounds.hpp):
//   - joint: the row's outcomes are the window's cells, each in [prod_i lo_i, prod_i hi_i], the
//     mass leaving the grid (off the grid along some dimension: in [max_i leave_i.lo,
//     sum_i leave_i.hi]) and the cut mass (in [0, sum_i cut_i.hi]; in 1-d the dimension's own);
//   - product: the distributions whose dimension i picks its 1-d distribution within dimension i's
//     intervals (the O-maximisation one dimension at a time, the last dimension first); sound, its
//     lower bound at least the joint one (equal in one dimension).
// Mass leaving the grid is worth 0 to both bounds (it fails the specification, as in the
// abstraction). Cut mass lands on grid cells outside the window, whose values the row does not
// read: worth 0 to the lower bound and 1 to the upper.
#include <atomic>
#include <cstddef>
#include <vector>

#include "amytiss/grid.hpp"
#include "bounds/mass_bounds.hpp"

namespace amytiss::detail {

enum class Bound { Lower, Upper };

/// An outcome that can take more than its lower bound, as robust_expectation() orders them.
struct OutcomeSlack {
  double key;    ///< value (Lower) or -value (Upper): filled in increasing order of key
  double value;  ///< in [0, 1]
  double slack;  ///< hi - lo > 0
};
/// The O-maximisation: min (Lower) or max (Upper) of sum_j p_j values_j over lo <= p <= hi,
/// sum_j p_j = 1, j < count. Starts from lo and gives the budget 1 - sum lo to the outcomes in
/// increasing (Lower) or decreasing (Upper) order of value (ties in index order), each at most
/// hi - lo. Values lie in [0, 1]; the row must be feasible (sum lo <= 1 <= sum hi up to rounding;
/// std::logic_error otherwise). The result is moved outward by the arithmetic's error bound and
/// clipped to [0, 1]. `order` is scratch space.
double robust_expectation(const double* lo, const double* hi, const double* values, std::size_t count, Bound bound,
                          std::vector<OutcomeSlack>& order);
/// The error bound robust_expectation() allows for, for `count` outcomes: (4 count + 4) u.
inline double robust_expectation_rounding(std::size_t count) { return double(4 * count + 4) * kUnitRoundoff; }

/// Value of the cut mass: 0 for the lower bound, 1 for the upper.
inline double cut_value(Bound bound) { return bound == Bound::Upper ? 1.0 : 0.0; }

/// One row of the joint interval MDP: outcomes targets[j] (flat state indices of the window, row-
/// major) with [lo[j], hi[j]], then the mass leaving the grid and the cut mass as the last two
/// entries of lo and hi.
struct IntervalRow {
  std::vector<std::size_t> targets;
  std::vector<double> lo, hi;
};
/// One dimension's bounds of a row without owning them: a DimensionBounds or an entry of a packed
/// store (bounds/row_bounds.hpp). cells[k] is the mass of grid cell first + k, k < count.
struct DimensionView {
  std::int64_t first = 0;
  std::size_t count = 0;
  const MassInterval* cells = nullptr;
  MassInterval leave, cut;
};
DimensionView view_of(const DimensionBounds& bounds);

/// Products of the per-dimension bounds (one per state dimension), lo rounded down and hi up at
/// every multiplication, hi clipped to 1; leave and cut as above, at most remainder() of the cells.
IntervalRow joint_row(const Grid& states, const DimensionView* dimensions);
IntervalRow joint_row(const Grid& states, const std::vector<DimensionBounds>& dimensions);
/// robust_expectation() of a joint row over `values` (one per state cell, flat).
double joint_expectation(const IntervalRow& row, const double* values, Bound bound);

/// The product (orthogonally decoupled) bound over `values` (one per state cell, flat): the last
/// dimension's intervals applied first to the values of each line of the window, then the
/// previous dimension's to those results, down to dimension 0; each stage's leave outcome is worth
/// 0, its cut outcome cut_value(bound).
double product_expectation(const Grid& states, const std::vector<DimensionBounds>& dimensions, const double* values,
                           Bound bound);

/// Reusable space of product_expectation() (one per thread): after the first rows of a grid it
/// allocates nothing.
struct ProductScratch {
  struct Stage {
    std::vector<double> lo, hi, line;
  };
  std::vector<Stage> stages;           ///< one per dimension
  std::vector<std::size_t> counts;     ///< cells of the state grid per dimension
  std::vector<std::size_t> prefixes;   ///< prefixes[d]: cells of dimensions 0..d-1 (1 for d = 0)
  std::vector<OutcomeSlack> order;     ///< robust_expectation()'s
  std::vector<DimensionView> views;    ///< for callers that gather a row's views
  /// Optional, for rows that share the bounds of dimensions d..dims-1 (1 <= d < dims): stage d's
  /// result on the window line at prefix p (flat index over dimensions 0..d-1) is kept at
  /// table[row_class * prefixes[d] + p] (one class's lines side by side); NaN: not computed yet.
  /// A cache belongs to one `values` vector and one bound; the caller sets row_class for each row.
  struct StageCache {
    std::atomic<double>* table = nullptr;  ///< null: stage d is not cached
    std::size_t classes = 0;
    std::size_t row_class = 0;
  };
  std::vector<StageCache> caches;  ///< per dimension, or empty
};
/// product_expectation() of one row given as one view per state dimension.
double product_expectation(const Grid& states, const DimensionView* dimensions, const double* values, Bound bound,
                           ProductScratch& scratch);

}  // namespace amytiss::detail
