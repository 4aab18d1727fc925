#include "amytiss/grid.hpp"

#include <stdexcept>

#include <cmath>
#include <limits>
#include <string>

#include "amytiss/errors.hpp"

namespace amytiss {

Grid::Grid(const GridSpec& spec) {
  const std::size_t dims = spec.lb.size();
  // The spec passed Config::validate() (which names the key); a violation is a bug of the caller.
  if (spec.ub.size() != dims || spec.eta.size() != dims)
    throw std::logic_error("Grid: expected a validated grid: " + std::string() + "lb, ub and eta have " + std::to_string(dims) + ", " +
                                  std::to_string(spec.ub.size()) + " and " +
                                  std::to_string(spec.eta.size()) +
                                  " values, expected the same number");
  lb_ = spec.lb;
  eta_ = spec.eta;
  counts_.resize(dims);
  strides_.resize(dims);
  size_ = 1;
  for (std::size_t d = 0; d < dims; ++d) {
    if (!(std::isfinite(spec.lb[d]) && std::isfinite(spec.ub[d]) && std::isfinite(spec.eta[d])))
      throw std::logic_error("Grid: expected a validated grid: " + std::string() + "dimension " + std::to_string(d) + " has a bound or eta that is not finite");
    if (!(spec.eta[d] > 0))
      throw std::logic_error("Grid: expected a validated grid: " + std::string() + "eta[" + std::to_string(d) + "] = " + std::to_string(spec.eta[d]) +
                                    ", expected a positive number");
    if (spec.lb[d] > spec.ub[d])
      throw std::logic_error("Grid: expected a validated grid: " + std::string() + "lb[" + std::to_string(d) + "] > ub[" + std::to_string(d) + "]");
    const double count = grid_points(spec.lb[d], spec.ub[d], spec.eta[d]);
    if (count > 1e15 || double(size_) * count > 1e18)
      throw std::logic_error("Grid: expected a validated grid: " + std::string() + "the grid has more points than can be indexed");
    counts_[d] = grid_count(spec.lb[d], spec.ub[d], spec.eta[d]);
    size_ *= counts_[d];
  }
  std::size_t stride = 1;
  for (std::size_t d = dims; d-- > 0;) {
    strides_[d] = stride;
    stride *= counts_[d];
  }
}

std::vector<double> Grid::last_point() const {
  std::vector<double> last(dims());
  for (std::size_t d = 0; d < dims(); ++d) last[d] = coordinate(d, counts_[d] - 1);
  return last;
}

void Grid::point(std::size_t flat, double* out) const {
  for (std::size_t d = 0; d < dims(); ++d) {
    const std::size_t k = flat / strides_[d];
    flat -= k * strides_[d];
    out[d] = coordinate(d, k);
  }
}

std::vector<double> Grid::point(std::size_t flat) const {
  std::vector<double> out(dims());
  point(flat, out.data());
  return out;
}

std::size_t Grid::flat_index(const std::size_t* multi) const {
  std::size_t flat = 0;
  for (std::size_t d = 0; d < dims(); ++d) flat += multi[d] * strides_[d];
  return flat;
}

void Grid::multi_index(std::size_t flat, std::size_t* multi) const {
  for (std::size_t d = 0; d < dims(); ++d) {
    multi[d] = flat / strides_[d];
    flat -= multi[d] * strides_[d];
  }
}

std::int64_t Grid::nearest(std::size_t dim, double value) const {
  const double position = std::floor((value - lb_[dim]) / eta_[dim] + 0.5);
  // Clamp before converting: a far-away value must not overflow the integer.
  constexpr double kLimit = 4e18;
  if (!(position < kLimit)) return std::numeric_limits<std::int64_t>::max() / 2;
  if (!(position > -kLimit)) return std::numeric_limits<std::int64_t>::min() / 2;
  return static_cast<std::int64_t>(position);
}

std::optional<std::size_t> Grid::cell_of(const double* state) const {
  std::size_t flat = 0;
  for (std::size_t d = 0; d < dims(); ++d) {
    const double value = state[d];
    if (!std::isfinite(value)) return std::nullopt;
    std::int64_t k = nearest(d, value);
    const auto count = static_cast<std::int64_t>(counts_[d]);
    // The covered set is closed: its upper face (last + eta/2) rounds up to index n but belongs
    // to the last cell.
    if (k == count && value <= coordinate(d, counts_[d] - 1) + 0.5 * eta_[d]) k = count - 1;
    if (k < 0 || k >= count) return std::nullopt;
    flat += static_cast<std::size_t>(k) * strides_[d];
  }
  return flat;
}

bool Grid::point_in_box(std::size_t flat, const Box& box) const {
  for (std::size_t d = 0; d < dims(); ++d) {
    const std::size_t k = (flat / strides_[d]) % counts_[d];
    if (!coordinate_in_box(coordinate(d, k), box.lb[d], box.ub[d], eta_[d])) return false;
  }
  return true;
}

bool Grid::point_in_region(std::size_t flat, const Region& region) const {
  for (const Box& box : region.boxes)
    if (point_in_box(flat, box)) return true;
  return false;
}

}  // namespace amytiss
