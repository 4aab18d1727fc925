#include "host/interval_bellman.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <string>

namespace amytiss::detail {
namespace {

void require(bool invariant, const char* what) {
  if (!invariant) throw std::logic_error(std::string("interval Bellman step: ") + what);
}

}  // namespace

double robust_expectation_rounding(std::size_t count) { return double(4 * count + 4) * kUnitRoundoff; }

double robust_expectation(const double* lo, const double* hi, const double* values, std::size_t count, Bound bound,
                          std::vector<std::size_t>& order) {
  double sum_lo = 0.0, sum_hi = 0.0, result = 0.0;
  for (std::size_t j = 0; j < count; ++j) {
    sum_lo += lo[j];
    sum_hi += hi[j];
    result += lo[j] * values[j];
  }
  const double rounding = robust_expectation_rounding(count);
  require(sum_lo <= 1.0 + rounding && sum_hi >= 1.0 - rounding, "a row with sum lo <= 1 <= sum hi");
  order.resize(count);
  std::iota(order.begin(), order.end(), std::size_t(0));
  // The adversary (Lower) fills the lowest values first, the friend (Upper) the highest; stable, so
  // that ties fill in index order whatever the other values.
  if (bound == Bound::Lower)
    std::stable_sort(order.begin(), order.end(), [values](std::size_t i, std::size_t j) { return values[i] < values[j]; });
  else
    std::stable_sort(order.begin(), order.end(), [values](std::size_t i, std::size_t j) { return values[i] > values[j]; });
  double budget = 1.0 - sum_lo;
  for (std::size_t j : order) {
    if (!(budget > 0.0)) break;
    const double given = std::min(hi[j] - lo[j], budget);
    result += given * values[j];
    budget -= given;
  }
  result = bound == Bound::Lower ? result - rounding : result + rounding;
  return std::clamp(result, 0.0, 1.0);
}

IntervalRow joint_row(const Grid& states, const std::vector<DimensionBounds>& dimensions) {
  const std::size_t dims = states.dims();
  require(dims > 0 && dimensions.size() == dims, "one DimensionBounds per state dimension");
  IntervalRow row;
  bool empty = false;
  for (const DimensionBounds& dimension : dimensions) empty = empty || dimension.cells.empty();
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
        if (++offset[d] < dimensions[d].cells.size()) {
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

double joint_expectation(const IntervalRow& row, const double* values, Bound bound) {
  std::vector<double> outcome_values(row.lo.size());
  for (std::size_t j = 0; j < row.targets.size(); ++j) outcome_values[j] = values[row.targets[j]];
  outcome_values[row.targets.size()] = 0.0;  // leaves the grid
  outcome_values[row.targets.size() + 1] = cut_value(bound);
  std::vector<std::size_t> order;
  return robust_expectation(row.lo.data(), row.hi.data(), outcome_values.data(), row.lo.size(), bound, order);
}

namespace {

// One stage of the product bound: dimension d's intervals over the values of its window line at
// flat `offset` (the later dimensions already eliminated below it).
struct ProductStages {
  const Grid& states;
  const std::vector<DimensionBounds>& dimensions;
  const double* values;
  Bound bound;
  std::vector<std::size_t> strides;
  std::vector<std::size_t> order;

  double eliminate(std::size_t d, std::size_t offset) {
    const DimensionBounds& dimension = dimensions[d];
    const std::size_t cells = dimension.cells.size();
    std::vector<double> lo(cells + 2), hi(cells + 2), line(cells + 2, 0.0);
    for (std::size_t j = 0; j < cells; ++j) {
      lo[j] = dimension.cells[j].lo;
      hi[j] = dimension.cells[j].hi;
      const std::size_t position = offset + (std::size_t(dimension.first) + j) * strides[d];
      // An outcome that can get no mass needs no value.
      if (hi[j] > 0.0) line[j] = d + 1 == dimensions.size() ? values[position] : eliminate(d + 1, position);
    }
    lo[cells] = dimension.leave.lo;  // worth 0
    hi[cells] = dimension.leave.hi;
    lo[cells + 1] = dimension.cut.lo;
    hi[cells + 1] = dimension.cut.hi;
    line[cells + 1] = cut_value(bound);
    return robust_expectation(lo.data(), hi.data(), line.data(), cells + 2, bound, order);
  }
};

}  // namespace

double product_expectation(const Grid& states, const std::vector<DimensionBounds>& dimensions, const double* values,
                           Bound bound) {
  const std::size_t dims = states.dims();
  require(dims > 0 && dimensions.size() == dims, "one DimensionBounds per state dimension");
  ProductStages stages{states, dimensions, values, bound, std::vector<std::size_t>(dims), {}};
  std::size_t stride = 1;
  for (std::size_t d = dims; d-- > 0;) {
    stages.strides[d] = stride;
    stride *= states.count(d);
  }
  return stages.eliminate(0, 0);
}

}  // namespace amytiss::detail
