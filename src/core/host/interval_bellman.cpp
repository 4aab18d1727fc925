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
  for (const DimensionBounds& dimension : dimensions) {
    row.cut = row.cut || dimension.cut;
    empty = empty || dimension.cells.empty();
  }
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
  // Outside the joint window means outside some dimension's: at least the largest of their
  // residuals, at most their sum.
  MassInterval residual = remainder(cells.data(), cells.size());
  double union_hi = dimensions[0].residual.hi;
  for (const DimensionBounds& dimension : dimensions) residual.lo = std::max(residual.lo, dimension.residual.lo);
  for (std::size_t d = 1; d < dims; ++d) union_hi = round_up(union_hi + dimensions[d].residual.hi);
  residual.hi = std::min(residual.hi, union_hi);
  for (const MassInterval& mass : cells) {
    row.lo.push_back(mass.lo);
    row.hi.push_back(mass.hi);
  }
  row.lo.push_back(residual.lo);
  row.hi.push_back(residual.hi);
  return row;
}

double joint_expectation(const IntervalRow& row, const double* values, Bound bound) {
  std::vector<double> outcome_values(row.lo.size());
  for (std::size_t j = 0; j < row.targets.size(); ++j) outcome_values[j] = values[row.targets[j]];
  outcome_values.back() = residual_value(bound, row.cut);
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
    std::vector<double> lo(cells + 1), hi(cells + 1), line(cells + 1, 0.0);
    for (std::size_t j = 0; j < cells; ++j) {
      lo[j] = dimension.cells[j].lo;
      hi[j] = dimension.cells[j].hi;
      const std::size_t position = offset + (std::size_t(dimension.first) + j) * strides[d];
      // An outcome that can get no mass needs no value.
      if (hi[j] > 0.0) line[j] = d + 1 == dimensions.size() ? values[position] : eliminate(d + 1, position);
    }
    lo[cells] = dimension.residual.lo;
    hi[cells] = dimension.residual.hi;
    line[cells] = residual_value(bound, dimension.cut);
    return robust_expectation(lo.data(), hi.data(), line.data(), cells + 1, bound, order);
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
