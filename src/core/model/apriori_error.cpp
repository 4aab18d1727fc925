#include "amytiss/apriori_error.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "amytiss/enclosure.hpp"
#include "amytiss/format.hpp"
#include "amytiss/interval.hpp"

namespace amytiss {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
// Relative slack for the few roundings of a closed-form product (each factor below is a handful of
// correctly rounded or libm operations, far below 1e-12 in all).
constexpr double kRoundingSlack = 1e-12;
// Relative slack on computed covariance eigenvalues (the symmetric eigensolver's backward error is
// a few units in the last place of the largest eigenvalue).
constexpr double kEigenvalueSlack = 1e-12;

// The covariance's eigenvalues, each moved down by the solver's error bound (a diagonal matrix: its
// entries, exact).
std::vector<double> covariance_eigenvalues_from_below(const NoiseConfig& noise, std::size_t n) {
  if (noise.covariance.size() == n) return noise.covariance;
  Eigen::MatrixXd matrix(n, n);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) matrix(Eigen::Index(i), Eigen::Index(j)) = noise.covariance[i * n + j];
  const Eigen::VectorXd values =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(matrix, Eigen::EigenvaluesOnly).eigenvalues();
  const double largest = values.cwiseAbs().maxCoeff();
  std::vector<double> lowered;
  for (Eigen::Index i = 0; i < values.size(); ++i) lowered.push_back(values(i) - kEigenvalueSlack * largest);
  return lowered;
}

// Upper bound of the spectral norm of every matrix whose entries lie in the interval Jacobian:
// with M the entries' magnitudes, |J|_2 <= |M|_2 <= min(Frobenius norm of M, sqrt(max row sum of
// M^T M)) (M^T M is nonnegative: its spectral radius is at most its largest row sum).
double spectral_norm_bound(const IntervalJacobian& jacobian, std::size_t n) {
  std::vector<double> magnitude(n * n);
  double frobenius = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < n; ++j) {
      magnitude[i * n + j] = jacobian.entries[i][j].magnitude();
      frobenius += magnitude[i * n + j] * magnitude[i * n + j];
    }
  double largest_row = 0;
  for (std::size_t j = 0; j < n; ++j) {
    double row = 0;
    for (std::size_t k = 0; k < n; ++k)
      for (std::size_t i = 0; i < n; ++i) row += magnitude[i * n + j] * magnitude[i * n + k];
    largest_row = std::max(largest_row, row);
  }
  return std::min(std::sqrt(frobenius), std::sqrt(largest_row)) * (1 + kRoundingSlack);
}

// Cells per box along each dimension: 1 while the boxes (with a Free cell), inputs and
// disturbances need at most `max_jacobians` Jacobians; else the dimension with the most boxes is
// coarsened (its box side doubled) until they fit. 0: every cell.
std::vector<std::size_t> box_sides(const Abstraction& abstraction, std::size_t max_jacobians) {
  const Grid& states = abstraction.states;
  std::vector<std::size_t> side(states.dims(), 1);
  if (max_jacobians == 0) return side;
  const double per_box = double(abstraction.inputs.size()) * double(abstraction.disturbances.size());
  auto boxes_along = [&](std::size_t d) { return (states.count(d) + side[d] - 1) / side[d]; };
  for (;;) {
    double boxes = 1;
    std::size_t widest = 0;
    for (std::size_t d = 0; d < states.dims(); ++d) {
      boxes *= double(boxes_along(d));
      if (boxes_along(d) > boxes_along(widest)) widest = d;
    }
    if (boxes * per_box <= double(max_jacobians) || states.dims() == 0 || boxes_along(widest) == 1) return side;
    side[widest] *= 2;
  }
}

