#pragma once
// The rules of a grid that both Config::validate() and the abstraction apply (docs/semantics.md):
// how many points a uniform dimension has, which points a box contains, and the faces that
// states.fit_sets inserts. One definition, so that what validation promises is what the
// abstraction does.
#include <cstddef>
#include <cstdint>

#include "amytiss/config.hpp"

namespace amytiss {

class Grid;

/// Number of points of one dimension, floor((ub - lb)/eta + 0.5) + 1, as a double so that a grid
/// too large for any index type can still be counted (and refused).
double grid_points(double lb, double ub, double eta);
/// The same as an index count; only for a dimension validate() accepted.
std::size_t grid_count(double lb, double ub, double eta);

/// Relative tolerance of box membership: a point within 1e-9*eta of a face is in the box (for a
/// dimension given by its faces, eta is the width of the point's cell).
constexpr double kBoxSlackPerEta = 1e-9;
/// Whether a grid coordinate (lb + k*eta) lies in the closed interval [lo, hi], with the slack
/// above: the one membership rule of the specification's boxes.
inline bool coordinate_in_box(double coordinate, double lo, double hi, double eta) {
  const double slack = kBoxSlackPerEta * eta;
  return !(coordinate < lo - slack || coordinate > hi + slack);
}

/// Indices first..last (inclusive) of dimension `dim` of a grid whose points lie in [lo, hi] by
/// coordinate_in_box() (Grid::point_in_box); first > last when there are none.
struct IndexRange {
  std::int64_t first = 0;
  std::int64_t last = -1;
};
IndexRange box_index_range(const Grid& grid, std::size_t dim, double lo, double hi);

/// Relative tolerance of fit_sets: a set face within 1e-9 of a cell's width from one of the cell's
/// faces is taken to be that face (no sliver cell is inserted).
constexpr double kFitFaceSlack = 1e-9;
/// The state grid the abstraction and the bounds use: config.states, or with config.fit_sets the
/// grid with a face inserted at every face of the target, avoid, safe and obstacle boxes that lies
/// strictly inside the grid's range (a dimension without an inserted face stays as it was). The
/// configuration's grid must be valid (Config::validate() checks it first).
GridSpec fitted_states(const Config& config);
/// Gives dimension `dim` of `spec` its cell `faces` (n + 1 strictly increasing values, state
/// units): faces[dim] set, lb, ub and eta NaN there, as states.faces describes such a dimension.
void set_dimension_faces(GridSpec& spec, std::size_t dim, std::vector<double> faces);

}  // namespace amytiss
