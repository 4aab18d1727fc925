#pragma once
// The rules of a uniform grid that both Config::validate() and the abstraction apply
// (docs/semantics.md): how many points a dimension has and which points a box contains. One
// definition, so that what validation promises is what the abstraction does.
#include <cstddef>
#include <cstdint>

#include "amytiss/config.hpp"

namespace amytiss {

/// Number of points of one dimension, floor((ub - lb)/eta + 0.5) + 1, as a double so that a grid
/// too large for any index type can still be counted (and refused).
double grid_points(double lb, double ub, double eta);
/// The same as an index count; only for a dimension validate() accepted.
std::size_t grid_count(double lb, double ub, double eta);

/// Relative tolerance of box membership: a point within 1e-9*eta of a face is in the box.
constexpr double kBoxSlackPerEta = 1e-9;
/// Whether a grid coordinate (lb + k*eta) lies in the closed interval [lo, hi], with the slack
/// above: the one membership rule of the specification's boxes.
inline bool coordinate_in_box(double coordinate, double lo, double hi, double eta) {
  const double slack = kBoxSlackPerEta * eta;
  return !(coordinate < lo - slack || coordinate > hi + slack);
}

/// Indices first..last (inclusive) of dimension `dim` of a validated grid whose points lie in
/// [lo, hi] by coordinate_in_box(); first > last when there are none.
struct IndexRange {
  std::int64_t first = 0;
  std::int64_t last = -1;
};
IndexRange box_index_range(const GridSpec& grid, std::size_t dim, double lo, double hi);

}  // namespace amytiss
