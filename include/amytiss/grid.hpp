#pragma once
// Rectilinear grids (docs/semantics.md): per dimension uniform (lb + k*eta) or given by its cell
// faces. Flat indices are row-major: the LAST dimension varies fastest,
// flat = ((k0*n1 + k1)*n2 + k2)..., so a flat value array reshapes to numpy's (n0, n1, ...).
// A grid with zero dimensions has exactly one (empty) point: autonomous systems, no disturbance.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "amytiss/config.hpp"
#include "amytiss/grid_rules.hpp"

namespace amytiss {

class Grid {
 public:
  Grid() = default;  ///< zero dimensions, one point
  explicit Grid(const GridSpec& spec);

  std::size_t dims() const { return lb_.size(); }
  std::size_t size() const { return size_; }          ///< number of points (product of counts)
  std::size_t count(std::size_t dim) const { return counts_[dim]; }
  const std::vector<std::size_t>& counts() const { return counts_; }
  /// First representative point per dimension (lb of a uniform dimension).
  const std::vector<double>& lb() const { return lb_; }
  /// Spacing per dimension (state units): eta of a uniform dimension; for a dimension given by its
  /// faces, its smallest cell width (a length scale for tolerances, not a spacing).
  const std::vector<double>& eta() const { return eta_; }
  /// Whether dimension dim is uniform (lb + k*eta) rather than given by its faces.
  bool uniform(std::size_t dim) const { return faces_[dim].empty(); }
  /// Whether every dimension is uniform.
  bool all_uniform() const;
  /// The n + 1 cell faces of dimension dim (state units): face(dim, 0..n).
  std::vector<double> faces(std::size_t dim) const;
  /// Last representative point per dimension (lb + (n-1)*eta; may differ from the spec's ub).
  std::vector<double> last_point() const;
  /// Lowest and highest face of dimension dim: the covered set's extent (uniform: lb - eta/2 and
  /// the last point + eta/2, computed in that order).
  double covered_low(std::size_t dim) const;
  double covered_high(std::size_t dim) const;
  /// Width of cell k along dim (state units).
  double width(std::size_t dim, std::size_t k) const { return face(dim, std::int64_t(k) + 1) - face(dim, std::int64_t(k)); }

  /// Representative coordinate of index k along dim: lb + k*eta (uniform), the cell's midpoint.
  double coordinate(std::size_t dim, std::size_t k) const {
    return faces_[dim].empty() ? lb_[dim] + double(k) * eta_[dim] : points_[dim][k];
  }
  /// The face between cells k-1 and k along dim: lb + (k - 1/2)*eta (uniform), faces[k]. Cell k
  /// spans [face(dim, k), face(dim, k + 1)]; neighbouring cells share the exact same face. Beyond
  /// the grid (k < 0, k > n) faces continue with the outermost cells' widths.
  double face(std::size_t dim, std::int64_t k) const {
    return faces_[dim].empty() ? lb_[dim] + (double(k) - 0.5) * eta_[dim] : listed_face(dim, k);
  }
  /// Writes the point of a flat index into out[0..dims).
  void point(std::size_t flat, double* out) const;
  std::vector<double> point(std::size_t flat) const;
  /// Multi-index <-> flat index.
  std::size_t flat_index(const std::size_t* multi) const;
  void multi_index(std::size_t flat, std::size_t* multi) const;
  /// Index of the cell containing value along dim (may be < 0 or >= count; monotone in value):
  /// uniform floor((v-lb)/eta + 0.5); with faces the k with faces[k] <= v < faces[k+1], beyond the
  /// grid counted in cells of the outermost widths.
  std::int64_t nearest(std::size_t dim, double value) const;
  /// nearest() clamped to 0..count-1.
  std::int64_t clamped_cell(std::size_t dim, double value) const;
  /// Flat index of the cell containing `state` (nearest point per dimension), or nullopt when the
  /// state lies outside the covered set (beyond half a cell from the outermost points) or is not
  /// finite. O(dims), no allocation.
  std::optional<std::size_t> cell_of(const double* state) const;
  /// Whether the point of flat index lies in the closed box (coordinate_in_box, grid_rules.hpp).
  bool point_in_box(std::size_t flat, const Box& box) const;
  /// Whether the point of flat index lies in one of the region's boxes (point_in_box).
  bool point_in_region(std::size_t flat, const Region& region) const;

 private:
  std::vector<double> lb_, eta_;
  std::vector<std::vector<double>> faces_, points_;  // empty for a uniform dimension
  std::vector<std::size_t> counts_, strides_;
  std::size_t size_ = 1;
  double listed_face(std::size_t dim, std::int64_t k) const;
  std::int64_t listed_nearest(std::size_t dim, double value) const;
};

}  // namespace amytiss
