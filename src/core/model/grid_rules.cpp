#include "amytiss/grid_rules.hpp"

#include <algorithm>
#include <cmath>

#include "amytiss/grid.hpp"

namespace amytiss {

double grid_points(double lb, double ub, double eta) { return std::floor((ub - lb) / eta + 0.5) + 1; }

std::size_t grid_count(double lb, double ub, double eta) {
  return static_cast<std::size_t>(std::floor((ub - lb) / eta + 0.5)) + 1;
}

IndexRange box_index_range(const Grid& grid, std::size_t dim, double lo, double hi) {
  const auto count = static_cast<std::int64_t>(grid.count(dim));
  if (!grid.uniform(dim)) {
    // The points grow with k: the first and the last inside bound the range.
    IndexRange range;
    range.first = count;
    for (std::int64_t k = 0; k < count; ++k) {
      if (!coordinate_in_box(grid.coordinate(dim, std::size_t(k)), lo, hi, grid.width(dim, std::size_t(k)))) continue;
      range.first = std::min(range.first, k);
      range.last = k;
    }
    return range;
  }
  const double lb = grid.lb()[dim], eta = grid.eta()[dim];
  const auto inside = [&](std::int64_t k) {
    return k >= 0 && k < count && coordinate_in_box(lb + double(k) * eta, lo, hi, eta);
  };
  // The division gives the range to within rounding; the membership rule itself settles the ends
  // (the points inside are consecutive, coordinates growing with k).
  const double first_guess = std::ceil((lo - lb) / eta - kBoxSlackPerEta);
  const double last_guess = std::floor((hi - lb) / eta + kBoxSlackPerEta);
  IndexRange range;
  range.first = static_cast<std::int64_t>(std::clamp(first_guess, 0.0, double(count)));
  range.last = static_cast<std::int64_t>(std::clamp(last_guess, -1.0, double(count - 1)));
  while (range.first <= range.last && !inside(range.first)) ++range.first;
  while (inside(range.first - 1)) --range.first;
  while (range.last >= range.first && !inside(range.last)) --range.last;
  while (inside(range.last + 1)) ++range.last;
  return range;
}

}  // namespace amytiss
