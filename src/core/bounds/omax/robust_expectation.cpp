#include "bounds/omax/robust_expectation.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "common/require.hpp"

namespace amytiss::detail {
namespace {

constexpr Require require{"interval Bellman step: "};

}  // namespace

double robust_expectation(const double* lo, const double* hi, const double* values, std::size_t count, Bound bound,
                          std::vector<OutcomeSlack>& order) {
  double sum_lo = 0.0, sum_hi = 0.0, result = 0.0;
  const double sign = bound == Bound::Lower ? 1.0 : -1.0;
  if (order.size() < count) order.resize(count);
  // Only outcomes with slack take part in the filling (the others would be given 0). Insertion
  // sort on the outcomes themselves: rows are short (a window and two outcomes), it allocates
  // nothing, and it is stable, so ties fill in index order whatever the other values.
  OutcomeSlack* sorted = order.data();
  std::size_t filled = 0;
  for (std::size_t j = 0; j < count; ++j) {
    sum_lo += lo[j];
    sum_hi += hi[j];
    result += lo[j] * values[j];
    const double slack = hi[j] - lo[j];
    if (!(slack > 0.0)) continue;
    const double key = sign * values[j];
    std::size_t k = filled++;
    while (k > 0 && sorted[k - 1].key > key) {
      sorted[k] = sorted[k - 1];
      --k;
    }
    sorted[k] = {key, values[j], slack};
  }
  const double rounding = robust_expectation_rounding(count);
  require(sum_lo <= 1.0 + rounding && sum_hi >= 1.0 - rounding, "a row with sum lo <= 1 <= sum hi");
  double budget = 1.0 - sum_lo;
  for (std::size_t k = 0; k < filled && budget > 0.0; ++k) {
    const double given = std::min(sorted[k].slack, budget);
    result += given * sorted[k].value;
    budget -= given;
  }
  result = bound == Bound::Lower ? result - rounding : result + rounding;
  return std::clamp(result, 0.0, 1.0);
}

DimensionView view_of(const DimensionBounds& bounds) {
  return {bounds.first, bounds.cells.size(), bounds.cells.data(), bounds.leave, bounds.cut};
}

IntervalRow joint_row(const Grid& states, const DimensionView* dimensions) {
  const std::size_t dims = states.dims();
  require(dims > 0, "a state grid with dimensions");
  IntervalRow row;
  bool empty = false;
  for (std::size_t d = 0; d < dims; ++d) empty = empty || dimensions[d].count == 0;
  std::vector<MassInterval> cells;
  if (!empty) {
    std::vector<std::size_t> multi(dims), offset(dims, 0);  // offset[d]: index into dimensions[d].cells
    for (std::size_t d = 0; d < dims; ++d) multi[d] = std::size_t(dimensions[d].first);
    while (true) {
      MassInterval mass = dimensions[0].cells[offset[0]];
      for (std::size_t d = 1; d < dims; ++d) {
        const MassInterval& factor = dimensions[d].cells[offset[d]];
        mass.lo = std::max(0.0, round_down(mass.lo * factor.lo));
        mass.hi = std::min(1.0, round_up(mass.hi * factor.hi));
      }
      cells.push_back(mass);
      row.targets.push_back(states.flat_index(multi.data()));
      std::size_t d = dims;
      while (d-- > 0) {
        if (++offset[d] < dimensions[d].count) {
          ++multi[d];
          break;
        }
        offset[d] = 0;
        multi[d] = std::size_t(dimensions[d].first);
      }
      if (d == std::size_t(-1)) break;
    }
  }
  // Off the grid: off it along some dimension, so at least the largest and at most the sum of
  // theirs. Cut (on the grid, outside the window): outside some dimension's window, at most the
  // sum (in 1-d exactly the dimension's). Both at most what the cells leave.
  const MassInterval rest = remainder(cells.data(), cells.size());
  MassInterval leave = dimensions[0].leave, cut = dimensions[0].cut;
  if (dims > 1) cut.lo = 0.0;
  for (std::size_t d = 1; d < dims; ++d) {
    leave.lo = std::max(leave.lo, dimensions[d].leave.lo);
    leave.hi = round_up(leave.hi + dimensions[d].leave.hi);
    cut.hi = round_up(cut.hi + dimensions[d].cut.hi);
  }
  leave.hi = std::min(leave.hi, rest.hi);
  cut.hi = std::min(cut.hi, rest.hi);
  for (const MassInterval& mass : cells) {
    row.lo.push_back(mass.lo);
    row.hi.push_back(mass.hi);
  }
  for (const MassInterval& mass : {leave, cut}) {
    row.lo.push_back(mass.lo);
    row.hi.push_back(mass.hi);
  }
  return row;
}

IntervalRow joint_row(const Grid& states, const std::vector<DimensionBounds>& dimensions) {
  require(dimensions.size() == states.dims(), "one DimensionBounds per state dimension");
  std::vector<DimensionView> views;
  for (const DimensionBounds& dimension : dimensions) views.push_back(view_of(dimension));
  return joint_row(states, views.data());
}

double joint_expectation(const IntervalRow& row, const double* values, Bound bound) {
  std::vector<double> outcome_values(row.lo.size());
  for (std::size_t j = 0; j < row.targets.size(); ++j) outcome_values[j] = values[row.targets[j]];
  outcome_values[row.targets.size()] = 0.0;  // leaves the grid
  outcome_values[row.targets.size() + 1] = cut_value(bound);
  std::vector<OutcomeSlack> order;
  return robust_expectation(row.lo.data(), row.hi.data(), outcome_values.data(), row.lo.size(), bound, order);
}

namespace {

// One stage of the product bound: dimension d's intervals over the values of its window line at
// `prefix` (flat index over dimensions 0..d-1; the later dimensions already eliminated below it).
double eliminate(const DimensionView* dimensions, std::size_t dims, const double* values, Bound bound,
                 ProductScratch& scratch, std::size_t d, std::size_t prefix) {
  std::atomic<double>* cached = nullptr;
  if (d > 0 && !scratch.caches.empty() && scratch.caches[d].table) {
    const ProductScratch::StageCache& cache = scratch.caches[d];
    cached = &cache.table[cache.row_class * scratch.prefixes[d] + prefix];
    const double known = cached->load(std::memory_order_relaxed);
    if (!std::isnan(known)) return known;
  }
  const DimensionView& dimension = dimensions[d];
  const std::size_t cells = dimension.count;
  ProductScratch::Stage& stage = scratch.stages[d];
  if (stage.line.size() < cells + 2) {
    stage.lo.resize(cells + 2);
    stage.hi.resize(cells + 2);
    stage.line.resize(cells + 2);
  }
  const std::size_t first = prefix * scratch.counts[d] + std::size_t(dimension.first);
  for (std::size_t j = 0; j < cells; ++j) {
    stage.lo[j] = dimension.cells[j].lo;
    stage.hi[j] = dimension.cells[j].hi;
    // An outcome that can get no mass needs no value.
    if (!(stage.hi[j] > 0.0))
      stage.line[j] = 0.0;
    else
      stage.line[j] = d + 1 == dims ? values[first + j] : eliminate(dimensions, dims, values, bound, scratch, d + 1, first + j);
  }
  stage.lo[cells] = dimension.leave.lo;  // worth 0
  stage.hi[cells] = dimension.leave.hi;
  stage.line[cells] = 0.0;
  stage.lo[cells + 1] = dimension.cut.lo;
  stage.hi[cells + 1] = dimension.cut.hi;
  stage.line[cells + 1] = cut_value(bound);
  const double result =
      robust_expectation(stage.lo.data(), stage.hi.data(), stage.line.data(), cells + 2, bound, scratch.order);
  // Threads that meet the same line and class compute the same value: either store is it.
  if (cached) cached->store(result, std::memory_order_relaxed);
  return result;
}

}  // namespace

double product_expectation(const Grid& states, const DimensionView* dimensions, const double* values, Bound bound,
                           ProductScratch& scratch) {
  const std::size_t dims = states.dims();
  require(dims > 0, "a state grid with dimensions");
  bool same_grid = scratch.counts.size() == dims;
  for (std::size_t d = 0; d < dims && same_grid; ++d) same_grid = scratch.counts[d] == states.count(d);
  if (!same_grid) {
    scratch.stages.resize(dims);
    scratch.counts.resize(dims);
    scratch.prefixes.resize(dims);
    std::size_t prefix = 1;
    for (std::size_t d = 0; d < dims; ++d) {
      scratch.counts[d] = states.count(d);
      scratch.prefixes[d] = prefix;
      prefix *= states.count(d);
    }
  }
  return eliminate(dimensions, dims, values, bound, scratch, 0, 0);
}

double product_expectation(const Grid& states, const std::vector<DimensionBounds>& dimensions, const double* values,
                           Bound bound) {
  require(dimensions.size() == states.dims(), "one DimensionBounds per state dimension");
  std::vector<DimensionView> views;
  for (const DimensionBounds& dimension : dimensions) views.push_back(view_of(dimension));
  ProductScratch scratch;
  return product_expectation(states, views.data(), values, bound, scratch);
}

}  // namespace amytiss::detail
