#include "amytiss/grid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <limits>
#include <string>

#include "amytiss/errors.hpp"

namespace amytiss {

namespace {

[[noreturn]] void invalid(const std::string& what) {
  // The spec passed Config::validate() (which names the key); a violation is a bug of the caller.
  throw std::logic_error("Grid: expected a validated grid: " + what);
}

// Faces of a dimension given by them: at least two, finite, strictly increasing.
void check_faces(const std::vector<double>& faces, std::size_t d) {
  if (faces.size() < 2) invalid("faces[" + std::to_string(d) + "] has fewer than 2 faces");
  for (std::size_t k = 0; k < faces.size(); ++k) {
    if (!std::isfinite(faces[k])) invalid("faces[" + std::to_string(d) + "] has a face that is not finite");
    if (k > 0 && !(faces[k - 1] < faces[k])) invalid("faces[" + std::to_string(d) + "] is not strictly increasing");
  }
}

}  // namespace

Grid::Grid(const GridSpec& spec) {
  const std::size_t dims = spec.lb.size();
  if (spec.ub.size() != dims || spec.eta.size() != dims)
    invalid("lb, ub and eta have " + std::to_string(dims) + ", " + std::to_string(spec.ub.size()) + " and " +
            std::to_string(spec.eta.size()) + " values, expected the same number");
  if (!spec.faces.empty() && spec.faces.size() != dims)
    invalid("faces has " + std::to_string(spec.faces.size()) + " entries, expected " + std::to_string(dims));
  lb_ = spec.lb;
  eta_ = spec.eta;
  faces_.assign(dims, {});
  points_.assign(dims, {});
  counts_.resize(dims);
  strides_.resize(dims);
  size_ = 1;
  for (std::size_t d = 0; d < dims; ++d) {
    double count = 0;
    if (spec.has_faces(d)) {
      check_faces(spec.faces[d], d);
      faces_[d] = spec.faces[d];
      count = double(faces_[d].size() - 1);
      points_[d].resize(faces_[d].size() - 1);
      double smallest = faces_[d][1] - faces_[d][0];
      for (std::size_t k = 0; k + 1 < faces_[d].size(); ++k) {
        points_[d][k] = 0.5 * (faces_[d][k] + faces_[d][k + 1]);
        smallest = std::min(smallest, faces_[d][k + 1] - faces_[d][k]);
      }
      lb_[d] = points_[d][0];
      eta_[d] = smallest;
    } else {
      if (!(std::isfinite(spec.lb[d]) && std::isfinite(spec.ub[d]) && std::isfinite(spec.eta[d])))
        invalid("dimension " + std::to_string(d) + " has a bound or eta that is not finite");
      if (!(spec.eta[d] > 0))
        invalid("eta[" + std::to_string(d) + "] = " + std::to_string(spec.eta[d]) + ", expected a positive number");
      if (spec.lb[d] > spec.ub[d]) invalid("lb[" + std::to_string(d) + "] > ub[" + std::to_string(d) + "]");
      count = grid_points(spec.lb[d], spec.ub[d], spec.eta[d]);
    }
    if (count > 1e15 || double(size_) * count > 1e18) invalid("the grid has more points than can be indexed");
    counts_[d] = spec.has_faces(d) ? faces_[d].size() - 1 : grid_count(spec.lb[d], spec.ub[d], spec.eta[d]);
    size_ *= counts_[d];
  }
  std::size_t stride = 1;
  for (std::size_t d = dims; d-- > 0;) {
    strides_[d] = stride;
    stride *= counts_[d];
  }
}

bool Grid::all_uniform() const {
  return std::all_of(faces_.begin(), faces_.end(), [](const std::vector<double>& f) { return f.empty(); });
}

std::vector<double> Grid::faces(std::size_t dim) const {
  if (!uniform(dim)) return faces_[dim];
  std::vector<double> out(counts_[dim] + 1);
  for (std::size_t k = 0; k < out.size(); ++k) out[k] = face(dim, std::int64_t(k));
  return out;
}

double Grid::covered_low(std::size_t dim) const {
  return uniform(dim) ? lb_[dim] - 0.5 * eta_[dim] : faces_[dim].front();
}

double Grid::covered_high(std::size_t dim) const {
  return uniform(dim) ? coordinate(dim, counts_[dim] - 1) + 0.5 * eta_[dim] : faces_[dim].back();
}

double Grid::listed_face(std::size_t dim, std::int64_t k) const {
  const std::vector<double>& f = faces_[dim];
  const auto n = static_cast<std::int64_t>(f.size()) - 1;
  if (k < 0) return f[0] + double(k) * (f[1] - f[0]);
  if (k > n) return f[n] + double(k - n) * (f[n] - f[n - 1]);
  return f[std::size_t(k)];
}

std::int64_t Grid::listed_nearest(std::size_t dim, double value) const {
  const std::vector<double>& f = faces_[dim];
  const std::size_t n = f.size() - 1;
  double position;
  if (value < f[0]) position = std::floor((value - f[0]) / (f[1] - f[0]));
  else if (value >= f[n]) position = double(n) + std::floor((value - f[n]) / (f[n] - f[n - 1]));
  else return std::int64_t(std::upper_bound(f.begin(), f.end(), value) - f.begin()) - 1;
  constexpr double kLimit = 4e18;
  if (!(position < kLimit)) return std::numeric_limits<std::int64_t>::max() / 2;
  if (!(position > -kLimit)) return std::numeric_limits<std::int64_t>::min() / 2;
  return static_cast<std::int64_t>(position);
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
  if (!uniform(dim)) return listed_nearest(dim, value);
  const double position = std::floor((value - lb_[dim]) / eta_[dim] + 0.5);
  // Clamp before converting: a far-away value must not overflow the integer.
  constexpr double kLimit = 4e18;
  if (!(position < kLimit)) return std::numeric_limits<std::int64_t>::max() / 2;
  if (!(position > -kLimit)) return std::numeric_limits<std::int64_t>::min() / 2;
  return static_cast<std::int64_t>(position);
}

std::int64_t Grid::clamped_cell(std::size_t dim, double value) const {
  return std::clamp<std::int64_t>(nearest(dim, value), 0, std::int64_t(counts_[dim]) - 1);
}

std::optional<std::size_t> Grid::cell_of(const double* state) const {
  std::size_t flat = 0;
  for (std::size_t d = 0; d < dims(); ++d) {
    const double value = state[d];
    if (!std::isfinite(value)) return std::nullopt;
    std::int64_t k = nearest(d, value);
    const auto count = static_cast<std::int64_t>(counts_[d]);
    if (!uniform(d)) {
      // The covered set is closed: its upper face belongs to the last cell.
      if (value < faces_[d].front() || value > faces_[d].back()) return std::nullopt;
      flat += static_cast<std::size_t>(std::min(k, count - 1)) * strides_[d];
      continue;
    }
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
    const double scale = uniform(d) ? eta_[d] : width(d, k);
    if (!coordinate_in_box(coordinate(d, k), box.lb[d], box.ub[d], scale)) return false;
  }
  return true;
}

bool Grid::point_in_region(std::size_t flat, const Region& region) const {
  for (const Box& box : region.boxes)
    if (point_in_box(flat, box)) return true;
  return false;
}

}  // namespace amytiss
