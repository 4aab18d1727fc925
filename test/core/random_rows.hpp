#pragma once
// Random feasible windows over random lines, and the O-maximisation of a window by
// robust_expectation() as the oracle: the data of the tests of the line-wise O-maximisations.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <random>
#include <vector>

#include "bounds/omax/robust_expectation.hpp"

namespace amytiss::test_rows {

using detail::Bound;
using detail::DimensionView;

// A random feasible window of `count` cells at `first` with leave and cut, values drawn from a few
// levels (ties) including 0 and 1.
struct RandomRow {
  std::vector<MassInterval> cells;
  DimensionView window;
};

inline RandomRow random_row(std::mt19937& random, std::size_t length) {
  std::uniform_int_distribution<std::size_t> count_of(1, std::min<std::size_t>(length, 30));
  RandomRow row;
  const std::size_t count = count_of(random);
  const std::size_t first = std::uniform_int_distribution<std::size_t>(0, length - count)(random);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> centre(count + 2);
  for (double& mass : centre) mass = unit(random) < 0.2 ? 0.0 : unit(random);
  centre[count] += 1e-3;  // some mass somewhere
  const double total = std::accumulate(centre.begin(), centre.end(), 0.0);
  std::vector<MassInterval> all;
  for (double mass : centre) {
    const double p = mass / total, width = unit(random) < 0.3 ? 0.0 : 0.2 * unit(random) * p + 1e-3 * unit(random);
    all.push_back({std::max(0.0, p - width), std::min(1.0, p + width)});
  }
  // Sometimes leave or cut may take all the budget: the filling ends at them.
  if (unit(random) < 0.2) all[count + std::size_t(unit(random) < 0.5)] = {0.0, 1.0};
  row.cells.assign(all.begin(), all.begin() + std::ptrdiff_t(count));
  row.window = {std::int64_t(first), count, nullptr, all[count], all[count + 1]};
  return row;
}

inline std::vector<double> random_line(std::mt19937& random, std::size_t length) {
  std::uniform_int_distribution<int> level(0, 6);
  std::vector<double> line(length);
  for (double& value : line) value = level(random) / 6.0;
  return line;
}

// Values drawn uniformly from [0, 1]: ties only by chance.
inline std::vector<double> random_smooth_line(std::mt19937& random, std::size_t length) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> line(length);
  for (double& value : line) value = unit(random);
  return line;
}

// robust_expectation() of the window's cells (values from the line), leave (worth 0) and cut.
inline double sorted_expectation(const std::vector<double>& line, const RandomRow& row, Bound bound) {
  std::vector<double> lo, hi, values;
  for (std::size_t j = 0; j < row.cells.size(); ++j) {
    lo.push_back(row.cells[j].lo);
    hi.push_back(row.cells[j].hi);
    values.push_back(line[std::size_t(row.window.first) + j]);
  }
  lo.push_back(row.window.leave.lo);
  hi.push_back(row.window.leave.hi);
  values.push_back(0.0);
  lo.push_back(row.window.cut.lo);
  hi.push_back(row.window.cut.hi);
  values.push_back(detail::cut_value(bound));
  std::vector<detail::OutcomeSlack> scratch;
  return detail::robust_expectation(lo.data(), hi.data(), values.data(), lo.size(), bound, scratch);
}

}  // namespace amytiss::test_rows