// The closed boxes (faces moved out by one step: they are rounded grid arithmetic) of `side` cells
// per dimension that hold at least one Free cell.
std::vector<IntervalBox> boxes_with_free_cells(const Abstraction& abstraction, const std::vector<std::size_t>& side) {
  const Grid& states = abstraction.states;
  const std::size_t n = states.dims();
  std::vector<std::size_t> boxes_along(n), multi(n);
  std::size_t boxes = 1;
  for (std::size_t d = 0; d < n; ++d) boxes *= boxes_along[d] = (states.count(d) + side[d] - 1) / side[d];
  std::vector<char> has_free(boxes, 0);
  for (std::size_t cell = 0; cell < states.size(); ++cell) {
    if (abstraction.roles[cell] != CellRole::Free) continue;
    states.multi_index(cell, multi.data());
    std::size_t box = 0;
    for (std::size_t d = 0; d < n; ++d) box = box * boxes_along[d] + multi[d] / side[d];
    has_free[box] = 1;
  }
  std::vector<IntervalBox> result;
  for (std::size_t box = 0; box < boxes; ++box) {
    if (!has_free[box]) continue;
    IntervalBox interval_box(n);
    for (std::size_t d = n, rest = box; d-- > 0; rest /= boxes_along[d]) {
      const std::size_t first = (rest % boxes_along[d]) * side[d];
      const std::size_t last = std::min(first + side[d], states.count(d)) - 1;
      interval_box[d] = Interval(round_down(states.face(d, std::int64_t(first))),
                                 round_up(states.face(d, std::int64_t(last) + 1)));
    }
    result.push_back(std::move(interval_box));
  }
  return result;
}

std::string box_text(const IntervalBox& box) {
  std::string text;
  for (const Interval& side : box)
    text += (text.empty() ? "[" : " x [") + format_significant(side.lo) + ", " + format_significant(side.hi) + "]";
  return text;
}

// The largest spectral-norm bound of df/dx over the boxes of Free cells, the inputs and the
// disturbances; infinite (with the box in `why_not`) at the first row that is not valid.
double jacobian_norm_over_free_cells(const Abstraction& abstraction, const std::vector<std::size_t>& side,
                                     std::string* why_not) {
  const ImageEnclosure enclosure(abstraction.config);
  const std::size_t n = abstraction.states.dims();
  double largest = 0;
  for (const IntervalBox& box : boxes_with_free_cells(abstraction, side)) {
    for (std::size_t input = 0; input < abstraction.inputs.size(); ++input) {
      const std::vector<double> u = abstraction.inputs.dims() ? abstraction.inputs.point(input) : std::vector<double>{};
      for (std::size_t disturbance = 0; disturbance < abstraction.disturbances.size(); ++disturbance) {
        const std::vector<double> w =
            abstraction.disturbances.dims() ? abstraction.disturbances.point(disturbance) : std::vector<double>{};
        const IntervalJacobian jacobian = enclosure.jacobian(box, u, w);
        for (std::size_t i = 0; i < n; ++i)
          if (!jacobian.valid[i]) {
            *why_not = "the map's coordinate " + std::to_string(i) + " may jump inside " + box_text(box) +
                       " (a floor, ceil, comparison, branch or domain edge): no Lipschitz constant";
            return kInfinity;
          }
        largest = std::max(largest, spectral_norm_bound(jacobian, n));
      }
    }
  }
  return largest;
}

}  // namespace

double noise_density_slope(const Abstraction& abstraction, std::string* why_not) {
  const NoiseConfig& noise = abstraction.config.noise;
  const std::size_t n = abstraction.states.dims();
  why_not->clear();
  if (noise.type == NoiseType::Multiplicative) {
    *why_not = "multiplicative noise: the density's scale moves with the state (not bounded here)";
    return kInfinity;
  }
  switch (noise.distribution) {
    case Distribution::Normal: break;
    case Distribution::Uniform:
      *why_not = "uniform noise: its density jumps at the support's ends, not Lipschitz";
      return kInfinity;
    case Distribution::Exponential:
      *why_not = "exponential noise: its density jumps at the shift, not Lipschitz";
      return kInfinity;
    case Distribution::Beta:
      *why_not = "beta noise: no Lipschitz bound of its density is computed here";
      return kInfinity;
    case Distribution::Custom:
      *why_not = "custom noise density: no Lipschitz bound is computed here";
      return kInfinity;
  }
  // N(y; 0, Sigma): grad = -Sigma^-1 y N(y). With z = Sigma^-1/2 y, |Sigma^-1 y| <= |z| / sqrt(lambda_min)
  // and |z| exp(-|z|^2/2) <= exp(-1/2) (at |z| = 1, along the smallest eigenvector: attained), so
  // sup |grad| = exp(-1/2) / (sqrt(lambda_min) (2 pi)^(n/2) sqrt(det Sigma)).
  const std::vector<double> eigenvalues = covariance_eigenvalues_from_below(noise, n);
  const double smallest = *std::min_element(eigenvalues.begin(), eigenvalues.end());
  if (!(smallest > 0)) {
    *why_not = "a covariance with a variance of 0 (or not safely positive definite): the noise has no density";
    return kInfinity;
  }
  double denominator = std::sqrt(smallest);
  for (double eigenvalue : eigenvalues) denominator *= std::sqrt(2 * M_PI * eigenvalue);
  return std::exp(-0.5) / denominator * (1 + kRoundingSlack);
}

namespace {

// Volume of the cells that are not fixed at zero, cell by cell (a grid with faces).
double positive_volume(const Abstraction& abstraction) {
  const Grid& states = abstraction.states;
  std::vector<std::size_t> multi(states.dims());
  double volume = 0;
  for (std::size_t cell = 0; cell < states.size(); ++cell) {
    if (abstraction.roles[cell] == CellRole::FixedZero) continue;
    states.multi_index(cell, multi.data());
    double cell_volume = 1;
    for (std::size_t d = 0; d < states.dims(); ++d) cell_volume *= states.width(d, multi[d]);
    volume += cell_volume;
  }
  return volume;
}

}  // namespace

AprioriError apriori_error(const Abstraction& abstraction, std::size_t max_jacobians) {
  AprioriError error;
  const Grid& states = abstraction.states;
  double cell_volume = 1, diameter_squared = 0;
  for (std::size_t d = 0; d < states.dims(); ++d) {
    // A dimension given by its faces: its widest cell bounds the diameter.
    double eta = states.eta()[d];
    if (!states.uniform(d))
      for (std::size_t k = 0; k < states.count(d); ++k) eta = std::max(eta, states.width(d, k));
    cell_volume *= eta;
    diameter_squared += eta * eta;
  }
  error.delta = std::sqrt(diameter_squared) * (1 + kRoundingSlack);
  const auto positive_cells = std::count_if(abstraction.roles.begin(), abstraction.roles.end(),
                                            [](CellRole role) { return role != CellRole::FixedZero; });
  error.measure = states.all_uniform() ? double(positive_cells) * cell_volume * (1 + kRoundingSlack)
                                       : positive_volume(abstraction) * (1 + kRoundingSlack);
  error.horizon = abstraction.unbounded ? kInfinity : double(abstraction.horizon);

  std::string why_not;
  error.density_slope = noise_density_slope(abstraction, &why_not);
  if (why_not.empty()) {
    const std::vector<std::size_t> side = box_sides(abstraction, max_jacobians);
    for (std::size_t cells : side) error.cells_per_box *= cells;
    error.jacobian_norm = jacobian_norm_over_free_cells(abstraction, side, &why_not);
  }
  error.lipschitz = why_not.empty() ? error.density_slope * error.jacobian_norm * (1 + kRoundingSlack) : kInfinity;
  if (why_not.empty() && abstraction.unbounded) why_not = "the horizon is infinite";
  error.epsilon = why_not.empty() ? error.horizon * error.lipschitz * error.measure * error.delta * (1 + kRoundingSlack)
                                  : kInfinity;
  error.explanation = "T " + format_significant(error.horizon) + " x H " + format_significant(error.lipschitz) +
                      " (density slope " + format_significant(error.density_slope) + " x |df/dx| " +
                      format_significant(error.jacobian_norm) +
                      (error.cells_per_box > 1 ? " over boxes of " + std::to_string(error.cells_per_box) + " cells"
                                               : "") +
                      ") x L(A) " + format_significant(error.measure) +
                      " x delta " + format_significant(error.delta);
  if (!why_not.empty()) error.explanation += "; infinite: " + why_not;
  return error;
}

std::string describe_apriori_error(const AprioriError& error) {
  return "a-priori error of the abstraction (paper's bound): " + format_significant(error.epsilon, 2) +
         (error.vacuous() ? ", vacuous" : "") + ": " + error.explanation;
}

}  // namespace amytiss
